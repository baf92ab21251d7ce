// The `appell` subcommands. Each returns the process exit code.
#pragma once

#include "args.hpp"

#include <appell/urdf.hpp>

namespace appell::cli {

int run(int argc, char** argv);
int info(int argc, char** argv);
int equilibria(int argc, char** argv);
int linearize(int argc, char** argv);
int sweep(int argc, char** argv);
int view(int argc, char** argv);
int plot(int argc, char** argv);

/// Options every command that loads a scene accepts.
inline const std::set<std::string> kLoadOptions = {"package-path", "bound-inertia", "bound-mass"};
inline const std::set<std::string> kLoadFlags = {"project-initial", "no-joint-limits", "balance-inertia",
                                                 "help"};
/// Their help lines for the inertia repairs (InertiaRepairs, model.hpp).
#define APPELL_INERTIA_HELP \
  "  --balance-inertia   raise each body's smallest principal moment to I3 - I2 where\n" \
  "                      the moments break the triangle inequality (CAD rounding)\n" \
  "  --bound-inertia V   raise every principal moment below V kg m^2 to V\n" \
  "  --bound-mass M      raise every moving body's mass below M kg to M\n" \
  "                      (each overrides the scene's <simulation> attribute; every\n" \
  "                      repaired body is named in a warning)\n"

/// Loads the scene named by the single positional argument.
Scene loadFromArgs(const Args& args, bool check_initial = true);

/// Throws UsageError when the output file `out` (given by `option`) is one of
/// the command's inputs — the scene file, a mesh it loaded, or an extra input
/// such as a trajectory — compared as files (device and inode), so that
/// `--out scene.urdf` can never overwrite the scene.
void refuseOverwritingInputs(const std::string& option, const std::string& out, const Scene& scene,
                             const std::vector<std::string>& other_inputs = {});

/// A help text with "{integrators}" and "{formulations}" replaced by the
/// canonical names of integratorTable() and formulationTable() ("a | b | c").
std::string helpText(const char* text);


}  // namespace appell::cli
