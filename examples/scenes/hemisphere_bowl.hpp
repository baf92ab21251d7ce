// Heavy hemisphere rolling without slipping inside a spherical bowl (seed 002).
//
// Bowl: sphere of radius R₁ about C = (0, 0, R₁), bodies inside (its bottom at
// the origin). Hemisphere: spherical surface of radius R < R₁ about the body
// origin O, the curved face toward the body's −z (cap axis −z, half-angle π/2),
// centre of mass at distance l₁ from O on the axis: com = (0, 0, −l₁).
// Seed angles: θ₁, ψ₁ polar and azimuth of the contact point seen from C
// (θ₁ = 0 at the bottom); θ the tilt of the hemisphere's axis from vertical,
// ψ the azimuth toward which its pole (the lowest point when upright) swings,
// φ the spin about the axis. The seed's equilibrium manifold is
//     ψ = ψ₁,  l₁ sin θ = R sin θ₁   (centre of mass above the contact point),
// three-dimensional (θ₁, ψ₁, φ free).
#pragma once

#include "scene.hpp"

#include <appell/contacts.hpp>

#include <algorithm>
#include <limits>
#include <numbers>

namespace appell::scenes {

struct HemisphereBowlParams {
  double bowl_radius = 1.0;   ///< R₁
  double radius = 0.3;        ///< R
  double mass = 1.5;
  double com_distance = -1;   ///< l₁; negative: a solid homogeneous hemisphere, 3R/8
  double contact_polar = 0.2; ///< θ₁
  double contact_azimuth = 0.4;  ///< ψ₁
  double tilt = -1;           ///< θ; negative: the equilibrium tilt asin(R sin θ₁ / l₁)
  double tilt_azimuth = std::numeric_limits<double>::quiet_NaN();  ///< ψ; NaN: ψ₁
  double spin = 0.0;          ///< φ
  Vec3 omega = Vec3::Zero();  ///< initial world angular velocity (rolling about the contact)
  double duration = 5.0;
};

inline double hemisphereComDistance(const HemisphereBowlParams& p) {
  return p.com_distance >= 0 ? p.com_distance : 3.0 * p.radius / 8.0;
}

/// Rotation with the pole (body −z) swung by θ toward azimuth ψ, spun by φ.
inline Mat3 hemisphereRotation(double tilt, double azimuth, double spin) {
  return axisAngle(Vec3::UnitZ(), azimuth) * axisAngle(Vec3::UnitY(), -tilt) *
         axisAngle(Vec3::UnitZ(), spin);
}

/// Seed angles of a configuration: (θ₁, ψ₁) of the contact point, (θ, ψ) of the pole.
struct HemisphereAngles {
  double contact_polar, contact_azimuth, tilt, tilt_azimuth;
};
inline HemisphereAngles hemisphereAngles(const HemisphereBowlParams& p, const VecX& q) {
  const Vec3 C(0, 0, p.bowl_radius);
  const Vec3 O = q.head<3>();
  const Vec3 e = (O - C).normalized();  // from the bowl centre toward the contact point
  const Vec3 pole = -floatingRotation(q, 0).col(2);
  return {std::acos(std::clamp(-e.z(), -1.0, 1.0)), std::atan2(e.y(), e.x()),
          std::acos(std::clamp(-pole.z(), -1.0, 1.0)), std::atan2(pole.y(), pole.x())};
}

inline BuiltScene hemisphereInBowl(const HemisphereBowlParams& p = {}) {
  const double l1 = hemisphereComDistance(p);
  const double m = p.mass, R = p.radius;
  // Solid hemisphere: 2/5 m R² about every axis through O; shift the transverse
  // moments to the centre of mass (parallel axes).
  const double Ia = 0.4 * m * R * R, It = 0.4 * m * R * R - m * l1 * l1;
  ModelBuilder b;
  const int body = b.addBody("hemisphere", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(),
                             principalInertia(m, Vec3(It, It, Ia), Vec3(0, 0, -l1)), "free");
  BuiltScene s;
  s.name = "hemisphere_in_bowl";
  s.model = b.build();
  const Vec3 C(0, 0, p.bowl_radius);
  s.constraints.push_back(makeContact(
      ContactKind::Rolling, body,
      SphericalCap{R, Vec3::Zero(), -Vec3::UnitZ(), std::numbers::pi / 2},
      Support{SphereSurface{C, p.bowl_radius, SphereSurface::Side::Inside}, StaticMotion{}, "bowl"},
      ContactOptions{"shell", Vec3::Zero(), {}}));
  const double t1 = p.contact_polar, s1 = p.contact_azimuth;
  const Vec3 e(std::sin(t1) * std::cos(s1), std::sin(t1) * std::sin(s1), -std::cos(t1));
  const Vec3 O = C + (p.bowl_radius - R) * e;
  const Vec3 P = C + p.bowl_radius * e;
  const double th = p.tilt >= 0 ? p.tilt : std::asin(std::clamp(R * std::sin(t1) / l1, -1.0, 1.0));
  const double az = std::isnan(p.tilt_azimuth) ? s1 : p.tilt_azimuth;
  const Mat3 Rot = hemisphereRotation(th, az, p.spin);
  s.q0 = neutralConfiguration(s.model);
  setFloatingPose(s.q0, 0, O, Rot);
  s.v0 = floatingVelocity(Rot, p.omega, p.omega.cross(O - P));
  closeGaps(s.model, s.constraints, s.q0);
  projectVelocityEuclidean(s.model, s.constraints, s.q0, s.v0);
  s.duration = p.duration;
  return s;
}

}  // namespace appell::scenes
