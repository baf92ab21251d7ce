// Thin disk rolling without slipping on a horizontal plane.
//
// Three models of the same body, each for a job:
//   rollingDisk()          free body (floating joint) + exact rolling rim contact
//                          — the general engine path (main scene);
//   verticalRollingDisk()  disk held upright: sliders x, y, heading φ about z,
//                          spin θ about the axle — the textbook system with the
//                          exact circle solution (REFERENCES.md);
//   rollingDiskChain()     planar joint (a, b, ψ) at the contact point, lean
//                          about the travel direction, spin about the axle: the
//                          position, heading and spin are cyclic coordinates
//                          (planar velocities are body-frame, the disk is
//                          axisymmetric), so steady motions are relative
//                          equilibria the linearization can reduce.
// Lean-frame conventions (rollingDisk): t = travel direction (horizontal, in the
// disk plane), u = in-plane "up" from the contact point to the centre, a = t × u
// the axle; lean θ = angle of u from vertical; ω = Ω e_z + (ω_a − Ω sin θ) a +
// θ̇ t, so ω·a = ω_a (rate about the axle) and ω·u = Ω cos θ.
#pragma once

#include "scene.hpp"

#include <appell/contacts.hpp>

namespace appell::scenes {

struct RollingDiskParams {
  double radius = 0.3;
  double mass = 1.2;
  double lean = 0.0;        ///< θ, rad (disk leans toward the heading frame's +y)
  double heading = 0.0;     ///< ψ, rad: travel direction (cos ψ, sin ψ, 0)
  double precession = 0.0;  ///< Ω: rate of turn about the vertical
  double axle_rate = 5.0;   ///< ω_a: angular velocity component along the axle
  double lean_rate = 0.0;   ///< θ̇
  Vec3 contact = Vec3::Zero();  ///< initial contact point (z ignored)
  double duration = 5.0;
};

/// Diametral and axial moments of a thin uniform disk: (m r²/4, m r²/2).
inline Vec3 thinDiskInertia(double m, double r) { return {m * r * r / 4, m * r * r / 4, m * r * r / 2}; }

/// ω_a making (lean θ, turn rate Ω) a steady circular rolling motion of a disk
/// with diametral moment A, axial moment C. Balance of angular momentum about
/// the centre, dH/dt = Ω e_z × H = (P − G) × F with F = m a_G + m g e_z:
///     Ω cos θ (C ω_a − A Ω sin θ) + m r (r ω_a Ω cos θ + g sin θ) = 0
/// (for A = m r²/4, C = m r²/2 this is REFERENCES.md's u̇₁ = 0 with u₂ = ω_a,
///  u₃ = Ω cos θ). Needs Ω cos θ ≠ 0.
inline double steadyDiskAxleRate(double m, double r, double A, double C, double g, double lean,
                                 double Omega) {
  const double s = std::sin(lean), c = std::cos(lean);
  if (std::abs(Omega * c) < 1e-300)
    throw std::invalid_argument("steadyDiskAxleRate: needs a non-zero turn rate and lean < 90°");
  return (A * Omega * Omega * s * c - m * g * r * s) / ((C + m * r * r) * Omega * c);
}

inline BuiltScene rollingDisk(const RollingDiskParams& p = {}) {
  ModelBuilder b;
  const int body = b.addBody("disk", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(),
                             principalInertia(p.mass, thinDiskInertia(p.mass, p.radius)), "free");
  BuiltScene s;
  s.name = "rolling_disk";
  s.model = b.build();
  s.constraints.push_back(makeContact(ContactKind::Rolling, body, Disk{p.radius, Vec3::Zero(), Vec3::UnitZ()},
                                      Support{Plane{}, StaticMotion{}, "ground"},
                                      ContactOptions{"rim", Vec3::Zero(), {}}));
  // Lean frame, then the body frame: x = t, y = u, z = a.
  const Mat3 H = axisAngle(Vec3::UnitZ(), p.heading);
  const Vec3 t = H * Vec3::UnitX();
  const Vec3 u = H * Vec3(0, std::sin(p.lean), std::cos(p.lean));
  const Vec3 a = t.cross(u);
  Mat3 R;
  R << t, u, a;
  const Vec3 P(p.contact.x(), p.contact.y(), 0);
  const Vec3 G = P + p.radius * u;
  const Vec3 w = p.precession * Vec3::UnitZ() + (p.axle_rate - p.precession * a.z()) * a + p.lean_rate * t;
  s.q0 = neutralConfiguration(s.model);
  setFloatingPose(s.q0, 0, G, R);
  s.v0 = floatingVelocity(R, w, w.cross(G - P));  // the rim point in contact is at rest
  closeGaps(s.model, s.constraints, s.q0);
  projectVelocityEuclidean(s.model, s.constraints, s.q0, s.v0);
  s.duration = p.duration;
  return s;
}

struct VerticalDiskParams {
  double radius = 0.3;
  double mass = 1.2;
  double heading = 0.3;       ///< φ₀
  double heading_rate = 1.5;  ///< ω_φ
  double spin_rate = 4.0;     ///< ω_θ (about the axle)
  Vec3 centre = Vec3::Zero(); ///< initial (x, y); z ignored
  double duration = 5.0;
};

/// q = (x, y, φ, θ): centre (x, y, R), heading φ, spin θ; v = q̇. The rolling
/// contact's normal row is identically zero here (the sliders hold the height):
/// a redundant row the solvers must detect.
inline BuiltScene verticalRollingDisk(const VerticalDiskParams& p = {}) {
  ModelBuilder b;
  const Inertia none{0, Vec3::Zero(), Mat3::Zero()};
  SE3 lift;
  lift.p = Vec3(0, 0, p.radius);
  const int bx = b.addBody("slider_x", -1, lift, JointType::Prismatic, Vec3::UnitX(), none, "x");
  const int by = b.addBody("slider_y", bx, SE3::Identity(), JointType::Prismatic, Vec3::UnitY(), none, "y");
  const int bh = b.addBody("fork", by, SE3::Identity(), JointType::Continuous, Vec3::UnitZ(), none, "heading");
  const Vec3 I = thinDiskInertia(p.mass, p.radius);
  const int bd = b.addBody("disk", bh, SE3::Identity(), JointType::Continuous, Vec3::UnitY(),
                           principalInertia(p.mass, Vec3(I.x(), I.z(), I.y())), "spin");
  BuiltScene s;
  s.name = "vertical_rolling_disk";
  s.model = b.build();
  s.constraints.push_back(makeContact(ContactKind::Rolling, bd, Disk{p.radius, Vec3::Zero(), Vec3::UnitY()},
                                      Support{Plane{}, StaticMotion{}, "ground"},
                                      ContactOptions{"rim", Vec3::Zero(), {}}));
  s.q0 = VecX::Zero(4);
  s.q0 << p.centre.x(), p.centre.y(), p.heading, 0;
  s.v0 = VecX::Zero(4);
  // The axle is (−sin φ, cos φ, 0); rolling moves the centre along (cos φ, sin φ).
  s.v0 << p.radius * p.spin_rate * std::cos(p.heading), p.radius * p.spin_rate * std::sin(p.heading),
      p.heading_rate, p.spin_rate;
  s.duration = p.duration;
  return s;
}

struct DiskChainParams {
  double radius = 0.3;
  double mass = 1.2;
  double lean = 0.0;        ///< θ about the heading frame's x (travel) axis
  double heading_rate = 0;  ///< ψ̇
  double spin_rate = 5.0;   ///< φ̇ (relative spin about the axle)
  double lean_rate = 0;
  double duration = 5.0;
};

/// q = (a, b, ψ, θ, φ): planar joint at the contact point (heading frame, z up),
/// lean θ about the heading x axis, spin φ about the axle (lean frame y) at the
/// centre (0, 0, r) of the lean frame. v = (v₁, v₂ body-frame planar velocity,
/// ψ̇, θ̇, φ̇). Cyclic: θ-indices 0, 1, 2 (position, heading) and 4 (spin).
inline BuiltScene rollingDiskChain(const DiskChainParams& p = {}) {
  ModelBuilder b;
  const Inertia none{0, Vec3::Zero(), Mat3::Zero()};
  const int bh = b.addBody("heading", -1, SE3::Identity(), JointType::Planar, Vec3::UnitZ(), none, "plane");
  const int bl = b.addBody("lean", bh, SE3::Identity(), JointType::Continuous, Vec3::UnitX(), none, "lean");
  SE3 centre;
  centre.p = Vec3(0, 0, p.radius);
  const Vec3 I = thinDiskInertia(p.mass, p.radius);
  const int bd = b.addBody("disk", bl, centre, JointType::Continuous, Vec3::UnitY(),
                           principalInertia(p.mass, Vec3(I.x(), I.z(), I.y())), "spin");
  BuiltScene s;
  s.name = "rolling_disk_chain";
  s.model = b.build();
  s.constraints.push_back(makeContact(ContactKind::Rolling, bd, Disk{p.radius, Vec3::Zero(), Vec3::UnitY()},
                                      Support{Plane{}, StaticMotion{}, "ground"},
                                      ContactOptions{"rim", Vec3::Zero(), {}}));
  s.q0 = VecX::Zero(5);
  s.q0[3] = p.lean;
  s.v0 = VecX::Zero(5);
  s.v0 << 0, 0, p.heading_rate, p.lean_rate, p.spin_rate;
  completeVelocity(s.model, s.constraints, s.q0, s.v0, {0, 1});  // the planar velocities follow
  s.duration = p.duration;
  return s;
}

}  // namespace appell::scenes
