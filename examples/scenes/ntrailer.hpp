// Scaling scene: a tractor pulling N trailers (a chain — the deep case for the
// tree solver). The tractor is a free body; each trailer hangs on a revolute
// hitch (vertical axis) behind the body in front and carries one knife-edge
// axle (lateral + normal row) on a flat ground. The tractor has its own axle.
// Bodies: N + 1; rows: 2 (N + 1). The normal rows of all axles span only
// {vertical force, roll, pitch} at the root, so N − 2 of them are redundant.
#pragma once

#include <appell/appell.hpp>
#include <appell/configuration.hpp>
#include <appell/contacts.hpp>

#include <cmath>
#include <string>
#include <vector>

namespace appell::scenes {

struct ScalingScene {
  std::string name;
  Model model;
  ConstraintList constraints;
  VecX q, v;
};

/// Box inertia about its centre offset by `com`.
inline Inertia boxInertia(double m, const Vec3& size, const Vec3& com = Vec3::Zero()) {
  const double a = size.x(), b = size.y(), c = size.z();
  return {m, com, Vec3(m * (b * b + c * c) / 12, m * (a * a + c * c) / 12,
                       m * (a * a + b * b) / 12).asDiagonal()};
}

/// Free-joint configuration at (x, y, z) with yaw ψ: q = (p, quaternion xyzw).
inline void setFreePose(VecX& q, int idx_q, const Vec3& p, double yaw) {
  q.segment<3>(idx_q) = p;
  const Quat r(Eigen::AngleAxisd(yaw, Vec3::UnitZ()));
  q.segment<4>(idx_q + 3) << r.x(), r.y(), r.z(), r.w();
}

inline Support groundSupport() { return Support{Plane{}, StaticMotion{}, "ground", -1}; }

/// A rolling thin-disk contact (radius R, axle along the body's y) on every
/// body attached by a continuous joint: the wheels of the scaling scenes.
inline void addWheelContacts(ScalingScene& s, double R) {
  for (int i = 0; i < s.model.nbodies; ++i) {
    if (s.model.joints[i].type != JointType::Continuous) continue;
    ContactOptions o;
    o.name = "roll_" + s.model.body_names[i];
    s.constraints.push_back(makeContact(ContactKind::Rolling, i,
                                        Disk{R, Vec3::Zero(), Vec3::UnitY()}, groundSupport(), o));
  }
}

inline ScalingScene nTrailer(int n_trailers) {
  const double L = 1.5, H = 0.4;  // hitch-to-axle length, body height of the frames
  ModelBuilder b;
  const int tractor = b.addBody("tractor", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(),
                                boxInertia(400, Vec3(2.0, 1.2, 0.8), Vec3(0.5, 0, 0)));
  int prev = tractor;
  for (int k = 0; k < n_trailers; ++k) {
    SE3 hitch;
    hitch.p = Vec3(-L, 0, 0);  // behind the axle of the body in front
    prev = b.addBody("trailer" + std::to_string(k), prev, hitch, JointType::Revolute,
                     Vec3::UnitZ(), boxInertia(150, Vec3(1.6, 1.0, 0.6), Vec3(-0.8, 0, 0)));
  }
  ScalingScene s;
  s.name = "ntrailer";
  s.model = b.build();
  // Every axle sits under its body frame's origin, a height H below it, for the
  // trailers at the rear end (x = −L); the blade runs along the body's x axis.
  for (int i = 0; i < s.model.nbodies; ++i) {
    ContactOptions o;
    o.name = "axle" + std::to_string(i);
    o.blade_direction = Vec3::UnitX();
    const Vec3 point = i == 0 ? Vec3(0, 0, -H) : Vec3(-L, 0, -H);
    s.constraints.push_back(
        makeContact(ContactKind::KnifeEdge, i, PointShape{point}, groundSupport(), o));
  }
  s.q = neutralConfiguration(s.model);
  setFreePose(s.q, 0, Vec3(0, 0, H), 0.0);
  // A gentle zig-zag of hitch angles, and a forward speed.
  for (int k = 0; k < n_trailers; ++k) s.q[s.model.joints[k + 1].idx_q] = 0.2 * ((k % 3) - 1);
  s.v = VecX::Zero(s.model.nv);
  s.v[3] = 2.0;  // tractor forward velocity (body frame)
  s.v[2] = 0.1;  // and yaw rate
  return s;
}

}  // namespace appell::scenes
