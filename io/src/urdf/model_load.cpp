// Loading the model alone (no contacts): the part of the loader that needs
// only the engine.
#include "urdf/urdf_internal.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

namespace appell {

namespace io {

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SceneError(path + ": cannot open file");
  std::ostringstream s;
  s << in.rdbuf();
  if (in.bad()) throw SceneError(path + ": read error");
  return s.str();
}

std::string folderOf(const std::string& path) {
  return std::filesystem::absolute(path).parent_path().string();
}

}  // namespace io

Model loadUrdfModel(const std::string& path, const LoadOptions& options) {
  const std::string xml = io::readFile(path);
  const io::XmlSource src{path};
  TiXmlDocument doc;
  const TiXmlElement* robot = io::parseDocument(src, doc, xml);
  const io::UrdfRobot urdf = io::readUrdf(src, robot);
  // Only the gravity of the scene block matters for the model.
  Vec3 gravity(0, 0, -9.81);
  if (const TiXmlElement* block = robot->FirstChildElement("appell"))
    if (const TiXmlElement* g = block->FirstChildElement("gravity")) gravity = io::vec3(src, g, "xyz");
  return io::buildRobot(src, urdf, io::folderOf(path), options, gravity).model;
}

}  // namespace appell
