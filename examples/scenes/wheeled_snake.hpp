// Scaling scene: a wheeled snake — N links in a chain on vertical-axis
// revolute joints, each link carrying a passive wheel pair (two thin disks on
// continuous joints about the link's lateral axis) rolling without slipping.
// Bodies: 3N; rows: 3 per wheel (two tangential + normal) = 6N.
#pragma once

#include "ntrailer.hpp"

namespace appell::scenes {

inline ScalingScene wheeledSnake(int n_links) {
  const double L = 0.6, R = 0.15, W = 0.25;  // link length, wheel radius, half track
  ModelBuilder b;
  int prev = -1;
  for (int k = 0; k < n_links; ++k) {
    SE3 X;
    if (k > 0) X.p = Vec3(-L, 0, 0);
    const int link = b.addBody("link" + std::to_string(k), prev, X,
                               k == 0 ? JointType::Floating : JointType::Revolute, Vec3::UnitZ(),
                               boxInertia(5, Vec3(L, 0.3, 0.1), Vec3(-L / 2, 0, 0)));
    for (int side : {-1, 1}) {
      SE3 axle;
      axle.p = Vec3(-L / 2, side * W, 0);
      b.addBody("wheel" + std::to_string(k) + (side < 0 ? "R" : "L"), link, axle,
                JointType::Continuous, Vec3::UnitY(),
                Inertia{0.5, Vec3::Zero(), Vec3(0.25 * 0.5 * R * R, 0.5 * 0.5 * R * R,
                                                0.25 * 0.5 * R * R).asDiagonal()});
    }
    prev = link;
  }
  ScalingScene s;
  s.name = "wheeled_snake";
  s.model = b.build();
  addWheelContacts(s, R);
  s.q = neutralConfiguration(s.model);
  setFreePose(s.q, 0, Vec3(0, 0, R), 0.0);
  for (int i = 1; i < s.model.nbodies; ++i)
    if (s.model.joints[i].type == JointType::Revolute)
      s.q[s.model.joints[i].idx_q] = 0.3 * std::sin(0.7 * i);
  s.v = VecX::Zero(s.model.nv);
  s.v[3] = 1.0;
  return s;
}

}  // namespace appell::scenes
