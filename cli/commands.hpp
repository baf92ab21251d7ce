// The `appell` subcommands. Each returns the process exit code.
#pragma once

#include "args.hpp"

#include <appell/urdf.hpp>

namespace appell::cli {

int run(int argc, char** argv);
int info(int argc, char** argv);
int equilibria(int argc, char** argv);
int linearize(int argc, char** argv);
int view(int argc, char** argv);
int plot(int argc, char** argv);

/// Options every command that loads a scene accepts.
inline const std::set<std::string> kLoadOptions = {"package-path"};
inline const std::set<std::string> kLoadFlags = {"project-initial", "no-joint-limits", "help"};

/// Loads the scene named by the single positional argument.
Scene loadFromArgs(const Args& args, bool check_initial = true);

/// A help text with "{integrators}" and "{formulations}" replaced by the
/// canonical names of integratorTable() and formulationTable() ("a | b | c").
std::string helpText(const char* text);


}  // namespace appell::cli
