// Private layout of a terrain's index: face planes, edge neighbours and a
// bounding-box tree over the triangles (built once, queried without allocation).
#pragma once

#include <appell/contact_geometry.hpp>
#include <appell/terrain.hpp>

namespace appell {

struct TerrainIndex {
  struct Node {
    Vec3 lo, hi;           ///< box of the triangles below this node
    int left = -1, right = -1;
    int first = 0, count = 0;  ///< leaf: order[first, first + count)
  };
  std::vector<Vec3> normal;                      ///< unit face normals (support frame)
  /// neighbour[f][k]: the face across the edge opposite vertex k of f, or −1.
  std::vector<std::array<int, 3>> neighbour;
  std::vector<Node> nodes;                       ///< nodes[0] is the root
  std::vector<int> order;                        ///< face indices, grouped by leaf
  int depth = 0;                                 ///< longest root-to-leaf path (nodes)
};

namespace detail {

/// Depth the query stack must hold; makeTerrain refuses deeper trees (it never
/// builds one: the median split halves the faces at each level).
constexpr int kTerrainStack = 64;

/// Calls visit(face) for every face whose box overlaps [lo, hi]. No allocation.
template <class F>
void forEachFaceInBox(const TerrainIndex& index, const Vec3& lo, const Vec3& hi, F&& visit) {
  if (index.nodes.empty()) return;
  int stack[kTerrainStack];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const TerrainIndex::Node& n = index.nodes[stack[--top]];
    if ((n.lo.array() > hi.array()).any() || (n.hi.array() < lo.array()).any()) continue;
    if (n.count > 0) {
      for (int k = 0; k < n.count; ++k) visit(index.order[n.first + k]);
    } else {
      stack[top++] = n.left;
      stack[top++] = n.right;
    }
  }
}

/// The contact geometry of a shape on a terrain (terrain.hpp): the plane
/// geometry of the holding face with the smallest gap, or singular over an
/// edge or vertex.
void terrainGeometry(const Shape& shape, const TerrainMesh& terrain, const SupportState& S,
                     const SE3& pose, const Vec6& V, ContactGeometry& out,
                     const GeometryOptions& opt);

}  // namespace detail
}  // namespace appell
