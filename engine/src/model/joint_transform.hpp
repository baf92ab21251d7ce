// Joint kinematics: the motion a joint adds between its frame and its body.
#pragma once

#include <appell/model.hpp>

namespace appell::detail {

/// Pose of the body in its joint frame for the joint's coordinates q_j.
template <typename QSeg>
SE3 jointTransform(const Joint& j, const QSeg& q) {
  SE3 X;
  switch (j.type) {
    case JointType::Fixed:
      break;
    case JointType::Revolute:
    case JointType::Continuous:
      X.R = axisAngle(j.axis, q[0]);
      break;
    case JointType::Prismatic:
      X.p = j.axis * q[0];
      break;
    case JointType::Planar:
      X.R = axisAngle(j.axis, q[2]);
      X.p = j.t1 * q[0] + j.t2 * q[1];
      break;
    case JointType::Floating:
      X.p = Vec3(q[0], q[1], q[2]);
      X.R = Quat(q[6], q[3], q[4], q[5]).toRotationMatrix();
      break;
    case JointType::Ball:
      X.R = Quat(q[3], q[0], q[1], q[2]).toRotationMatrix();
      break;
  }
  return X;
}

/// S x for the joint's motion subspace S and x one of its velocity-like
/// segments. A floating joint's S is the identity (model.cpp): its product
/// is a copy, not a 6 × 6 dynamic-size one.
template <typename Seg>
Vec6 jointMotion(const Joint& j, const Seg& x) {
  if (j.type == JointType::Floating) return Vec6(x);
  return j.S * x;
}

}  // namespace appell::detail
