// Terrain meshes: validation, face normals, edge adjacency and FCL's hierarchy.
#include "terrain_index.hpp"

#include <fcl/geometry/bvh/detail/BV_splitter.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

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

// Longest root-to-leaf path, in nodes.
int hierarchyDepth(const fcl::BVHModel<fcl::OBBRSSd>& bvh, int node) {
  const auto& n = bvh.getBV(node);
  if (n.isLeaf()) return 1;
  return 1 + std::max(hierarchyDepth(bvh, n.leftChild()), hierarchyDepth(bvh, n.rightChild()));
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
  idx->edge.assign(nf, {-1, -1, -1});
  for (int f = 0; f < nf; ++f) {
    const auto& tri = t.triangles[f];
    idx->normal[f] = terrainFaceNormal(t, f);
    for (int k = 0; k < 3; ++k) {
      const int a = weld[tri[(k + 1) % 3]], b = weld[tri[(k + 2) % 3]];
      const auto key = std::minmax(a, b);
      auto [it, fresh] = edges.emplace(key, std::make_pair(f, k));
      if (fresh) {
        idx->edge[f][k] = static_cast<int>(idx->edge_ends.size());
        idx->edge_ends.push_back({key.first, key.second});
      } else {
        idx->edge[f][k] = idx->edge[it->second.first][it->second.second];
        // A third face on one edge is not a surface; keep the first pair.
        if (idx->neighbour[it->second.first][it->second.second] < 0) {
          idx->neighbour[it->second.first][it->second.second] = f;
          idx->neighbour[f][k] = it->second.first;
        }
      }
    }
  }
  // Regions: faces joined across edges whose two planes coincide (normals
  // equal and each face's vertices on the other's plane, to round-off).
  idx->region.assign(nf, -1);
  for (int f0 = 0; f0 < nf; ++f0) {
    if (idx->region[f0] >= 0) continue;
    const int r = static_cast<int>(idx->region_face.size());
    idx->region_face.push_back(f0);
    idx->region[f0] = r;
    std::vector<int> stack{f0};
    while (!stack.empty()) {
      const int f = stack.back();
      stack.pop_back();
      for (int k = 0; k < 3; ++k) {
        const int j = idx->neighbour[f][k];
        if (j < 0 || idx->region[j] >= 0) continue;
        const auto& tj = t.triangles[j];
        const double scale = (t.vertices[tj[1]] - t.vertices[tj[0]]).norm() +
                             (t.vertices[tj[2]] - t.vertices[tj[0]]).norm();
        const Vec3& a = t.vertices[t.triangles[f][0]];
        const bool coplanar = (idx->normal[j] - idx->normal[f]).norm() <= 1e-12 &&
                              std::abs(idx->normal[f].dot(t.vertices[tj[0]] - a)) <= 1e-12 * scale &&
                              std::abs(idx->normal[f].dot(t.vertices[tj[1]] - a)) <= 1e-12 * scale &&
                              std::abs(idx->normal[f].dot(t.vertices[tj[2]] - a)) <= 1e-12 * scale;
        if (!coplanar) continue;
        idx->region[j] = r;
        stack.push_back(j);
      }
    }
  }
  idx->regions = static_cast<int>(idx->region_face.size());
  idx->edges = static_cast<int>(idx->edge_ends.size());
  // Each edge's faces, and each welded vertex's edges (compressed rows).
  idx->edge_face.assign(idx->edges, {-1, -1});
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) {
      auto& ef = idx->edge_face[idx->edge[f][k]];
      if (ef[0] < 0) ef[0] = f;
      else if (ef[1] < 0 && ef[0] != f) ef[1] = f;
    }
  const int nv = static_cast<int>(t.vertices.size());
  idx->edge_normal.assign(idx->edges, Vec3::Zero());
  for (int e = 0; e < idx->edges; ++e)
    for (int f : idx->edge_face[e])
      if (f >= 0) idx->edge_normal[e] += idx->normal[f];
  idx->vertex_normal.assign(nv, Vec3::Zero());
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) {
      const auto& tri = t.triangles[f];
      const Vec3& x = t.vertices[tri[k]];
      const Vec3 a = (t.vertices[tri[(k + 1) % 3]] - x).normalized();
      const Vec3 b = (t.vertices[tri[(k + 2) % 3]] - x).normalized();
      idx->vertex_normal[weld[tri[k]]] += std::acos(std::clamp(a.dot(b), -1.0, 1.0)) * idx->normal[f];
    }
  for (Vec3& n : idx->edge_normal) n.normalize();
  for (Vec3& n : idx->vertex_normal)
    if (n.norm() > 0) n.normalize();
  idx->vertex_edge_start.assign(nv + 1, 0);
  for (const auto& ends : idx->edge_ends)
    for (int v : ends) ++idx->vertex_edge_start[v + 1];
  for (int v = 0; v < nv; ++v) idx->vertex_edge_start[v + 1] += idx->vertex_edge_start[v];
  idx->vertex_edge.assign(idx->vertex_edge_start[nv], -1);
  {
    std::vector<int> fill(idx->vertex_edge_start.begin(), idx->vertex_edge_start.end() - 1);
    for (int e = 0; e < idx->edges; ++e)
      for (int v : idx->edge_ends[e]) idx->vertex_edge[fill[v]++] = e;
  }
  idx->weld = std::move(weld);
  idx->bvh = detail::buildHierarchy(t.vertices, t.triangles, true);
  if (!idx->bvh) fail("FCL could not build its bounding-volume hierarchy");
  idx->depth = hierarchyDepth(*idx->bvh, 0);
  if (idx->depth >= detail::kTerrainStack) fail("bounding-volume hierarchy too deep");
  t.index = std::move(idx);
  return t;
}

