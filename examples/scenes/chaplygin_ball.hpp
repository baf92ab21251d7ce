// Chaplygin ball: a sphere whose mass distribution is not spherical — unequal
// principal moments, and optionally a centre of mass off the geometric centre
// (Chaplygin's "ball with displaced centre"). With the centre of mass at the
// geometric centre it is integrable (Chaplygin 1903): besides the energy, the
// angular momentum about the contact point, K = I_G ω + m r² n × (ω × n)
// (world frame, n the vertical), is conserved — the contact force passes
// through the contact point and gravity through the centre.
#pragma once

#include "scene.hpp"

#include <appell/contacts.hpp>

namespace appell::scenes {

struct ChaplyginBallParams {
  double radius = 0.1;
  double mass = 0.8;
  Vec3 principal = Vec3(0.0025, 0.0032, 0.0041);  ///< principal moments about the centre of mass
  Vec3 com_offset = Vec3::Zero();                 ///< centre of mass from the geometric centre (body)
  Mat3 orientation = axisAngle(Vec3(1, 2, 3).normalized(), 0.7);
  Vec3 omega = Vec3(2.0, -1.0, 3.0);              ///< initial world angular velocity
  double duration = 5.0;
};

/// Body frame origin at the geometric centre; the sphere is centred there.
inline BuiltScene chaplyginBall(const ChaplyginBallParams& p = {}) {
  ModelBuilder b;
  const int body = b.addBody("ball", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(),
                             principalInertia(p.mass, p.principal, p.com_offset), "free");
  BuiltScene s;
  s.name = p.com_offset.norm() > 0 ? "chaplygin_top_ball" : "chaplygin_ball";
  s.model = b.build();
  s.constraints.push_back(makeContact(ContactKind::Rolling, body, Sphere{p.radius, Vec3::Zero()},
                                      Support{Plane{}, StaticMotion{}, "ground"},
                                      ContactOptions{"ball_contact", Vec3::Zero(), {}}));
  const Vec3 O(0, 0, p.radius), P = Vec3::Zero();
  s.q0 = neutralConfiguration(s.model);
  setFloatingPose(s.q0, 0, O, p.orientation);
  s.v0 = floatingVelocity(p.orientation, p.omega, p.omega.cross(O - P));
  s.duration = p.duration;
  return s;
}

}  // namespace appell::scenes
