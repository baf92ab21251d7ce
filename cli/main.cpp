// appell — run, inspect and analyse nonholonomic multibody scenes from URDF.
#include "commands.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <new>

namespace {

const char* kUsage = R"(usage: appell <command> SCENE.urdf [options]
       appell plot RUN.csv [options]

commands:
  run          simulate the scene, print a summary, write the trajectory (CSV)
  info         bodies, joints, degrees of freedom, contacts, constraint rows
  equilibria   find equilibria (including those held by nonholonomic reactions)
  linearize    eigenvalues of the linearized constrained dynamics
  sweep        many cases (a grid or random draws of --set values) through
               run or linearize on N threads: a CSV or JSON row per case
  view         a self-contained HTML page replaying a run in 3-D (three.js)
  plot         PNG plots of a run's CSV: energy, residuals, contact loads, path

SCENE.urdf is a URDF with an <appell> block, or a scene file: a top-level
<appell robot="package://PKG/robot.urdf"> that adds contacts, the initial state
and settings to a description left as published (docs/scene-format.md §3).

'appell <command> --help' describes each command's options; 'appell --version' prints the version.
)";

// What a command printed is its result: when standard output cannot take it
// (`> /dev/full`, a closed pipe), that is a failure, said on stderr — never a
// lost summary with exit status 0. stdio buffers the text, so the error only
// shows once the buffer is flushed.
int checkedStdout(const std::string& cmd, int status) {
  std::cout.flush();
  if (std::fflush(stdout) != 0 || std::ferror(stdout) || !std::cout) {
    std::cerr << "appell " << cmd << ": error: cannot write to standard output (" << std::strerror(errno)
              << "): the output is lost\n";
    return status == 0 ? 1 : status;
  }
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace appell::cli;
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h")) {
    std::cout << kUsage;
    return argc < 2 ? 2 : 0;
  }
  if (!std::strcmp(argv[1], "--version") || !std::strcmp(argv[1], "-V")) {
    std::cout << "appell " APPELL_VERSION "\n";
    return 0;
  }
  const std::string cmd = argv[1];
  try {
    int status = -1;
    if (cmd == "run") status = run(argc, argv);
    if (cmd == "info") status = info(argc, argv);
    if (cmd == "equilibria") status = equilibria(argc, argv);
    if (cmd == "linearize") status = linearize(argc, argv);
    if (cmd == "sweep") status = sweep(argc, argv);
    if (cmd == "view") status = view(argc, argv);
    if (cmd == "plot") status = plot(argc, argv);
    if (status < 0) {
      std::cerr << "appell: unknown command '" << cmd << "'\n" << kUsage;
      return 2;
    }
    return checkedStdout(cmd, status);
  } catch (const UsageError& e) {
    std::cerr << "appell " << cmd << ": " << e.what() << " (see appell " << cmd << " --help)\n";
    return 2;
  } catch (const std::bad_alloc&) {
    std::cerr << "appell " << cmd << ": error: out of memory (the scene or its meshes are too large)\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "appell " << cmd << ": error: " << e.what() << "\n";
    return 1;
  } catch (...) {
    std::cerr << "appell " << cmd << ": internal error: an unknown exception\n";
    return 1;
  }
}
