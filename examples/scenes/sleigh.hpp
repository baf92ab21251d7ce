// Chaplygin sleigh on an inclined plane: a rigid body on a knife edge (the
// blade) and two frictionless sliding supports (seed 002, Emelyanova & Fufaev).
//
// Incline of angle α through the origin: normal n = (0, sin α, cos α);
// in-plane axes e₁ = x (across the slope) and d = (0, cos α, −sin α) (down the
// slope), so n = e₁ × d. The seed's coordinates: blade point (x, y) = x e₁ + y d,
// blade direction (cos φ, sin φ) in (e₁, d), constraint ẋ sin φ − ẏ cos φ = 0.
// Body frame: origin at the blade point, x along the blade, z = n.
//   Seed variant: centre of mass at distance l PERPENDICULAR to the blade,
//     com = (0, −l, h): world offset l (sin φ, −cos φ), so the force function is
//     U = m g (y − l cos φ) sin α; equilibria φ = 0, π held by the blade,
//     λ = ±m g sin α on the seed's row.
//   Usual sleigh: centre of mass ahead of the blade, along it: com = (a, 0, h);
//     no static equilibrium on an incline.
// Two models: sleigh() — floating body with the contacts module (knife edge +
// two sliding supports, 4 rows, 3 of them holonomic normal rows);
// sleighReduced() — sliders x along e₁, y along d and a revolute φ about n,
// v = (ẋ, ẏ, φ̇) exactly the seed's, with the seed's row as a custom constraint.
#pragma once

#include "scene.hpp"

#include <appell/contacts.hpp>
#include <appell/custom_constraint.hpp>

#include <numbers>

