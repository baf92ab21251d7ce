// The loader's entry points: one parse of the text, one read of the URDF and
// of the <appell> block from that DOM, then the build — all or nothing.
#include "scene/block.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

namespace appell {

Scene loadSceneFromString(const std::string& xml, const std::string& base_dir,
                          const std::string& name, const LoadOptions& options) {
  const io::XmlSource src{name};
  TiXmlDocument doc;
  const TiXmlElement* robot = io::parseDocument(src, doc, xml);
  const io::UrdfRobot urdf = io::readUrdf(src, robot);
  const io::AppellBlock block = io::parseAppellBlock(src, robot, base_dir, options);
  io::Robot parsed = io::buildRobot(src, urdf, base_dir, options, block.gravity,
                                    io::inertiaRepairs(options, block.repairs));
  Scene scene;
  scene.model = std::move(parsed.model);
  scene.geometry = std::move(parsed.geometry);
  scene.warnings = std::move(parsed.warnings);
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
