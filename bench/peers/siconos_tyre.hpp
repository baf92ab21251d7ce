// A tyre on the ground plane z = 0 as a Siconos NewtonEuler3DR relation
// (siconos_car.cpp): the relation's documentation asks a
// subclass to set the contact points pc1, pc2, the normal nc and the gap y
// in computeh; NewtonEuler3DR builds the three rows' Jacobians from them.
// The tyre is a sphere of radius ρ about the wheel centre — the point
// contact of appell's torus tyre and MuJoCo's sphere wheel.
#pragma once

#include "vehicle_problem.hpp"

#include <siconos/kernel/SiconosKernel.hpp>

#include <Eigen/Geometry>

namespace peers {

/// A wheel's tyre on the ground plane z = 0: a sphere of radius ρ about the
/// wheel centre, `offset` from the body's centre of mass in body axes.
class TyreOnGround final : public NewtonEuler3DR {
 public:
  TyreOnGround(const V3& offset, double radius) : offset_(offset), radius_(radius) {}

  void computeh(double, const BlockVector& q0, SiconosVector& y) override {
    const V3 x(q0.getValue(0), q0.getValue(1), q0.getValue(2));
    const Eigen::Quaterniond q(q0.getValue(3), q0.getValue(4), q0.getValue(5), q0.getValue(6));
    const V3 centre = x + q.normalized() * offset_;
    y.setValue(0, centre.z() - radius_);
    for (int k = 0; k < 3; ++k) {
      _Nc->setValue(k, k == 2 ? 1.0 : 0.0);
      _Pc1->setValue(k, k == 2 ? centre.z() - radius_ : centre[k]);
      _Pc2->setValue(k, k == 2 ? 0.0 : centre[k]);
    }
  }

 private:
  V3 offset_;
  double radius_;
};

}  // namespace peers