namespace appell::scenes {

struct SleighParams {
  double mass = 2.0;
  Vec3 principal = Vec3(0.08, 0.12, 0.18);   ///< principal moments about the CoM (body axes)
  Vec3 com = Vec3(0, -0.3, 0.1);             ///< CoM in the body frame (blade point = origin)
  double incline = 0.35;                     ///< α
  /// The two sliding feet in the body frame (z = 0: on the plane).
  Vec3 foot1 = Vec3(0.5, -0.6, 0), foot2 = Vec3(-0.5, -0.6, 0);
  double x = 0, y = 0, heading = 0;          ///< initial blade point and φ
  double speed = 0.0;                        ///< initial speed along the blade
  double turn_rate = 0.0;                    ///< initial φ̇
  double duration = 5.0;
  std::string name = "chaplygin_sleigh";
};

/// The seed's sleigh: CoM at distance l perpendicular to the blade.
inline SleighParams seedSleighParams(double l = 0.3, double alpha = 0.35) {
  SleighParams p;
  p.com = Vec3(0, -l, 0.1);
  p.incline = alpha;
  p.foot1 = Vec3(0.5, -2 * l, 0);
  p.foot2 = Vec3(-0.5, -2 * l, 0);
  p.name = "seed_sleigh";
  return p;
}

/// The usual Chaplygin sleigh: CoM a distance `a` ahead of the blade, along it.
inline SleighParams usualSleighParams(double a = 0.3, double alpha = 0.35) {
  SleighParams p;
  p.com = Vec3(a, 0, 0.1);
  p.incline = alpha;
  p.foot1 = Vec3(0.8, 0.3, 0);
  p.foot2 = Vec3(0.8, -0.3, 0);
  p.name = "usual_sleigh";
  return p;
}

struct Incline {
  Vec3 e1, d, n;
};
inline Incline inclineFrame(double alpha) {
  return {Vec3::UnitX(), Vec3(0, std::cos(alpha), -std::sin(alpha)),
          Vec3(0, std::sin(alpha), std::cos(alpha))};
}

/// World rotation of the sleigh body at heading φ on the incline.
inline Mat3 sleighRotation(double alpha, double phi) {
  const Incline f = inclineFrame(alpha);
  const Vec3 blade = std::cos(phi) * f.e1 + std::sin(phi) * f.d;
  Mat3 R;
  R << blade, f.n.cross(blade), f.n;
  return R;
}

/// The seed's row direction (sin φ, −cos φ) in the world: a reaction λ on the
/// seed's row is the force λ·(this vector) at the blade point.
inline Vec3 seedRowDirection(double alpha, double phi) {
  const Incline f = inclineFrame(alpha);
  return std::sin(phi) * f.e1 - std::cos(phi) * f.d;
}

inline BuiltScene sleigh(const SleighParams& p = seedSleighParams()) {
  ModelBuilder b;
  b.setGravity(Vec3(0, 0, -9.81));
  const int body = b.addBody("sleigh", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(),
                             principalInertia(p.mass, p.principal, p.com), "free");
  BuiltScene s;
  s.name = p.name;
  s.model = b.build();
  const Incline f = inclineFrame(p.incline);
  const Support slope{Plane{Vec3::Zero(), f.n}, StaticMotion{}, "incline"};
  s.constraints.push_back(makeContact(ContactKind::KnifeEdge, body, PointShape{Vec3::Zero()}, slope,
                                      ContactOptions{"blade", Vec3::UnitX(), {}}));
  s.constraints.push_back(makeContact(ContactKind::Sliding, body, PointShape{p.foot1}, slope,
                                      ContactOptions{"foot1", Vec3::Zero(), {}}));
  s.constraints.push_back(makeContact(ContactKind::Sliding, body, PointShape{p.foot2}, slope,
                                      ContactOptions{"foot2", Vec3::Zero(), {}}));
  const Mat3 R = sleighRotation(p.incline, p.heading);
  const Vec3 P = p.x * f.e1 + p.y * f.d;
  s.q0 = neutralConfiguration(s.model);
  setFloatingPose(s.q0, 0, P, R);
  // Blade point moves along the blade; the body turns about the normal.
  s.v0 = floatingVelocity(R, p.turn_rate * f.n, p.speed * R.col(0));
  s.duration = p.duration;
  return s;
}

/// Sliders + revolute: q = v = (x, y, φ) as in the seed; one custom row
/// ẋ sin φ − ẏ cos φ = 0 (multiplier = the seed's λ).
inline BuiltScene sleighReduced(const SleighParams& p = seedSleighParams()) {
  ModelBuilder b;
  const Incline f = inclineFrame(p.incline);
  const Inertia none{0, Vec3::Zero(), Mat3::Zero()};
  const int bx = b.addBody("slider_x", -1, SE3::Identity(), JointType::Prismatic, f.e1, none, "x");
  const int by = b.addBody("slider_y", bx, SE3::Identity(), JointType::Prismatic, f.d, none, "y");
  SE3 onSlope;
  onSlope.R << f.e1, f.d, f.n;
  const int bs = b.addBody("sleigh", by, onSlope, JointType::Continuous, Vec3::UnitZ(),
                           principalInertia(p.mass, p.principal, p.com), "phi");
  BuiltScene s;
  s.name = p.name + "_reduced";
  s.model = b.build();
  CustomRows rows;
  rows.name = "blade";
  rows.rows = 1;
  rows.body = bs;
  rows.labels = {"lateral"};
  // A = (sin φ, −cos φ, 0); Ȧ v = φ̇ (ẋ cos φ + ẏ sin φ).
  rows.A_b = [](const Model&, const VecX& q, double, Eigen::Ref<MatX> A, Eigen::Ref<VecX> bb) {
    A(0, 0) = std::sin(q[2]);
    A(0, 1) = -std::cos(q[2]);
    A(0, 2) = 0;
    bb[0] = 0;
  };
  rows.bias = [](const Model&, const VecX& q, const VecX& v, double, Eigen::Ref<VecX> ab) {
    ab[0] = v[2] * (v[0] * std::cos(q[2]) + v[1] * std::sin(q[2]));
  };
  s.constraints.push_back(std::make_shared<CustomConstraint>(rows));
  s.q0 = VecX(3);
  s.q0 << p.x, p.y, p.heading;
  s.v0 = VecX(3);
  s.v0 << p.speed * std::cos(p.heading), p.speed * std::sin(p.heading), p.turn_rate;
  s.duration = p.duration;
  return s;
}

}  // namespace appell::scenes
