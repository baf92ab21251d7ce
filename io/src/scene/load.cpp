// The loader's entry points: one parse of each document (a URDF, or a scene
// file and the description it names: urdf/documents.cpp), one read of the
// URDF and of the <appell> block in force, then the build — all or nothing.
#include "scene/block.hpp"
#include "urdf/snap_angles.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

namespace appell {

Scene loadSceneFromString(const std::string& xml, const std::string& base_dir,
                          const std::string& name, const LoadOptions& options) {
  io::Documents d;
  io::openDocuments(d, xml, base_dir, name, options);
  const io::XmlSource& src = d.src;
  io::UrdfRobot urdf = io::fromDescription(d, [&] { return io::readUrdf(src, d.robot); });
  const io::AppellBlock block = io::parseAppellBlock(src, d.block, d.scene_file, d.block_dir, options);
  const double snap = options.snap_angles > 0 ? options.snap_angles : block.settings.snap_angles;
  const std::vector<std::string> snapped = snap > 0 ? io::snapAngles(src, snap, urdf)
                                                    : std::vector<std::string>{};
  io::Robot parsed = io::fromDescription(d, [&] {
    return io::buildRobot(src, urdf, d.robot_dir, options, block.gravity,
                          io::inertiaRepairs(options, block.repairs), block.collisionLinks());
  });
  parsed.warnings.insert(parsed.warnings.begin(), snapped.begin(), snapped.end());
  Scene scene;
  scene.model = std::move(parsed.model);
  scene.geometry = std::move(parsed.geometry);
  // Warnings in the order the loader met them: the documents, the snap, the
  // URDF (buildRobot carries the reader's), its meshes and inertias, the block.
  scene.warnings = d.warnings;
  scene.warnings.insert(scene.warnings.end(), parsed.warnings.begin(), parsed.warnings.end());
  scene.warnings.insert(scene.warnings.end(), block.warnings.begin(), block.warnings.end());
  scene.source = name;
  scene.robot_source = d.robot_path;
  io::buildSceneContents(src, urdf, block, options, scene);
  if (options.check_initial_state)
    checkInitialState(scene, options.project_initial_state, options.initial_state_tolerance);
  return scene;
}

Scene loadScene(const std::string& path, const LoadOptions& options) {
  return loadSceneFromString(io::readFile(path), io::folderOf(path), path, options);
}

}  // namespace appell
