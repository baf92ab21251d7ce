// Triangle meshes through assimp, behind the gate of mesh/mesh_gate.hpp
// (bounded read, format sniffed from the content, the format's sizes and
// Collada's node graph bounded): the node tree walked with its transforms,
// every vertex checked finite as it is placed, then welded.
#include <appell/urdf.hpp>

#include "mesh/mesh_gate.hpp"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/config.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <unordered_map>

namespace appell {

namespace {

// A vertex that is NaN or infinite (as read, or once placed and scaled: a
// float coordinate of 1e300 is already infinite) is refused by its index in
// its mesh — for an STL file vertex i is corner i % 3 of facet i / 3.
[[noreturn]] void throwNonFiniteVertex(const std::string& path, const aiMesh& mesh, unsigned i,
                                       const Vec3& placed) {
  const aiVector3D& raw = mesh.mVertices[i];
  char coordinates[96];
  std::snprintf(coordinates, sizeof coordinates, "(%g, %g, %g)", static_cast<double>(raw.x),
                static_cast<double>(raw.y), static_cast<double>(raw.z));
  std::string why = "vertex " + std::to_string(i) + " of mesh '" + mesh.mName.C_Str() + "' is " + coordinates;
  if (std::isfinite(raw.x) && std::isfinite(raw.y) && std::isfinite(raw.z))
    why += " and (" + std::to_string(placed.x()) + ", " + std::to_string(placed.y()) + ", " +
           std::to_string(placed.z()) + ") once placed and scaled";
  throw SceneError(path + ": " + why + ": a mesh vertex must be finite");
}

// Every face checked before assimp's post-processing reads it: 1 to
// kMaxFaceCorners corners (its ear clipping is quadratic in them), each
// naming a vertex the mesh has (the triangulation reads the positions: an
// index past them was a segfault), and the mesh's primitive types recomputed
// from its faces (an importer that sets them wrong, or not at all, reached
// an ai_assert abort in the triangulation: PLY, NFF and AC3D files the mesh
// fuzzer made). The scene is the importer's own; it is fixed in place.
void checkFaces(const std::string& path, const aiScene& scene) {
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    aiMesh& mesh = *scene.mMeshes[m];
    const std::string where = path + ": mesh '" + mesh.mName.C_Str() + "'";
    if (mesh.mNumVertices > 0 && !mesh.mVertices) throw SceneError(where + " has no vertex positions");
    unsigned types = 0;
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices == 0 || !face.mIndices)
        throw SceneError(where + ": face " + std::to_string(f) + " has no corners: the file is damaged");
      if (face.mNumIndices > io::kMaxFaceCorners)
        throw SceneError(where + ": face " + std::to_string(f) + " has " + std::to_string(face.mNumIndices) +
                         " corners (at most " + std::to_string(io::kMaxFaceCorners) + " are triangulated)");
      for (unsigned c = 0; c < face.mNumIndices; ++c)
        if (face.mIndices[c] >= mesh.mNumVertices)
          throw SceneError(path + ": face " + std::to_string(f) + " names vertex " + std::to_string(face.mIndices[c]) +
                           " but the mesh has " + std::to_string(mesh.mNumVertices) + " vertices");
      types |= face.mNumIndices == 1   ? aiPrimitiveType_POINT
               : face.mNumIndices == 2 ? aiPrimitiveType_LINE
               : face.mNumIndices == 3 ? aiPrimitiveType_TRIANGLE
                                       : aiPrimitiveType_POLYGON;
    }
    mesh.mPrimitiveTypes = types;
  }
}

