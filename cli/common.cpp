#include "commands.hpp"

#include <appell/constrained_dynamics.hpp>
#include <appell/integrators.hpp>
#include <appell/simulator.hpp>

#include <filesystem>
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
  opt.snap_angles = args.number("snap-angles", 0);  // the loader checks its range
  if (args.has("balance-inertia")) opt.balance_inertia = true;
  if (args.has("bound-inertia")) opt.bound_inertia = args.nonNegativeNumber("bound-inertia");
  if (args.has("bound-mass")) opt.bound_mass = args.nonNegativeNumber("bound-mass");
  Scene scene = loadScene(args.positional()[0], opt);
  for (const std::string& w : scene.warnings) std::cerr << "appell: warning: " << w << "\n";
  return scene;
}

void refuseOverwritingInputs(const std::string& option, const std::string& out, const Scene& scene,
                             const std::vector<std::string>& other_inputs) {
  std::vector<std::string> inputs = other_inputs;
  inputs.push_back(scene.source);
  inputs.push_back(scene.robot_source);
  for (const LinkGeometry& link : scene.geometry)
    for (const auto* list : {&link.visual, &link.collision})
      for (const Geometry& g : *list)
        if (!g.mesh_path.empty()) inputs.push_back(g.mesh_path);
  std::error_code ec;
  if (!std::filesystem::exists(out, ec)) return;  // a new file overwrites nothing
  for (const std::string& input : inputs)
    if (std::filesystem::equivalent(out, input, ec) && !ec)
      throw UsageError("--" + option + " '" + out + "' is an input of this command (" + input +
                       "): it would be overwritten; name another file");
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
