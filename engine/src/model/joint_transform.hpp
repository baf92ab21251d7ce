// Joint kinematics: the motion a joint adds between its frame and its body.
#pragma once

#include <appell/model.hpp>

#include <cmath>

namespace appell::detail {

/// The rotation of the unit quaternion q/|q| for any q ≠ 0 — Eigen's
/// toRotationMatrix() with 2 replaced by 2/|q|² (no square root). That
/// formula assumes |q| = 1 and, given a quaternion off the unit sphere (a
/// caller's q from a sensor or an integrator of its own), returns a matrix
/// that is no rotation: every kinematic quantity, the rows and the
/// dynamics would then be silently wrong together. MuJoCo normalises the
/// same way in its kinematics.
inline Mat3 rotationOf(double w, double x, double y, double z) {
  // The division only off the unit sphere: on it (the integrators keep q
  // there to ~√N ε) it would lengthen every evaluation's critical path.
  const double n2 = w * w + x * x + y * y + z * z;
  double s = 2.0;
  if (std::abs(n2 - 1.0) > 1e-12) [[unlikely]]
    s = 2.0 / n2;
  const double xx = s * x * x, yy = s * y * y, zz = s * z * z;
  const double xy = s * x * y, xz = s * x * z, yz = s * y * z;
  const double wx = s * w * x, wy = s * w * y, wz = s * w * z;
  Mat3 R;
  R << 1 - yy - zz, xy - wz, xz + wy,
       xy + wz, 1 - xx - zz, yz - wx,
       xz - wy, yz + wx, 1 - xx - yy;
  return R;
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
      X.R = rotationOf(q[6], q[3], q[4], q[5]);
      break;
    case JointType::Ball:
      X.R = rotationOf(q[3], q[0], q[1], q[2]);
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