std::string terrainFeatureName(const TerrainMesh& t, int feature) {
  if (!t.index || feature < 0) return "no piece";
  const TerrainIndex& idx = *t.index;
  const int nf = static_cast<int>(t.triangles.size());
  if (feature < idx.regions) {
    std::string faces;
    int count = 0;
    for (int f = 0; f < nf; ++f) {
      if (idx.region[f] != feature) continue;
      if (++count <= 4) faces += (count > 1 ? ", " : "") + std::to_string(f);
    }
    if (count == 1) return "face " + faces;
    return "flat region of faces " + faces + (count > 4 ? ", … (" + std::to_string(count) + ")" : "");
  }
  feature -= idx.regions;
  if (feature < idx.edges) {
    int first = -1, second = -1;
    for (int f = 0; f < nf && second < 0; ++f)
      for (int k = 0; k < 3; ++k)
        if (idx.edge[f][k] == feature) {
          if (first < 0) first = f;
          else if (f != first) second = f;
        }
    if (second < 0) return "boundary edge of face " + std::to_string(first);
    return "edge between faces " + std::to_string(first) + " and " + std::to_string(second);
  }
  return "vertex " + std::to_string(feature - idx.edges);
}

namespace detail {

std::shared_ptr<fcl::BVHModel<fcl::OBBRSSd>> buildHierarchy(
    const std::vector<Vec3>& vertices, const std::vector<std::array<int, 3>>& triangles,
    bool median) {
  auto bvh = std::make_shared<fcl::BVHModel<fcl::OBBRSSd>>();
  // The median split keeps the depth at ⌈log₂ n⌉ + 1 (FCL's default mean
  // split can be deep on clustered meshes, and the query stack is fixed).
  if (median)
    bvh->bv_splitter = std::make_shared<fcl::detail::BVSplitter<fcl::OBBRSSd>>(
        fcl::detail::SPLIT_METHOD_MEDIAN);
  std::vector<fcl::Triangle> tris;
  tris.reserve(triangles.size());
  for (const auto& tri : triangles) tris.emplace_back(tri[0], tri[1], tri[2]);
  if (bvh->beginModel(static_cast<int>(tris.size()), static_cast<int>(vertices.size())) !=
          fcl::BVH_OK ||
      bvh->addSubModel(vertices, tris) != fcl::BVH_OK || bvh->endModel() != fcl::BVH_OK)
    return nullptr;
  return bvh;
}

}  // namespace detail
}  // namespace appell
