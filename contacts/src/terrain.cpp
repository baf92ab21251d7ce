// Terrain meshes: validation, face normals, edge adjacency and the box tree.
#include "terrain_index.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>

namespace appell {

namespace {

[[noreturn]] void fail(const std::string& what) {
  throw std::invalid_argument("terrain mesh: " + what);
}

Vec3 rawNormal(const TerrainMesh& t, int f) {
  const auto& tri = t.triangles[f];
  const Vec3& a = t.vertices[tri[0]];
  return (t.vertices[tri[1]] - a).cross(t.vertices[tri[2]] - a);
}

// Median split along the longest axis of the centroids' box; leaves of ≤ 4 faces.
int build(const TerrainMesh& t, TerrainIndex& idx, std::vector<Vec3>& centroid, int first,
          int count, int depth) {
  idx.depth = std::max(idx.depth, depth);
  const int id = static_cast<int>(idx.nodes.size());
  idx.nodes.emplace_back();
  Vec3 lo = Vec3::Constant(INFINITY), hi = Vec3::Constant(-INFINITY);
  Vec3 clo = lo, chi = hi;
  for (int k = first; k < first + count; ++k) {
    const int f = idx.order[k];
    for (int v : t.triangles[f]) {
      lo = lo.cwiseMin(t.vertices[v]);
      hi = hi.cwiseMax(t.vertices[v]);
    }
    clo = clo.cwiseMin(centroid[f]);
    chi = chi.cwiseMax(centroid[f]);
  }
  idx.nodes[id].lo = lo;
  idx.nodes[id].hi = hi;
  if (count <= 4) {
    idx.nodes[id].first = first;
    idx.nodes[id].count = count;
    return id;
  }
  int axis = 0;
  (chi - clo).maxCoeff(&axis);
  const int half = count / 2;
  std::nth_element(idx.order.begin() + first, idx.order.begin() + first + half,
                   idx.order.begin() + first + count,
                   [&](int a, int b) { return centroid[a](axis) < centroid[b](axis); });
  const int left = build(t, idx, centroid, first, half, depth + 1);
  const int right = build(t, idx, centroid, first + half, count - half, depth + 1);
  idx.nodes[id].left = left;
  idx.nodes[id].right = right;
  return id;
}

}  // namespace

void validateTerrain(const TerrainMesh& t) {
  if (t.triangles.empty()) fail("has no triangles");
  const int nv = static_cast<int>(t.vertices.size());
  for (int v = 0; v < nv; ++v)
    if (!t.vertices[v].allFinite()) fail("vertex " + std::to_string(v) + " is not finite");
  for (int f = 0; f < static_cast<int>(t.triangles.size()); ++f) {
    const auto& tri = t.triangles[f];
    for (int v : tri)
      if (v < 0 || v >= nv)
        fail("triangle " + std::to_string(f) + " has vertex index " + std::to_string(v) +
             " out of range (the mesh has " + std::to_string(nv) + " vertices)");
    double longest = 0;
    for (int k = 0; k < 3; ++k)
      longest = std::max(longest, (t.vertices[tri[(k + 1) % 3]] - t.vertices[tri[k]]).squaredNorm());
    // |(b − a) × (c − a)| = 2·area; relative to the longest edge squared so the
    // test does not depend on the mesh's units.
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] ||
        rawNormal(t, f).norm() <= 1e-12 * longest || longest == 0)
      fail("triangle " + std::to_string(f) + " (vertices " + std::to_string(tri[0]) + ", " +
           std::to_string(tri[1]) + ", " + std::to_string(tri[2]) +
           ") is degenerate: it has no normal");
  }
}

Vec3 terrainFaceNormal(const TerrainMesh& t, int face) { return rawNormal(t, face).normalized(); }

TerrainMesh makeTerrain(std::vector<Vec3> vertices, std::vector<std::array<int, 3>> triangles) {
  TerrainMesh t;
  t.vertices = std::move(vertices);
  t.triangles = std::move(triangles);
  validateTerrain(t);
  const int nf = static_cast<int>(t.triangles.size());
  auto idx = std::make_shared<TerrainIndex>();
  idx->normal.resize(nf);
  idx->neighbour.assign(nf, {-1, -1, -1});
  std::vector<Vec3> centroid(nf);
  // Vertices welded by position: STL files repeat each vertex per triangle,
  // and edge neighbours must still be found.
  std::vector<int> weld(t.vertices.size());
  {
    std::map<std::array<double, 3>, int> seen;
    for (int v = 0; v < static_cast<int>(t.vertices.size()); ++v) {
      const Vec3& x = t.vertices[v];
      weld[v] = seen.emplace(std::array<double, 3>{x.x(), x.y(), x.z()}, v).first->second;
    }
  }
  // Edge (i, j) with i < j (welded) → (face, local vertex opposite the edge).
  std::map<std::pair<int, int>, std::pair<int, int>> edges;
  for (int f = 0; f < nf; ++f) {
    const auto& tri = t.triangles[f];
    idx->normal[f] = terrainFaceNormal(t, f);
    centroid[f] = (t.vertices[tri[0]] + t.vertices[tri[1]] + t.vertices[tri[2]]) / 3.0;
    for (int k = 0; k < 3; ++k) {
      const int a = weld[tri[(k + 1) % 3]], b = weld[tri[(k + 2) % 3]];
      const auto key = std::minmax(a, b);
      auto [it, fresh] = edges.emplace(key, std::make_pair(f, k));
      if (!fresh) {
        // A third face on one edge is not a surface; keep the first pair.
        if (idx->neighbour[it->second.first][it->second.second] < 0) {
          idx->neighbour[it->second.first][it->second.second] = f;
          idx->neighbour[f][k] = it->second.first;
        }
      }
    }
  }
  idx->order.resize(nf);
  std::iota(idx->order.begin(), idx->order.end(), 0);
  idx->nodes.reserve(2 * nf);
  build(t, *idx, centroid, 0, nf, 1);
  if (idx->depth >= detail::kTerrainStack) fail("box tree too deep");
  t.index = std::move(idx);
  return t;
}

}  // namespace appell
