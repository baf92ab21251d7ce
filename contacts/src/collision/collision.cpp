// FCL geometry of shapes and supports, and its distance and collision queries
// (collision.hpp states the representations and why).
#include <appell/collision.hpp>
#include <appell/overloaded.hpp>

#include "terrain_index.hpp"

#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/distance.h>

#include <stdexcept>
#include <string>

namespace appell {

class CollisionGeometry {
 public:
  std::shared_ptr<fcl::CollisionGeometryd> geometry;
  SE3 local;  ///< pose of the FCL geometry's frame in the body or support frame
};

namespace {

// Rotation taking FCL's z axis (cylinder axis) onto unit `axis`.
Mat3 zOnto(const Vec3& axis) {
  return Eigen::Quaterniond::FromTwoVectors(Vec3::UnitZ(), axis.normalized()).toRotationMatrix();
}

std::shared_ptr<const CollisionGeometry> wrap(std::shared_ptr<fcl::CollisionGeometryd> g,
                                              const SE3& local) {
  auto out = std::make_shared<CollisionGeometry>();
  g->computeLocalAABB();
  out->geometry = std::move(g);
  out->local = local;
  return out;
}

[[noreturn]] void refuse(const std::string& what, const std::string& why) {
  throw std::invalid_argument(what + ": FCL cannot represent it (" + why + ")");
}

fcl::Transform3d toFcl(const SE3& x) {
  fcl::Transform3d t = fcl::Transform3d::Identity();
  t.linear() = x.R;
  t.translation() = x.p;
  return t;
}

std::shared_ptr<fcl::BVHModel<fcl::OBBRSSd>> meshModel(const Mesh& m) {
  auto bvh = detail::buildHierarchy(m.vertices, m.triangles, false);
  if (!bvh) refuse("mesh '" + m.file + "'", "FCL could not build its hierarchy");
  return bvh;
}

}  // namespace

std::shared_ptr<const CollisionGeometry> makeCollisionGeometry(const Shape& shape) {
  validateShape(shape);
  return std::visit(
      Overloaded{
          [](const PointShape& s) {
            return wrap(std::make_shared<fcl::Sphered>(0.0), {Mat3::Identity(), s.position});
          },
          [](const Sphere& s) {
            return wrap(std::make_shared<fcl::Sphered>(s.radius), {Mat3::Identity(), s.centre});
          },
          [](const Ellipsoid& s) {
            return wrap(std::make_shared<fcl::Ellipsoidd>(s.semi_axes), {s.orientation, s.centre});
          },
          [](const Disk& s) {
            return wrap(std::make_shared<fcl::Cylinderd>(s.radius, 0.0), {zOnto(s.axis), s.centre});
          },
          [](const Torus&) -> std::shared_ptr<const CollisionGeometry> {
            refuse("torus", "FCL has no torus primitive; a rolling torus uses the exact analytic "
                            "geometry");
          },
          [](const SphericalCap&) -> std::shared_ptr<const CollisionGeometry> {
            refuse("spherical cap", "FCL has no spherical-cap primitive; a rolling cap uses the "
                                    "exact analytic geometry");
          },
          [](const Box& s) {
            return wrap(std::make_shared<fcl::Boxd>(2.0 * s.half_extents), s.pose);
          },
          [](const Cylinder& s) {
            return wrap(std::make_shared<fcl::Cylinderd>(s.radius, s.length), s.pose);
          },
          [](const Mesh& s) -> std::shared_ptr<const CollisionGeometry> {
            if (s.triangles.empty())
              refuse("mesh '" + s.file + "'", "its triangles were not loaded");
            return wrap(meshModel(s), s.pose);
          }},
      shape);
}

std::shared_ptr<const CollisionGeometry> makeCollisionGeometry(const Support& support) {
  const std::string what = "support '" + support.name + "'";
  return std::visit(
      Overloaded{
          [&](const Plane& p) {
            // Slab: the box's top face is the plane, its centre kPlaneExtent
            // below the plane's point.
            const Vec3 n = p.normal.normalized();
            return wrap(std::make_shared<fcl::Boxd>(Vec3::Constant(2.0 * kPlaneExtent)),
                        {zOnto(n), p.point - kPlaneExtent * n});
          },
          [&](const SphereSurface& s) -> std::shared_ptr<const CollisionGeometry> {
            if (s.side == SphereSurface::Side::Inside)
              refuse(what, "the inside of a sphere (a bowl) is concave; FCL has no concave shell");
            return wrap(std::make_shared<fcl::Sphered>(s.radius), {Mat3::Identity(), s.centre});
          },
          [&](const TerrainMesh& t) -> std::shared_ptr<const CollisionGeometry> {
            if (!t.index) refuse(what, "the terrain's index is not built (use makeTerrain)");
            auto out = std::make_shared<CollisionGeometry>();
            out->geometry = t.index->bvh;
            return out;
          }},
      support.surface);
}

Proximity proximity(const CollisionGeometry& body, const SE3& body_pose,
                    const CollisionGeometry& support, const SE3& support_pose) {
  const fcl::CollisionObjectd a(body.geometry, toFcl(body_pose * body.local));
  const fcl::CollisionObjectd b(support.geometry, toFcl(support_pose * support.local));
  fcl::DistanceRequestd request(true);
  request.enable_signed_distance = true;
  request.distance_tolerance = 1e-12;
  request.gjk_solver_type = fcl::GST_LIBCCD;
  fcl::DistanceResultd result;
  Proximity out;
  out.distance = fcl::distance(&a, &b, request, result);
  const bool a_mesh = body.geometry->getObjectType() == fcl::OT_BVH;
  const bool b_mesh = support.geometry->getObjectType() == fcl::OT_BVH;
  if (a_mesh != b_mesh) {
    // FCL 0.7 returns a shape–mesh pair's nearest points in the objects' own
    // frames, the mesh's first, in either argument order (shape–shape and
    // mesh–mesh pairs: world frame, argument order). Measured; see
    // docs/contacts.md §9.
    const Vec3& on_mesh = result.nearest_points[0];
    const Vec3& on_shape = result.nearest_points[1];
    out.body_point = a.getTransform() * (a_mesh ? on_mesh : on_shape);
    out.support_point = b.getTransform() * (b_mesh ? on_mesh : on_shape);
  } else {
    out.body_point = result.nearest_points[0];
    out.support_point = result.nearest_points[1];
  }
  const Vec3 d = out.body_point - out.support_point;
  if (d.norm() > 0) out.normal = (out.distance < 0 ? -d : d).normalized();
  return out;
}

bool collide(const CollisionGeometry& body, const SE3& body_pose,
             const CollisionGeometry& support, const SE3& support_pose, Vec3* point,
             double* depth) {
  const fcl::CollisionObjectd a(body.geometry, toFcl(body_pose * body.local));
  const fcl::CollisionObjectd b(support.geometry, toFcl(support_pose * support.local));
  fcl::CollisionRequestd request(64, true);
  fcl::CollisionResultd result;
  fcl::collide(&a, &b, request, result);
  if (!result.isCollision()) return false;
  int deepest = 0;
  for (int k = 1; k < static_cast<int>(result.numContacts()); ++k)
    if (result.getContact(k).penetration_depth > result.getContact(deepest).penetration_depth)
      deepest = k;
  if (point) *point = result.getContact(deepest).pos;
  if (depth) *depth = result.getContact(deepest).penetration_depth;
  return true;
}

}  // namespace appell
