// Scaling scene: a fleet of N independent differential-drive robots — a wide,
// shallow forest. Each robot: a free chassis, two wheels (thin disks on
// continuous joints) rolling without slipping, and a caster ball under the
// front modelled as a frictionless sliding sphere on the chassis.
// Bodies: 3N; rows: 2 × 3 + 1 = 7 per robot.
#pragma once

#include "ntrailer.hpp"

namespace appell::scenes {

inline ScalingScene fleet(int n_robots) {
  const double R = 0.1, W = 0.2, C = 0.05;  // wheel radius, half track, caster radius
  ModelBuilder b;
  std::vector<int> chassis;
  for (int k = 0; k < n_robots; ++k) {
    const int c = b.addBody("chassis" + std::to_string(k), -1, SE3::Identity(),
                            JointType::Floating, Vec3::UnitZ(),
                            boxInertia(8, Vec3(0.5, 0.35, 0.15), Vec3(0.1, 0, 0.05)));
    chassis.push_back(c);
    for (int side : {-1, 1}) {
      SE3 axle;
      axle.p = Vec3(0, side * W, 0);
      b.addBody("wheel" + std::to_string(k) + (side < 0 ? "R" : "L"), c, axle,
                JointType::Continuous, Vec3::UnitY(),
                Inertia{0.4, Vec3::Zero(), Vec3(0.25 * 0.4 * R * R, 0.5 * 0.4 * R * R,
                                                0.25 * 0.4 * R * R).asDiagonal()});
    }
  }
  ScalingScene s;
  s.name = "fleet";
  s.model = b.build();
  for (int i = 0; i < s.model.nbodies; ++i) {
    ContactOptions o;
    if (s.model.joints[i].type == JointType::Continuous) {
      o.name = "roll_" + s.model.body_names[i];
      s.constraints.push_back(makeContact(ContactKind::Rolling, i,
                                          Disk{R, Vec3::Zero(), Vec3::UnitY()}, groundSupport(), o));
    } else {
      o.name = "caster_" + s.model.body_names[i];
      s.constraints.push_back(makeContact(ContactKind::Sliding, i,
                                          Sphere{C, Vec3(0.3, 0, -(R - C))}, groundSupport(), o));
    }
  }
  s.q = neutralConfiguration(s.model);
  s.v = VecX::Zero(s.model.nv);
  for (size_t k = 0; k < chassis.size(); ++k) {
    const Joint& j = s.model.joints[chassis[k]];
    setFreePose(s.q, j.idx_q, Vec3(2.0 * (k % 32), 2.0 * (k / 32), R), 0.1 * k);
    s.v[j.idx_v + 2] = 0.3;  // yaw rate
    s.v[j.idx_v + 3] = 0.5;  // forward
  }
  return s;
}

}  // namespace appell::scenes
