// appell — run, inspect and analyse nonholonomic multibody scenes from URDF.
#include "commands.hpp"

#include <cstring>
#include <iostream>

namespace {

const char* kUsage = R"(usage: appell <command> SCENE.urdf [options]

commands:
  run          simulate the scene, print a summary, write the trajectory (CSV)
  info         bodies, joints, degrees of freedom, contacts, constraint rows
  equilibria   find equilibria (including those held by nonholonomic reactions)
  linearize    eigenvalues of the linearized constrained dynamics

'appell <command> --help' describes each command's options.
)";

}  // namespace

int main(int argc, char** argv) {
  using namespace appell::cli;
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h")) {
    std::cout << kUsage;
    return argc < 2 ? 2 : 0;
  }
  const std::string cmd = argv[1];
  try {
    if (cmd == "run") return run(argc, argv);
    if (cmd == "info") return info(argc, argv);
    if (cmd == "equilibria") return equilibria(argc, argv);
    if (cmd == "linearize") return linearize(argc, argv);
    std::cerr << "appell: unknown command '" << cmd << "'\n" << kUsage;
    return 2;
  } catch (const UsageError& e) {
    std::cerr << "appell " << cmd << ": " << e.what() << " (see appell " << cmd << " --help)\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "appell " << cmd << ": error: " << e.what() << "\n";
    return 1;
  }
}
