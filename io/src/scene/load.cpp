// The loader's entry points: one parse of the text, one read of the URDF and
// of the <appell> block from that DOM, then the build — all or nothing.
#include "scene/block.hpp"
#include "urdf/snap_angles.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

namespace appell {

Scene loadSceneFromString(const std::string& xml, const std::string& base_dir,
                          const std::string& name, const LoadOptions& options) {
  const io::XmlSource src{name};
  TiXmlDocument doc;
  const TiXmlElement* robot = io::parseDocument(src, doc, xml);
  io::UrdfRobot urdf = io::readUrdf(src, robot);
  const io::AppellBlock block = io::parseAppellBlock(src, robot, base_dir, options);
  const double snap = options.snap_angles > 0 ? options.snap_angles : block.settings.snap_angles;
  const std::vector<std::string> snapped = snap > 0 ? io::snapAngles(src, snap, urdf)
                                                    : std::vector<std::string>{};
  io::Robot parsed = io::buildRobot(src, urdf, base_dir, options, block.gravity,
                                    io::inertiaRepairs(options, block.repairs), block.collisionLinks());
  parsed.warnings.insert(parsed.warnings.begin(), snapped.begin(), snapped.end());
  Scene scene;
  scene.model = std::move(parsed.model);
  scene.geometry = std::move(parsed.geometry);
  // Warnings in the order the loader met them: the snap, the URDF (buildRobot
  // carries the reader's), its meshes and inertias, the block.
  scene.warnings = parsed.warnings;
  scene.warnings.insert(scene.warnings.end(), block.warnings.begin(), block.warnings.end());
  scene.source = name;
  io::buildSceneContents(src, urdf, block, options, scene);
  if (options.check_initial_state)
    checkInitialState(scene, options.project_initial_state, options.initial_state_tolerance);
  return scene;
}

Scene loadScene(const std::string& path, const LoadOptions& options) {
  return loadSceneFromString(io::readFile(path), io::folderOf(path), path, options);
}

}  // namespace appell
