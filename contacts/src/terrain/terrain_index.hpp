// Private layout of a terrain's index: face planes, edge neighbours and FCL's
// bounding-volume hierarchy over the triangles (built once, queried without
// allocation).
//
// The hierarchy is FCL's BVHModel with OBBRSS volumes (Larsen, Gottschalk,
// Lin & Manocha, "Fast proximity queries with swept sphere volumes", 1999;
// Gottschalk, Lin & Manocha, "OBBTree", SIGGRAPH 1996), split at the median so
// that its depth is ⌈log₂ faces⌉ + 1. The same model serves FCL's own
// distance and collision queries (collision.hpp). For the per-evaluation
// candidate search the contact code walks FCL's nodes itself with a
// fixed-size stack: FCL's query entry points fill std::vectors of results,
// and a contact evaluation must not allocate.
#pragma once

#include <appell/contact_geometry.hpp>
#include <appell/terrain.hpp>

#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/math/bv/OBBRSS.h>

#include <span>

namespace appell {

struct TerrainIndex {
  std::vector<Vec3> normal;                      ///< unit face normals (support frame)
  /// neighbour[f][k]: the face across the edge opposite vertex k of f, or −1.
  std::vector<std::array<int, 3>> neighbour;
  // Features: the pieces a contact can touch, each with one id
  // (ContactGeometry::feature). A *region* is a set of edge-connected faces on
  // one plane — a flat patch of many triangles is one piece, since the plane
  // contact is the same on all of them; then the edges (welded vertex pairs)
  // and the (welded) vertices:
  //   region r → r,   edge e → regions + e,   vertex v → regions + edges + v.
  std::vector<int> region;                       ///< per face: its region
  std::vector<int> region_face;                  ///< per region: one of its faces
  std::vector<std::array<int, 3>> edge;          ///< per face: the id of its edge k (opposite vertex k)
  std::vector<std::array<int, 2>> edge_ends;     ///< per edge: its two (welded) vertices
  std::vector<int> weld;                         ///< per vertex: the first vertex at its position
  std::vector<std::array<int, 2>> edge_face;     ///< per edge: its (first two) faces, −1 if none
  /// Angle-weighted pseudonormals of the edges and (welded) vertices: the
  /// side of the surface a point nearest to them lies on is the sign of
  /// (p − x)·N (Bærentzen & Aanæs, "Signed distance computation using the
  /// angle weighted pseudonormal", IEEE TVCG 2005).
  std::vector<Vec3> edge_normal, vertex_normal;
  /// Per welded vertex v: its edges are vertex_edge[vertex_edge_start[v] …
  /// vertex_edge_start[v + 1]) (a separate point's test, separatePiece).
  std::vector<int> vertex_edge_start, vertex_edge;
  int regions = 0, edges = 0;
  int regionFeature(int f) const { return region[f]; }
  int edgeFeature(int f, int k) const { return regions + edge[f][k]; }
  int vertexFeature(int v) const { return regions + edges + weld[v]; }
  /// FCL's hierarchy over the triangles (one triangle per leaf, leaf
  /// primitiveId() = index into TerrainMesh::triangles).
  std::shared_ptr<fcl::BVHModel<fcl::OBBRSSd>> bvh;
  int depth = 0;                                 ///< longest root-to-leaf path (nodes)
};

namespace detail {

/// FCL's hierarchy over a triangle list (one triangle per leaf), split at the
/// median when `median` (depth ⌈log₂ n⌉ + 1), else by FCL's default; null when
/// FCL refuses the triangles.
std::shared_ptr<fcl::BVHModel<fcl::OBBRSSd>> buildHierarchy(
    const std::vector<Vec3>& vertices, const std::vector<std::array<int, 3>>& triangles,
    bool median);

/// Depth the query stack must hold; makeTerrain refuses deeper trees (the
/// median split never builds one below 2⁶³ faces).
constexpr int kTerrainStack = 64;

/// Calls visit(face) for every face whose bounding volume's axis-aligned box
/// overlaps [lo, hi]. No allocation.
template <class F>
void forEachFaceInBox(const TerrainIndex& index, const Vec3& lo, const Vec3& hi, F&& visit) {
  const auto& bvh = *index.bvh;
  if (bvh.getNumBVs() == 0) return;
  int stack[kTerrainStack];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const auto& node = bvh.getBV(stack[--top]);
    // The box of the node's oriented box: centre To, half-widths |axis|·extent.
    const auto& obb = node.bv.obb;
    const Vec3 half = obb.axis.cwiseAbs() * obb.extent;
    if (((obb.To - half).array() > hi.array()).any() ||
        ((obb.To + half).array() < lo.array()).any())
      continue;
    if (node.isLeaf()) {
      visit(node.primitiveId());
    } else {
      stack[top++] = node.leftChild();
      stack[top++] = node.rightChild();
    }
  }
}

/// The contact geometry of a shape on a terrain (terrain.hpp): the plane
/// geometry of the holding face with the smallest gap, or singular over an
/// edge or vertex.
/// `latched` ≥ 0: with that feature only (TerrainIndex numbers them),
/// extended past its bounds.
/// `excluded` non-empty (the pieces the other points of the same pair hold):
/// the nearest separate piece (separatePiece) not among them within a reach
/// of the body's size; when there is none, out.feature = −1 and out.gap =
/// that reach (a lower bound of the gap, continuous as pieces come in reach).
void terrainGeometry(const Shape& shape, const TerrainMesh& terrain, const SupportState& S,
                     const SE3& pose, const Vec6& V, ContactGeometry& out,
                     const GeometryOptions& opt, int latched = -1,
                     std::span<const int> excluded = {});

/// A sphere on a terrain: the contact at the mesh point nearest to its
/// centre — on a face (the plane contact), an edge or a vertex — or at the
/// nearest point of the latched feature's plane, line or vertex
/// (terrain_sphere.cpp).
void terrainSphereGeometry(const Sphere& sphere, const TerrainMesh& terrain, const SupportState& S,
                           const SE3& pose, const Vec6& V, ContactGeometry& out,
                           const GeometryOptions& opt, int latched,
                           std::span<const int> excluded = {});

/// No piece in reach of an excluded search: gap = reach, normal along the
/// support's z axis, feature −1 (not singular: an open contact's watch).
void noPieceInReach(const SupportState& S, const SE3& pose, double reach, ContactGeometry& out);

/// Whether the piece `feature` is a separate place where the body touches
/// or nears the terrain: the distance from the body to the surface has a
/// local minimum on it, with n (support frame, from the piece toward the body)
/// the contact normal there. A region always is (its face holds the point);
/// an edge when n leans out of both its faces (n · u_f < −1e-9 for each face
/// f, u_f the face's direction away from the edge in its plane); a vertex
/// when n leans away from all its edges. An edge inside a flat region, a
/// concave crease or a vertex inside a face never is (their nearest points
/// are on a face). These are the Voronoi tests of the pieces (Ericson,
/// Real-Time Collision Detection, 2005, §5.1.5) over the whole surface.
bool separatePiece(const TerrainMesh& terrain, int feature, const Vec3& n);

/// The point of piece `feature` nearest to p (support frame): on a region's
/// plane, an edge's line or at a vertex — the piece extended, as latched.
Vec3 nearestOnPiece(const TerrainMesh& terrain, int feature, const Vec3& p);

/// Two contact points closer than this (relative to the body's size) are one
/// place of contact: a separate piece there is the held one's neighbour.
constexpr double kSamePlace = 1e-6;

/// Whether `feature` is one of `excluded`.
inline bool excludedPiece(std::span<const int> excluded, int feature) {
  for (int e : excluded)
    if (e == feature) return true;
  return false;
}

/// A point of the shape to measure from (its centre; a pose origin for the
/// collision-only shapes) and the radius of a ball about it holding the shape.
Vec3 shapeCentre(const Shape& shape);
double boundingRadius(const Shape& shape);
/// The point of triangle (a, b, c) nearest to p (terrain_sphere.cpp).
Vec3 nearestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

/// A smooth shape against the terrain edge from a_s to b_s (support frame):
/// false when the nearest point of the line lies beyond the segment (only
/// when `segment`: a latched edge is its whole line), the solve does not
/// converge, or the contact is singular (terrain_features.cpp).
bool terrainEdgeGeometry(const Shape& shape, const Vec3& a_s, const Vec3& b_s,
                         const SupportState& S, const SE3& pose, const Vec6& V,
                         ContactGeometry& out, const GeometryOptions& opt, bool segment = true);
/// A smooth shape against the terrain vertex x_s: false when singular.
bool terrainVertexGeometry(const Shape& shape, const Vec3& x_s, const SupportState& S,
                           const SE3& pose, const Vec6& V, ContactGeometry& out,
                           const GeometryOptions& opt);

}  // namespace detail
}  // namespace appell
