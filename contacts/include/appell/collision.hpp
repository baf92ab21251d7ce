// FCL collision geometry of contact shapes and supports, and FCL's distance
// query for any declared pair (Pan, Chitta & Manocha, "FCL: a general purpose
// library for collision and proximity queries", ICRA 2012).
//
// What FCL is for here. While a smooth contact is closed, its geometry is the
// exact analytic one (contact_geometry.hpp): the rolling rows need the
// contact point to round-off and the curvature Σ of the Gauss map, which no
// GJK/EPA witness point supplies (measured in docs/contacts.md §9: on a disk
// against a plane FCL's gap agrees to 1e-13 but its witness point drifts
// 1e-7…1e-5 m along the rim tangent, where the distance is flat to second
// order).
// FCL supplies what the analytic pairs do not: the gap, witness points and
// normal of any declared pair (a box, cylinder or mesh against a support),
// and the bounding-volume hierarchy of terrain meshes (terrain_index.hpp).
//
// Representations (shape frame → FCL):
//   Point → sphere of radius 0      Sphere, Ellipsoid, Box, Cylinder → the same primitive
//   Disk  → cylinder of length 0    Mesh → BVHModel<OBBRSS> of its triangles
//   Torus, SphericalCap → none (FCL has no torus or spherical cap; refused by name)
// Supports (support frame → FCL):
//   Plane → a slab: a box whose top face is the plane, `plane_extent` wide
//           (FCL 0.7's distance query dereferences a null support function for
//           Halfspace and Plane: it crashes, so they are not used)
//   SphereSurface outside → sphere; inside (a bowl) → none (FCL has no
//           concave shell; refused by name)
//   TerrainMesh → the terrain's own BVHModel (shared, not copied)
#pragma once

#include <appell/shapes.hpp>
#include <appell/supports.hpp>

#include <memory>

namespace appell {

/// An FCL geometry with its pose in the frame of the body or support that
/// carries it (opaque: FCL stays a private dependency).
class CollisionGeometry;

/// Half-width of the slab that stands for a plane (metres): distances are
/// exact for bodies within this distance of the plane's origin point.
constexpr double kPlaneExtent = 1e3;

/// Throws std::invalid_argument naming the shape and why FCL cannot represent
/// it (torus, spherical cap, a mesh without triangles).
std::shared_ptr<const CollisionGeometry> makeCollisionGeometry(const Shape& shape);
/// Throws std::invalid_argument naming the support and why (a spherical bowl,
/// a terrain without its index).
std::shared_ptr<const CollisionGeometry> makeCollisionGeometry(const Support& support);

/// Gap, witness points and normal of a pair (world frame).
struct Proximity {
  double distance = 0;       ///< > 0 apart; ≤ 0 touching or penetrating (depth = −distance for
                             ///< shape pairs; a mesh pair gives −1: use collide() for its depth)
  Vec3 body_point = Vec3::Zero();     ///< nearest (deepest) point of the body's geometry
  Vec3 support_point = Vec3::Zero();  ///< nearest point of the support
  Vec3 normal = Vec3::UnitZ();        ///< unit, from the support toward the body
};

/// FCL's distance query between a body geometry at world pose `body_pose` and
/// a support geometry whose frame is at `support_pose`. Signed: penetration
/// depth from FCL's EPA for primitive pairs. Allocates (FCL's traversal).
Proximity proximity(const CollisionGeometry& body, const SE3& body_pose,
                    const CollisionGeometry& support, const SE3& support_pose);

/// True when the two geometries overlap (FCL's collide), with the deepest
/// contact point in `point` (world) and its penetration depth in `depth`
/// when given. Use this, not proximity(), for how deep a mesh pair
/// overlaps: FCL's distance of an overlapping shape–mesh pair is −1, a flag,
/// not a depth. Allocates.
bool collide(const CollisionGeometry& body, const SE3& body_pose,
             const CollisionGeometry& support, const SE3& support_pose, Vec3* point = nullptr,
             double* depth = nullptr);

}  // namespace appell