// The file through the gate, then through the one assimp importer of its
// sniffed format (from memory: assimp never opens the file by its name, so
// it never picks an importer by name or by its own content sniffing), the
// polygons bounded, then triangulated.
const aiScene* importMesh(Assimp::Importer& importer, const std::string& path) {
  const io::MeshFile file = io::readMeshFile(path);
  // ROS tools take a Collada file's coordinates as they are (URDF frames are
  // z-up); assimp would otherwise rotate Z_UP files into its own y-up frame.
  importer.SetPropertyBool(AI_CONFIG_IMPORT_COLLADA_IGNORE_UP_DIRECTION, true);
  const aiScene* scene =
      importer.ReadFileFromMemory(file.bytes.data(), file.bytes.size(), 0, io::assimpHint(file.format));
  if (scene && scene->mRootNode) {
    checkFaces(path, *scene);
    scene = importer.ApplyPostProcessing(aiProcess_Triangulate | aiProcess_SortByPType);
  }
  if (!scene || !scene->mRootNode) {
    const std::string why = importer.GetErrorString();
    // assimp refuses files whose meshes are all empty; say it the same way
    // as for meshes made of points and lines only.
    if (why.find("No meshes") != std::string::npos)
      throw SceneError(path + ": mesh has no triangles (" + why + ")");
    throw SceneError(path + ": cannot read mesh (" + io::formatName(file.format) + "): " + why);
  }
  return scene;
}

// Weld vertices at the same position: STL repeats corners per facet and
// assimp keeps vertices apart when their normals differ; collision and
// contact code want one vertex per corner. Triangles that collapse go.
// Every vertex is finite here (checked as it was placed).
// Hashed on the coordinates' bits, −0 made +0 first (the two compare
// equal): a std::map's O(n log n) comparisons were a tenth of `appell
// info`'s time on a published robot's visual meshes. Welded vertices keep
// the order of their first appearance, as before.
struct PointHash {
  std::size_t operator()(const std::array<double, 3>& p) const {
    std::size_t h = 0;
    for (const double x : p) h = (h ^ std::hash<double>{}(x)) * 0x100000001b3ull;
    return h;
  }
};

void weld(TriangleMesh& out) {
  std::unordered_map<std::array<double, 3>, int, PointHash> index;
  index.reserve(out.vertices.size());
  std::vector<int> remap(out.vertices.size());
  std::vector<Vec3> welded;
  for (std::size_t i = 0; i < out.vertices.size(); ++i) {
    const Vec3& v = out.vertices[i];
    const std::array<double, 3> key = {v.x() + 0.0, v.y() + 0.0, v.z() + 0.0};  // −0 → +0
    const auto [it, inserted] = index.try_emplace(key, static_cast<int>(welded.size()));
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
}

}  // namespace

TriangleMesh loadMesh(const std::string& path, const Vec3& scale) {
  if (!scale.allFinite() || scale.cwiseAbs().minCoeff() == 0)
    throw SceneError(path + ": mesh scale must be finite and non-zero");
  Assimp::Importer importer;
  const aiScene* scene = importMesh(importer, path);

  TriangleMesh out;
  out.source = path;
  // Walk the node hierarchy so that each mesh instance gets its node's
  // transform (Collada and OBJ groups place parts with transforms).
  // The node tree, walked with an explicit stack (no recursion of ours,
  // whatever the depth assimp built).
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
      if (out.vertices.size() + mesh->mNumVertices > io::kMaxMeshVertices)
        throw SceneError(path + ": more than " + std::to_string(io::kMaxMeshVertices) +
                         " vertices once every node's meshes are placed");
      const int base = static_cast<int>(out.vertices.size());
      for (unsigned i = 0; i < mesh->mNumVertices; ++i) {
        const aiVector3D p = T * mesh->mVertices[i];
        out.vertices.emplace_back(scale.x() * p.x, scale.y() * p.y, scale.z() * p.z);
        // Before the weld below: a NaN coordinate has no place in it (it
        // equals nothing, not even itself, and the triangles on it are void).
        if (!out.vertices.back().allFinite()) throwNonFiniteVertex(path, *mesh, i, out.vertices.back());
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
  weld(out);
  if (out.triangles.empty()) throw SceneError(path + ": mesh has no triangles");
  return out;
}

}  // namespace appell
