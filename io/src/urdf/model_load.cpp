// Loading the model alone (no contacts): the part of the loader that needs
// only the engine.
#include "urdf/urdf_internal.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

namespace appell {

namespace io {

std::string readFile(const std::string& path) {
  // Bounded: only regular files, at most kMaxSceneBytes (a device such as
  // /dev/zero would otherwise be read until memory runs out).
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) throw SceneError(path + ": cannot open file (no such file)");
  if (std::filesystem::is_directory(status)) throw SceneError(path + ": is a directory, not a URDF file");
  if (!std::filesystem::is_regular_file(status))
    throw SceneError(path + ": not a regular file (a device, pipe or socket cannot be a scene)");
  const auto size = std::filesystem::file_size(path, ec);
  if (!ec && size > kMaxSceneBytes)
    throw SceneError(path + ": " + std::to_string(size) + " bytes, larger than the " +
                     std::to_string(kMaxSceneBytes >> 20) + " MiB a scene file may have");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SceneError(path + ": cannot open file");
  std::string text;
  try {
    text.resize(static_cast<std::size_t>(size));
    in.read(text.data(), static_cast<std::streamsize>(text.size()));
    text.resize(static_cast<std::size_t>(in.gcount()));
  } catch (const std::bad_alloc&) {
    throw SceneError(path + ": out of memory reading " + std::to_string(size) + " bytes");
  }
  if (in.bad()) throw SceneError(path + ": read error");
  // UTF-16 and UTF-32 (byte-order marks, or NUL bytes in the first line)
  // are not XML TinyXML reads: say so instead of "document empty".
  if (text.size() >= 2 && ((static_cast<unsigned char>(text[0]) == 0xFF && static_cast<unsigned char>(text[1]) == 0xFE) ||
                           (static_cast<unsigned char>(text[0]) == 0xFE && static_cast<unsigned char>(text[1]) == 0xFF)))
    throw SceneError(path + ": the file is UTF-16 (or UTF-32); save it as UTF-8");
  if (text.find('\0') != std::string::npos)
    throw SceneError(path + ": the file holds NUL bytes: not a text (UTF-8 XML) file");
  return text;
}

std::string folderOf(const std::string& path) {
  return std::filesystem::absolute(path).parent_path().string();
}

}  // namespace io

Model loadUrdfModel(const std::string& path, const LoadOptions& options) {
  io::Documents d;  // a URDF, or a scene file and its description
  io::openDocuments(d, io::readFile(path), io::folderOf(path), path, options);
  const io::UrdfRobot urdf = io::fromDescription(d, [&] { return io::readUrdf(d.src, d.robot); });
  // Only the gravity of the scene block matters for the model (the inertia
  // repairs are LoadOptions' alone here).
  Vec3 gravity(0, 0, -9.81);
  if (d.block)
    if (const TiXmlElement* g = d.block->FirstChildElement("gravity")) gravity = io::vec3(d.src, g, "xyz");
  return io::fromDescription(d, [&] {
    return io::buildRobot(d.src, urdf, d.robot_dir, options, gravity, io::inertiaRepairs(options, {})).model;
  });
}

}  // namespace appell
