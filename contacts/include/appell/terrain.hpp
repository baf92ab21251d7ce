// Terrain: a fixed (or rigidly moving) triangle mesh that bodies roll or slide
// on, treated as a piecewise-planar surface.
//
// Contact model of a sphere: the nearest point of the mesh to its centre, on
// a face, an edge or a vertex (terrain_sphere.cpp) — a ball pivots about the
// edges it rolls over. Every other shape: faces, then edges and vertices.
//
// Faces. For each candidate face f the shape is put against the plane
// of f exactly as on a Plane support (same Gauss-map point, rows and κ). The
// face "holds" the contact when the foot of that contact point on the plane
// lies inside the triangle (barycentric coordinates ≥ −1e-9). The shape
// touches the holding face with the smallest signed gap. Inside a face the
// contact is therefore exactly the plane contact: rolling on a face is exact.
// Edges and vertices. A triangle whose face does not hold the contact but
// whose plane is nearer than the best contact so far offers its edges (the
// shape's point nearest the edge's line, by Newton) and vertices (the
// outside of a radius-0 sphere) — terrain_features.cpp; the smallest gap
// wins. Only when none of these solves succeeds (a disk lying flat) is the
// geometry singular, with a reason naming the edge or the vertex, never an
// invented normal.
//
// Orientation. Each face's normal comes from its winding,
//   n = (b − a) × (c − a) / |…|   for the triangle (a, b, c),
// and must point to the side the bodies are on (+z for ground: counter-
// clockwise seen from above). Degenerate triangles (area ≈ 0), bad indices and
// non-finite vertices are rejected by makeTerrain / validateTerrain.
//
// Broad phase: FCL's bounding-volume hierarchy (OBBRSS) over the triangles,
// built once by makeTerrain; the query for a body walks it with the box of the
// body's extreme points and a fixed-size stack, so contact evaluation does not
// allocate. The same hierarchy answers FCL's distance queries (collision.hpp).
#pragma once

#include <appell/spatial.hpp>

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace appell {

/// Face planes, edge adjacency and FCL's hierarchy (private layout).
struct TerrainIndex;

struct TerrainMesh {
  std::vector<Vec3> vertices;                  ///< support frame
  std::vector<std::array<int, 3>> triangles;   ///< indices into vertices, oriented (see above)
  /// Built by makeTerrain; a contact builds it on construction when it is missing.
  std::shared_ptr<const TerrainIndex> index;
};

/// Validates the mesh (throws std::invalid_argument naming the triangle or
/// vertex and the reason) and builds its index.
TerrainMesh makeTerrain(std::vector<Vec3> vertices, std::vector<std::array<int, 3>> triangles);

/// Throws std::invalid_argument when the mesh is empty, a vertex is not finite,
/// an index is out of range or repeated, or a triangle is degenerate (its area
/// below 1e-12 of the squared longest edge).
void validateTerrain(const TerrainMesh& terrain);

/// Unit normal of triangle `face` from its winding (support frame).
Vec3 terrainFaceNormal(const TerrainMesh& terrain, int face);

/// Names a contact's piece of the terrain (ContactGeometry::feature): "face 3"
/// (a flat region of several faces: "flat region of faces 3, 4, …"), "edge
/// between faces 2 and 3" (or "boundary edge of face 2"), "vertex 7".
std::string terrainFeatureName(const TerrainMesh& terrain, int feature);

}  // namespace appell
