#include "commands.hpp"

#include <appell/constrained_dynamics.hpp>
#include <appell/integrators.hpp>
#include <appell/simulator.hpp>

#include <iostream>
#include <sstream>

namespace appell::cli {

Scene loadFromArgs(const Args& args, bool check_initial) {
  if (args.positional().size() != 1)
    throw UsageError("expected exactly one SCENE.urdf argument");
  LoadOptions opt;
  for (const std::string& p : args.list("package-path")) opt.package_paths.push_back(p);
  opt.check_initial_state = check_initial;
  opt.project_initial_state = args.has("project-initial");
  opt.joint_limits = !args.has("no-joint-limits");
  Scene scene = loadScene(args.positional()[0], opt);
  for (const std::string& w : scene.warnings) std::cerr << "appell: warning: " << w << "\n";
  return scene;
}

std::string helpText(const char* text) {
  std::string s = text;
  auto replace = [&](const std::string& key, const std::string& names) {
    for (auto at = s.find(key); at != std::string::npos; at = s.find(key, at + names.size()))
      s.replace(at, key.size(), names);
  };
  replace("{integrators}", canonicalNames(integratorTable()));
  replace("{formulations}", canonicalNames(formulationTable()));
  replace("{contact_schemes}", canonicalNames(contactSchemeTable()));
  return s;
}

}  // namespace appell::cli
