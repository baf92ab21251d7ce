// Scaling scene: N four-wheeled cars in a row (no steering): a free chassis
// and four wheels on continuous joints, each rolling without slipping — 12
// rows per car on a 10-DoF car, so several rows are redundant (a rigid axle
// pair on flat ground: the classic statically indeterminate vehicle).
// Bodies: 5N; rows: 12N.
#pragma once

#include "ntrailer.hpp"

namespace appell::scenes {

inline ScalingScene carRow(int n_cars) {
  const double R = 0.3, W = 0.8, A = 1.3;  // wheel radius, half track, half wheelbase
  ModelBuilder b;
  std::vector<int> chassis;
  for (int k = 0; k < n_cars; ++k) {
    const int c = b.addBody("car" + std::to_string(k), -1, SE3::Identity(), JointType::Floating,
                            Vec3::UnitZ(), boxInertia(1200, Vec3(4.0, 1.8, 1.2), Vec3(0, 0, 0.3)));
    chassis.push_back(c);
    for (int fr : {-1, 1})
      for (int side : {-1, 1}) {
        SE3 axle;
        axle.p = Vec3(fr * A, side * W, 0);
        b.addBody("car" + std::to_string(k) + "_wheel" + (fr < 0 ? "R" : "F") +
                      (side < 0 ? "r" : "l"),
                  c, axle, JointType::Continuous, Vec3::UnitY(),
                  Inertia{15, Vec3::Zero(), Vec3(0.25 * 15 * R * R, 0.5 * 15 * R * R,
                                                 0.25 * 15 * R * R).asDiagonal()});
      }
  }
  ScalingScene s;
  s.name = "car_row";
  s.model = b.build();
  addWheelContacts(s, R);
  s.q = neutralConfiguration(s.model);
  s.v = VecX::Zero(s.model.nv);
  for (size_t k = 0; k < chassis.size(); ++k) {
    const Joint& j = s.model.joints[chassis[k]];
    setFreePose(s.q, j.idx_q, Vec3(6.0 * k, 0, R), 0.0);
    s.v[j.idx_v + 3] = 3.0;
  }
  return s;
}

}  // namespace appell::scenes
