// Homogeneous ball rolling without slipping on a plane, fixed or turning.
//
// On a turntable turning at Ω about the vertical through c, the support moves
// (b ≠ 0 in A v + b = 0). With I = (2/5) m r² the no-slip condition
// differentiated in time, with m a_G = F and I ω̇ = −r e_z × F, gives
//     a_G = (2/7) Ω e_z × v_G,
// so the centre's velocity turns at 2Ω/7 and the centre runs round a circle
// (Routh; Earnshaw's ball on a turntable).
#pragma once

#include "scene.hpp"

#include <appell/contacts.hpp>

namespace appell::scenes {

struct BallParams {
  double radius = 0.1;
  double mass = 0.5;
  Vec3 centre = Vec3(0.3, 0.0, 0.0);   ///< initial centre (z is set from the radius)
  Vec3 omega = Vec3(1.0, -2.0, 0.5);   ///< initial world angular velocity
  double turntable_rate = 0.0;         ///< Ω (0: a fixed plane)
  Vec3 turntable_centre = Vec3::Zero();
  double duration = 5.0;
};

inline BuiltScene ball(const BallParams& p = {}) {
  ModelBuilder b;
  const double I = 0.4 * p.mass * p.radius * p.radius;
  const int body = b.addBody("ball", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(),
                             principalInertia(p.mass, Vec3(I, I, I)), "free");
  BuiltScene s;
  const bool turning = p.turntable_rate != 0.0;
  s.name = turning ? "ball_on_turntable" : "ball_on_plane";
  s.model = b.build();
  Support support{Plane{}, StaticMotion{}, turning ? "turntable" : "ground"};
  if (turning) support.motion = turntable(p.turntable_centre, Vec3::UnitZ(), p.turntable_rate);
  s.constraints.push_back(makeContact(ContactKind::Rolling, body, Sphere{p.radius, Vec3::Zero()}, support,
                                      ContactOptions{"ball_contact", Vec3::Zero(), {}}));
  const Vec3 G(p.centre.x(), p.centre.y(), p.radius);
  const Vec3 P(p.centre.x(), p.centre.y(), 0);
  const Vec3 vP = p.turntable_rate * Vec3::UnitZ().cross(P - p.turntable_centre);  // support material velocity
  s.q0 = neutralConfiguration(s.model);
  setFloatingPose(s.q0, 0, G, Mat3::Identity());
  s.v0 = floatingVelocity(Mat3::Identity(), p.omega, vP + p.omega.cross(G - P));
  s.duration = p.duration;
  return s;
}

inline BuiltScene ballOnTurntable(double rate = 2.0, BallParams p = {}) {
  p.turntable_rate = rate;
  return ball(p);
}

}  // namespace appell::scenes
