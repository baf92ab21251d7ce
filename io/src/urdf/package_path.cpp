// Resolution of mesh URIs: package://, file://, absolute and relative paths.
#include <appell/urdf.hpp>

#include "urdf/urdf_internal.hpp"

#include <tinyxml.h>

#include <sys/stat.h>

#include <cstdlib>
#include <deque>
#include <set>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace appell {

namespace fs = std::filesystem;

namespace {

// Folders searched for packages, in order: LoadOptions::package_paths, then
// ROS 1's ROS_PACKAGE_PATH (folders holding packages). ROS 2's
// AMENT_PREFIX_PATH lists install prefixes, each holding share/<package>;
// those are looked up directly (amentPrefixes), not searched.
std::vector<std::string> splitPath(const char* env) {
  std::vector<std::string> out;
  if (!env) return out;
  std::stringstream in(env);
  std::string entry;
  while (std::getline(in, entry, ':'))
    if (!entry.empty()) out.push_back(entry);
  return out;
}

std::vector<std::string> searchPath(const LoadOptions& options) {
  std::vector<std::string> path = options.package_paths;
  if (options.use_ros_package_path)
    for (std::string& e : splitPath(std::getenv("ROS_PACKAGE_PATH"))) path.push_back(std::move(e));
  return path;
}

std::vector<std::string> amentPrefixes(const LoadOptions& options) {
  return options.use_ros_package_path ? splitPath(std::getenv("AMENT_PREFIX_PATH"))
                                      : std::vector<std::string>{};
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

// Search for a folder whose package.xml names `name`. Like rospack it does
// not descend into a package or into hidden folders, and it follows
// symbolic links — but each folder is entered once, identified by device
// and inode, so a link back up the tree (a cycle) is not walked again, and
// the whole search stops after kMaxFolders folders: its work is bounded
// whatever the file system holds.
constexpr int kMaxDepth = 6;
constexpr std::size_t kMaxFolders = 100000;

struct ManifestSearch {
  const std::string& name;
  std::set<std::pair<std::uintmax_t, std::uintmax_t>> seen;  // (device, inode)
  std::size_t visited = 0;

  bool enter(const fs::path& dir) {
    struct stat st {};
    if (::stat(dir.c_str(), &st) != 0) return false;
    if (!seen.emplace(st.st_dev, st.st_ino).second) return false;  // entered before: a cycle
    return ++visited <= kMaxFolders;
  }

  // Breadth-first with an explicit queue: no recursion, and the shallowest
  // match wins, as a reader of the tree would expect.
  std::string find(const fs::path& root) {
    std::deque<std::pair<fs::path, int>> queue{{root, 0}};
    std::error_code ec;
    while (!queue.empty()) {
      auto [dir, depth] = std::move(queue.front());
      queue.pop_front();
      if (!enter(dir)) continue;
      if (fs::is_regular_file(dir / "package.xml", ec)) {
        if (packageName(dir / "package.xml") == name) return fs::absolute(dir).string();
        continue;  // a package: not descended into
      }
      if (depth == kMaxDepth) continue;
      for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
        if (!it->is_directory(ec)) continue;
        const std::string leaf = it->path().filename().string();
        if (leaf.empty() || leaf[0] == '.') continue;
        queue.emplace_back(it->path(), depth + 1);
      }
    }
    return "";
  }
};

}  // namespace

std::string findPackage(const std::string& name, const LoadOptions& options) {
  std::error_code ec;
  const auto normal = [](const fs::path& p) { return fs::absolute(p).lexically_normal().string(); };
  for (const std::string& entry : searchPath(options)) {
    const fs::path p = fs::path(entry) / name;
    if (fs::is_directory(p, ec)) return normal(p);
  }
  for (const std::string& prefix : amentPrefixes(options)) {
    const fs::path p = fs::path(prefix) / "share" / name;
    if (fs::is_directory(p, ec)) return normal(p);
  }
  ManifestSearch search{name, {}, 0};
  for (const std::string& entry : searchPath(options)) {
    if (!fs::is_directory(entry, ec)) continue;
    std::string found = search.find(entry);
    if (!found.empty()) return fs::path(found).lexically_normal().string();
  }
  return "";
}

namespace io {

std::string resolveFile(const std::string& what, const std::string& uri, const std::string& base_dir,
                        const LoadOptions& options) {
  std::error_code ec;
  fs::path path;
  const std::string pkg = "package://", file = "file://";
  if (uri.rfind(pkg, 0) == 0) {
    // `package:///NAME/…` (three slashes, as some published descriptions
    // write it) is `package://NAME/…`; the loader warns about it.
    std::size_t start = pkg.size();
    while (start < uri.size() && uri[start] == '/') ++start;
    const std::string rest = uri.substr(start);
    const auto slash = rest.find('/');
    const std::string name = rest.substr(0, slash);
    if (name.empty()) throw SceneError(what + " '" + uri + "': no package name (write package://NAME/path/in/package, "
                                          "or a path relative to the file's folder)");
    const std::string dir = findPackage(name, options);
    if (dir.empty()) {
      std::string searched;
      for (const auto& e : searchPath(options)) searched += (searched.empty() ? "" : ":") + e;
      std::string prefixes;
      for (const auto& e : amentPrefixes(options)) prefixes += (prefixes.empty() ? "" : ":") + e;
      throw SceneError(what + " '" + uri + "': package '" + name + "' not found in the search path [" +
                       searched + "]" +
                       (prefixes.empty() ? "" : " nor under the AMENT_PREFIX_PATH prefixes [" + prefixes + "]") +
                       " (give --package-path / LoadOptions::package_paths, or set ROS_PACKAGE_PATH or "
                       "AMENT_PREFIX_PATH)");
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
    throw SceneError(what + " '" + uri + "': file not found: " + path.string());
  return path.string();
}

std::string packageUriNote(const std::string& uri) {
  const std::string three = "package:///";
  if (uri.rfind(three, 0) != 0) return "";
  std::size_t start = three.size();
  while (start < uri.size() && uri[start] == '/') ++start;
  return "'" + uri + "' read as 'package://" + uri.substr(start) +
         "' (a package URI has two slashes before the package name)";
}

}  // namespace io

std::string resolveMeshPath(const std::string& uri, const std::string& base_dir,
                            const LoadOptions& options) {
  return io::resolveFile("mesh", uri, base_dir, options);
}

}  // namespace appell
