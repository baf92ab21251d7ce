// Triangle meshes through assimp.
#include <appell/urdf.hpp>

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/config.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <filesystem>
#include <limits>
#include <map>
#include <functional>

namespace appell {

namespace {

// Collada's number lists must hold numbers only: indices (<p>, <v>,
// <vcount>, <int_array>) unsigned integers no larger than the file could
// hold values for, coordinates (<float_array>) decimal numbers. assimp 5.2.5
// reads a corrupted index list — a stray byte, or coordinates pasted into a
// <p> — as indices of billions and allocates gigabytes for them (13 GB and
// 40 s before std::bad_alloc), found by the mesh fuzzer
// (tests/data/fuzz-regressions/assimp_dae_*). So the lists are checked
// before assimp sees the file, and the first bad one is named.
void checkColladaNumbers(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // Every count="N" (arrays, accessors, primitives): assimp reserves N.
  for (std::size_t at = text.find("count=\""); at != std::string::npos; at = text.find("count=\"", at + 1)) {
    std::size_t value = 0, k = at + 7;
    for (; k < text.size() && std::isdigit(static_cast<unsigned char>(text[k])); ++k) {
      value = value * 10 + static_cast<std::size_t>(text[k] - '0');
      if (value > text.size()) {
        const long line = 1 + std::count(text.begin(), text.begin() + static_cast<long>(at), '\n');
        throw SceneError(path + ":" + std::to_string(line) + ": count=\"" + text.substr(at + 7, k - at - 6) +
                         "…\": more values than the file could hold: the file is damaged");
      }
    }
  }
  // Arrays, accessors and primitives must say how many values they hold
  // (assimp 5.2.5 dereferences a missing count: a segfault the fuzzer found).
  for (const char* tag : {"<float_array", "<int_array", "<accessor", "<triangles", "<polylist",
                          "<polygons", "<lines", "<linestrips", "<trifans", "<tristrips"}) {
    const std::size_t len = std::strlen(tag);
    for (std::size_t at = text.find(tag); at != std::string::npos; at = text.find(tag, at + 1)) {
      const char after = at + len < text.size() ? text[at + len] : '>';
      if (!std::isspace(static_cast<unsigned char>(after)) && after != '>' && after != '/') continue;
      const std::size_t open_end = text.find('>', at);
      const std::string open = text.substr(at, open_end == std::string::npos ? std::string::npos : open_end - at);
      if (open.find(" count=\"") == std::string::npos && open.find("\tcount=\"") == std::string::npos &&
          open.find("\ncount=\"") == std::string::npos) {
        const long line = 1 + std::count(text.begin(), text.begin() + static_cast<long>(at), '\n');
        throw SceneError(path + ":" + std::to_string(line) + ": " + std::string(tag) +
                         ">: has no count attribute (Collada requires it): the file is damaged");
      }
    }
  }
  struct List {
    const char* tag;
    bool indices;
  };
  static const List kLists[] = {{"<p>", true},       {"<p ", true},          {"<v>", true},
                                {"<v ", true},       {"<vcount", true},      {"<int_array", true},
                                {"<float_array", false}};
  for (const List& list : kLists) {
    for (std::size_t at = text.find(list.tag); at != std::string::npos; at = text.find(list.tag, at + 1)) {
      const std::size_t open_end = text.find('>', at);
      if (open_end == std::string::npos || text[open_end - 1] == '/') continue;
      const std::size_t close = text.find('<', open_end + 1);
      if (close == std::string::npos) break;
      std::string name(list.tag + 1);
      if (name.back() == ' ' || name.back() == '>') name.pop_back();
      auto bad = [&](std::size_t k, const std::string& why) {
        const long line = 1 + std::count(text.begin(), text.begin() + static_cast<long>(k), '\n');
        throw SceneError(path + ":" + std::to_string(line) + ": <" + name + ">: " + why +
                         ": the file is damaged");
      };
      std::size_t value = 0;
      for (std::size_t k = open_end + 1; k < close; ++k) {
        const unsigned char c = static_cast<unsigned char>(text[k]);
        if (std::isspace(c)) {
          value = 0;
          continue;
        }
        const bool ok = std::isdigit(c) || (!list.indices && (c == '.' || c == '-' || c == '+' || c == 'e' || c == 'E'));
        if (!ok) {
          char shown[8];
          std::snprintf(shown, sizeof shown, std::isprint(c) ? "'%c'" : "0x%02x", c);
          bad(k, std::string(list.indices ? "an index" : "a number") + " list holds " + shown);
        }
        if (list.indices) {
          value = value * 10 + static_cast<std::size_t>(c - '0');
          if (value > text.size())
            bad(k, "an index or count larger than the file could hold values for");
        }
      }
      at = close;
    }
  }
}

bool hasExtension(const std::string& path, const char* ext) {
  std::string e = std::filesystem::path(path).extension().string();
  for (char& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return e == ext;
}

}  // namespace

TriangleMesh loadMesh(const std::string& path, const Vec3& scale) {
  if (!std::filesystem::is_regular_file(path))
    throw SceneError(path + ": mesh file not found");
  if (!scale.allFinite() || scale.cwiseAbs().minCoeff() == 0)
    throw SceneError(path + ": mesh scale must be finite and non-zero");
  if (hasExtension(path, ".dae")) checkColladaNumbers(path);
  Assimp::Importer importer;
  // ROS tools take a Collada file's coordinates as they are (URDF frames are
  // z-up); assimp would otherwise rotate Z_UP files into its own y-up frame.
  importer.SetPropertyBool(AI_CONFIG_IMPORT_COLLADA_IGNORE_UP_DIRECTION, true);
  const aiScene* scene = importer.ReadFile(
      path, aiProcess_Triangulate | aiProcess_SortByPType);
  if (!scene || !scene->mRootNode) {
    const std::string why = importer.GetErrorString();
    // assimp refuses files whose meshes are all empty; say it the same way
    // as for meshes made of points and lines only.
    if (why.find("No meshes") != std::string::npos)
      throw SceneError(path + ": mesh has no triangles (" + why + ")");
    throw SceneError(path + ": cannot read mesh: " + why);
  }

  TriangleMesh out;
  out.source = path;
  // Walk the node hierarchy so that each mesh instance gets its node's
  // transform (Collada and OBJ groups place parts with transforms).
  // The node tree, walked with an explicit stack (a Collada file may nest
  // nodes 10⁴ deep: recursion would overflow the stack).
  std::vector<std::pair<const aiNode*, aiMatrix4x4>> pending{{scene->mRootNode, aiMatrix4x4()}};
  while (!pending.empty()) {
    const auto [node, parent] = pending.back();
    pending.pop_back();
    const aiMatrix4x4 T = parent * node->mTransformation;
    for (unsigned k = 0; k < node->mNumMeshes; ++k) {
      if (node->mMeshes[k] >= scene->mNumMeshes)
        throw SceneError(path + ": node '" + node->mName.C_Str() + "' names mesh " +
                         std::to_string(node->mMeshes[k]) + " of " + std::to_string(scene->mNumMeshes));
      const aiMesh* mesh = scene->mMeshes[node->mMeshes[k]];
      if (!(mesh->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
      if (out.vertices.size() + mesh->mNumVertices > static_cast<std::size_t>(std::numeric_limits<int>::max()))
        throw SceneError(path + ": more vertices than a mesh may have (" +
                         std::to_string(out.vertices.size() + mesh->mNumVertices) + ")");
      const int base = static_cast<int>(out.vertices.size());
      for (unsigned i = 0; i < mesh->mNumVertices; ++i) {
        const aiVector3D p = T * mesh->mVertices[i];
        out.vertices.emplace_back(scale.x() * p.x, scale.y() * p.y, scale.z() * p.z);
      }
      for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
        const aiFace& face = mesh->mFaces[f];
        if (face.mNumIndices != 3) continue;
        for (unsigned c = 0; c < 3; ++c)
          if (face.mIndices[c] >= mesh->mNumVertices)
            throw SceneError(path + ": face " + std::to_string(f) + " names vertex " +
                             std::to_string(face.mIndices[c]) + " but the mesh has " +
                             std::to_string(mesh->mNumVertices) + " vertices");
        out.triangles.push_back({base + static_cast<int>(face.mIndices[0]),
                                 base + static_cast<int>(face.mIndices[1]),
                                 base + static_cast<int>(face.mIndices[2])});
      }
    }
    for (unsigned c = 0; c < node->mNumChildren; ++c) pending.emplace_back(node->mChildren[c], T);
  }
  // Weld vertices at the same position: STL repeats corners per facet and
  // assimp keeps vertices apart when their normals differ; collision and
  // contact code want one vertex per corner.
  std::map<std::array<double, 3>, int> index;
  std::vector<int> remap(out.vertices.size());
  std::vector<Vec3> welded;
  for (std::size_t i = 0; i < out.vertices.size(); ++i) {
    const Vec3& v = out.vertices[i];
    const auto [it, inserted] = index.try_emplace({v.x(), v.y(), v.z()}, static_cast<int>(welded.size()));
    if (inserted) welded.push_back(v);
    remap[i] = it->second;
  }
  out.vertices = std::move(welded);
  std::vector<std::array<int, 3>> kept;
  for (const auto& t : out.triangles) {
    const std::array<int, 3> w = {remap[t[0]], remap[t[1]], remap[t[2]]};
    if (w[0] != w[1] && w[1] != w[2] && w[0] != w[2]) kept.push_back(w);  // drop collapsed ones
  }
  out.triangles = std::move(kept);
  if (out.triangles.empty()) throw SceneError(path + ": mesh has no triangles");
  for (const Vec3& v : out.vertices)
    if (!v.allFinite()) throw SceneError(path + ": mesh has a non-finite vertex");
  return out;
}

}  // namespace appell
