// Solid ellipsoid rolling without slipping on a horizontal plane.
// Body frame at the centre along the principal axes (semi-axes a, b, c);
// moments m/5 (b² + c², a² + c², a² + b²). The centre's height over the plane
// is the support function h = √(nᵀ Q n), n = Rᵀ e_z, Q = diag(a², b², c²),
// and the contact point (body frame) is −Q n / h.
#pragma once

#include "scene.hpp"

#include <appell/contacts.hpp>

namespace appell::scenes {

struct EllipsoidParams {
  Vec3 semi_axes = Vec3(0.2, 0.14, 0.1);
  double mass = 1.0;
  Mat3 orientation = axisAngle(Vec3(1, -1, 2).normalized(), 0.5);
  Vec3 omega = Vec3(0.5, 1.0, 4.0);   ///< initial world angular velocity
  double duration = 5.0;
};

inline BuiltScene ellipsoidOnPlane(const EllipsoidParams& p = {}) {
  const Vec3& s2 = p.semi_axes.cwiseProduct(p.semi_axes);
  const Vec3 I = p.mass / 5.0 * Vec3(s2.y() + s2.z(), s2.x() + s2.z(), s2.x() + s2.y());
  ModelBuilder b;
  const int body = b.addBody("ellipsoid", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(),
                             principalInertia(p.mass, I), "free");
  BuiltScene s;
  s.name = "ellipsoid_on_plane";
  s.model = b.build();
  s.constraints.push_back(makeContact(ContactKind::Rolling, body,
                                      Ellipsoid{p.semi_axes, Vec3::Zero(), Mat3::Identity()},
                                      Support{Plane{}, StaticMotion{}, "ground"},
                                      ContactOptions{"ellipsoid_contact", Vec3::Zero(), {}}));
  const Vec3 n = p.orientation.transpose() * Vec3::UnitZ();
  const double h = std::sqrt(n.dot(s2.asDiagonal() * n));
  const Vec3 G(0, 0, h);
  const Vec3 P = G + p.orientation * (-(s2.asDiagonal() * n) / h);
  s.q0 = neutralConfiguration(s.model);
  setFloatingPose(s.q0, 0, G, p.orientation);
  s.v0 = floatingVelocity(p.orientation, p.omega, p.omega.cross(G - P));
  closeGaps(s.model, s.constraints, s.q0);
  projectVelocityEuclidean(s.model, s.constraints, s.q0, s.v0);
  s.duration = p.duration;
  return s;
}

}  // namespace appell::scenes
