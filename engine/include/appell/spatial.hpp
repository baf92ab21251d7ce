// Spatial algebra — the one convention used everywhere in appell.
//
// Featherstone, Rigid Body Dynamics Algorithms (2008), ch. 2, angular part first:
//   motion vector  m = [ω; v]  (angular velocity; velocity of the point at the
//                               frame origin), both expressed in that frame;
//   force vector   f = [n; f]  (moment about the frame origin; force).
// This is Featherstone's order and the REVERSE of Pinocchio's, which stores
// [v; ω] and [f; n]: when porting a formula or comparing numbers with
// Pinocchio, swap the two 3-blocks (and the blocks of 6 × 6 matrices).
// Method names (act, actInv, cross) follow Pinocchio's.
//   SE3 {R, p} is the pose of frame B in frame A:  x_A = R x_B + p.
//   act()    maps a vector expressed in B into A;  actInv() maps A into B.
// Spatial inertia is about the frame origin:  I = [[Ī + m[c][c]ᵀ, m[c]], [m[c]ᵀ, m·1]].
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace appell {

using Vec3 = Eigen::Vector3d;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat3 = Eigen::Matrix3d;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using VecX = Eigen::VectorXd;
using MatX = Eigen::MatrixXd;
using Quat = Eigen::Quaterniond;
/// 6 × k matrix with k ≤ 6 held on the stack (motion subspaces, joint columns).
using Mat6X = Eigen::Matrix<double, 6, Eigen::Dynamic, 0, 6, 6>;

inline Mat3 skew(const Vec3& a) {
  Mat3 s;
  s << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return s;
}

inline Vec3 angular(const Vec6& m) { return m.head<3>(); }
inline Vec3 linear(const Vec6& m) { return m.tail<3>(); }
inline Vec6 spatial(const Vec3& top, const Vec3& bottom) {
  Vec6 m;
  m << top, bottom;
  return m;
}

/// Pose of frame B in frame A (a rigid transform).
struct SE3 {
  Mat3 R = Mat3::Identity();
  Vec3 p = Vec3::Zero();

  static SE3 Identity() { return {}; }
  SE3 operator*(const SE3& b) const { return {R * b.R, R * b.p + p}; }
  SE3 inverse() const { return {R.transpose(), -(R.transpose() * p)}; }
  Vec3 apply(const Vec3& x) const { return R * x + p; }
  Vec3 applyInv(const Vec3& x) const { return R.transpose() * (x - p); }

  // Motion B → A and A → B.
  Vec6 act(const Vec6& m) const {
    const Vec3 w = R * angular(m);
    return spatial(w, R * linear(m) + p.cross(w));
  }
  Vec6 actInv(const Vec6& m) const {
    const Vec3 w = angular(m);
    return spatial(R.transpose() * w, R.transpose() * (linear(m) - p.cross(w)));
  }
  // Force B → A and A → B.
  Vec6 actForce(const Vec6& f) const {
    const Vec3 fl = R * linear(f);
    return spatial(R * angular(f) + p.cross(fl), fl);
  }
  Vec6 actInvForce(const Vec6& f) const {
    const Vec3 fl = linear(f);
    return spatial(R.transpose() * (angular(f) - p.cross(fl)), R.transpose() * fl);
  }
  /// 6×6 matrix of act() on motion vectors (Featherstone's ᴬX_B).
  Mat6 toMotionMatrix() const {
    Mat6 X;
    X << R, Mat3::Zero(), skew(p) * R, R;
    return X;
  }
};

/// out += ᴬX*_B H ᴮX_A for M = {R, p} the pose of B in A: a symmetric
/// force-from-motion map about B's origin (a spatial or articulated inertia)
/// expressed about A's origin and added — a body's inertia handed to its
/// parent in ABA, CRBA and the tree solver. With the force transform
/// F = [R, p̂R; 0, R] it is F H Fᵀ, done blockwise: rotate the three 3 × 3
/// blocks, then shear by p̂ — about a third of the multiplications of the two
/// dense 6 × 6 products. H must be symmetric: its lower-left block is not
/// read, and the result's lower-left is the transpose of its upper-right.
inline void addTransformedInertia(const SE3& M, const Mat6& H, Mat6& out) {
  const Mat3& R = M.R;
  const Mat3 A = R * H.topLeftCorner<3, 3>() * R.transpose();
  const Mat3 B = R * H.topRightCorner<3, 3>() * R.transpose();
  const Mat3 D = R * H.bottomRightCorner<3, 3>() * R.transpose();
  const Mat3 ph = skew(M.p);
  const Mat3 Bt = B + ph * D;  // top-right of T H' Tᵀ, T = [1, p̂; 0, 1]
  out.topRightCorner<3, 3>() += Bt;
  out.bottomLeftCorner<3, 3>() += Bt.transpose();
  out.bottomRightCorner<3, 3>() += D;
  out.topLeftCorner<3, 3>().noalias() += A + ph * B.transpose() - Bt * ph;
}

/// Spatial cross products: m ×  (motion) and m ×* (force).
inline Vec6 crossMotion(const Vec6& m, const Vec6& x) {
  return spatial(angular(m).cross(angular(x)),
                 angular(m).cross(linear(x)) + linear(m).cross(angular(x)));
}
inline Vec6 crossForce(const Vec6& m, const Vec6& f) {
  return spatial(angular(m).cross(angular(f)) + linear(m).cross(linear(f)),
                 angular(m).cross(linear(f)));
}
inline Mat6 crossMotionMatrix(const Vec6& m) {
  Mat6 X;
  X << skew(angular(m)), Mat3::Zero(), skew(linear(m)), skew(angular(m));
  return X;
}

/// Rigid-body inertia: mass, centre of mass and rotational inertia about the
/// centre of mass, all in the body frame.
struct Inertia {
  double mass = 0;
  Vec3 com = Vec3::Zero();
  Mat3 inertia_com = Mat3::Zero();

  /// The 6×6 spatial inertia about the frame origin.
  Mat6 matrix() const {
    const Mat3 c = skew(com);
    Mat6 I;
    I << inertia_com + mass * c * c.transpose(), mass * c, mass * c.transpose(),
        mass * Mat3::Identity();
    return I;
  }
  /// The same inertia seen in frame A, given this body's pose in A.
  Inertia transformed(const SE3& A_B) const {
    return {mass, A_B.apply(com), A_B.R * inertia_com * A_B.R.transpose()};
  }
  /// Two bodies rigidly joined, both given in the same frame: masses add, the
  /// centre of mass is the mass-weighted mean, and each rotational inertia is
  /// carried to the new centre by the parallel-axis theorem,
  ///     J = Σ Jₖ + mₖ (|dₖ|² 1 − dₖ dₖᵀ),   dₖ = cₖ − c.
  /// (The spatial inertias simply add; this is the same sum in these terms.)
  Inertia operator+(const Inertia& o) const {
    const double m = mass + o.mass;
    if (m == 0) return {0, Vec3::Zero(), inertia_com + o.inertia_com};
    const Vec3 c = (mass * com + o.mass * o.com) / m;
    auto shift = [&](const Inertia& k) {
      const Vec3 d = k.com - c;
      return Mat3(k.inertia_com + k.mass * (d.squaredNorm() * Mat3::Identity() - d * d.transpose()));
    };
    return {m, c, shift(*this) + shift(o)};
  }
};

/// Rotation matrix for a rotation of `angle` about the unit `axis`.
inline Mat3 axisAngle(const Vec3& axis, double angle) {
  return Eigen::AngleAxisd(angle, axis).toRotationMatrix();
}

/// exp: so(3) → SO(3) as a unit quaternion, accurate near zero.
inline Quat quatExp(const Vec3& w) {
  const double t = w.norm();
  const double half = 0.5 * t;
  // sin(t/2)/t, with its Taylor series below the point where it loses digits.
  const double k = t < 1e-4 ? 0.5 - t * t / 48.0 : std::sin(half) / t;
  return Quat(std::cos(half), k * w.x(), k * w.y(), k * w.z());
}

/// log: SO(3) → so(3) of a unit quaternion (the short way round).
inline Vec3 quatLog(const Quat& q0) {
  Quat q = q0.w() < 0 ? Quat(-q0.w(), -q0.x(), -q0.y(), -q0.z()) : q0;
  const double s = q.vec().norm();
  const double t = 2.0 * std::atan2(s, q.w());
  const double k = s < 1e-8 ? 2.0 / q.w() : t / s;
  return k * q.vec();
}

/// Inverse of the left-trivialised differential of exp on SO(3):
/// if R(t) = R₀ exp(θ(t)) and ω is the body angular velocity, θ̇ = dexpInv(θ) ω
/// (Iserles et al., Acta Numerica 2000, §2 — the map behind RKMK methods).
inline Mat3 dexpInv(const Vec3& theta) {
  const double t = theta.norm();
  const Mat3 T = skew(theta);
  // Coefficient of T² : (1 − (t/2) cot(t/2)) / t², series below 1e-3.
  const double c = t < 1e-3 ? 1.0 / 12.0 + t * t / 720.0
                            : (1.0 - 0.5 * t * std::cos(0.5 * t) / std::sin(0.5 * t)) / (t * t);
  return Mat3::Identity() + 0.5 * T + c * T * T;
}

}  // namespace appell
