// appell — run, inspect and analyse nonholonomic multibody scenes from URDF.
#include "commands.hpp"

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
  view         a self-contained HTML page replaying a run in 3-D (three.js)
  plot         PNG plots of a run's CSV: energy, residuals, contact loads, path

'appell <command> --help' describes each command's options; 'appell --version' prints the version.
)";

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
    if (cmd == "run") return run(argc, argv);
    if (cmd == "info") return info(argc, argv);
    if (cmd == "equilibria") return equilibria(argc, argv);
    if (cmd == "linearize") return linearize(argc, argv);
    if (cmd == "view") return view(argc, argv);
    if (cmd == "plot") return plot(argc, argv);
    std::cerr << "appell: unknown command '" << cmd << "'\n" << kUsage;
    return 2;
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
