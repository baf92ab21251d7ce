// Resolution of mesh URIs: package://, file://, absolute and relative paths.
#include <appell/urdf.hpp>

#include <tinyxml.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace appell {

namespace fs = std::filesystem;

namespace {

std::vector<std::string> searchPath(const LoadOptions& options) {
  std::vector<std::string> path = options.package_paths;
  if (options.use_ros_package_path) {
    if (const char* env = std::getenv("ROS_PACKAGE_PATH")) {
      std::stringstream in(env);
      std::string entry;
      while (std::getline(in, entry, ':'))
        if (!entry.empty()) path.push_back(entry);
    }
  }
  return path;
}

// The <name> of a package.xml, or "" if it cannot be read.
std::string packageName(const fs::path& manifest) {
  TiXmlDocument doc;
  if (!doc.LoadFile(manifest.string().c_str())) return "";
  const TiXmlElement* root = doc.RootElement();
  if (!root) return "";
  const TiXmlElement* name = root->FirstChildElement("name");
  if (!name || !name->GetText()) return "";
  std::string s = name->GetText();
  const auto b = s.find_first_not_of(" \t\r\n"), e = s.find_last_not_of(" \t\r\n");
  return b == std::string::npos ? "" : s.substr(b, e - b + 1);
}

// Depth-first search for a folder whose package.xml names `name`; like
// rospack, it does not descend into a package or into hidden folders.
std::string searchManifests(const fs::path& dir, const std::string& name, int depth) {
  std::error_code ec;
  if (fs::is_regular_file(dir / "package.xml", ec)) {
    return packageName(dir / "package.xml") == name ? fs::absolute(dir).string() : "";
  }
  if (depth == 0) return "";
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    if (!it->is_directory(ec)) continue;
    const std::string leaf = it->path().filename().string();
    if (leaf.empty() || leaf[0] == '.') continue;
    std::string found = searchManifests(it->path(), name, depth - 1);
    if (!found.empty()) return found;
  }
  return "";
}

}  // namespace

std::string findPackage(const std::string& name, const LoadOptions& options) {
  std::error_code ec;
  for (const std::string& entry : searchPath(options)) {
    const fs::path p = fs::path(entry) / name;
    if (fs::is_directory(p, ec)) return fs::absolute(p).lexically_normal().string();
  }
  for (const std::string& entry : searchPath(options)) {
    if (!fs::is_directory(entry, ec)) continue;
    std::string found = searchManifests(entry, name, 6);
    if (!found.empty()) return fs::path(found).lexically_normal().string();
  }
  return "";
}

std::string resolveMeshPath(const std::string& uri, const std::string& base_dir,
                            const LoadOptions& options) {
  std::error_code ec;
  fs::path path;
  const std::string pkg = "package://", file = "file://";
  if (uri.rfind(pkg, 0) == 0) {
    const std::string rest = uri.substr(pkg.size());
    const auto slash = rest.find('/');
    const std::string name = rest.substr(0, slash);
    if (name.empty()) throw SceneError("mesh '" + uri + "': no package name");
    const std::string dir = findPackage(name, options);
    if (dir.empty()) {
      std::string searched;
      for (const auto& e : searchPath(options)) searched += (searched.empty() ? "" : ":") + e;
      throw SceneError("mesh '" + uri + "': package '" + name + "' not found in the search path [" +
                       searched + "] (set LoadOptions::package_paths or ROS_PACKAGE_PATH)");
    }
    path = fs::path(dir) / (slash == std::string::npos ? "" : rest.substr(slash + 1));
  } else if (uri.rfind(file, 0) == 0) {
    path = uri.substr(file.size());
  } else {
    path = uri;
  }
  if (path.is_relative()) path = fs::path(base_dir.empty() ? "." : base_dir) / path;
  path = fs::absolute(path, ec).lexically_normal();
  if (!fs::is_regular_file(path, ec))
    throw SceneError("mesh '" + uri + "': file not found: " + path.string());
  return path.string();
}

}  // namespace appell
