// Joint kinematics: the motion a joint adds between its frame and its body.
#pragma once

#include <appell/model.hpp>

#include <cmath>

namespace appell::detail {

/// The rotation of the unit quaternion q/|q| for any q ≠ 0. Eigen's
/// toRotationMatrix() assumes |q| = 1 and, given a quaternion off the unit
/// sphere (a caller's q from a sensor or an integrator of its own), returns
/// a matrix that is no rotation: every kinematic quantity, the rows and the
/// dynamics would then be silently wrong together. MuJoCo normalises the
/// same way in its kinematics. On the sphere (the integrators keep q there
/// to ~√N ε) nothing is normalised: no square root on every evaluation's
/// critical path, and the same bits as toRotationMatrix().
inline Mat3 rotationOf(const Quat& q) {
  if (std::abs(q.squaredNorm() - 1.0) > 1e-12) [[unlikely]]
    return q.normalized().toRotationMatrix();
  return q.toRotationMatrix();
}

/// Pose of the body in its joint frame for the joint's coordinates q_j
/// (a quaternion's rotation is that of q/|q|: rotationOf).
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
      X.R = rotationOf(Quat(q[6], q[3], q[4], q[5]));
      break;
    case JointType::Ball:
      X.R = rotationOf(Quat(q[3], q[0], q[1], q[2]));
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
