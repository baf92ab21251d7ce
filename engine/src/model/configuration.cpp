// The configuration space joint by joint: the neutral and random
// configurations, retraction q = q₀ ⊕ θ and its rate, integration, the
// difference q₁ ⊖ q₀, q̇ from v, quaternion normalisation. What each joint
// type does is a switch over JointType with no default (the compiler lists
// them when a type is added); its facts (sizes, where its quaternion sits)
// come from the joint type table (joint_types.hpp).
#include <appell/configuration.hpp>
#include <appell/joint_types.hpp>

#include <cmath>
#include <limits>
#include <numbers>

namespace appell {

namespace {

Quat quatAt(const VecX& q, int i) { return Quat(q[i + 3], q[i], q[i + 1], q[i + 2]); }
void setQuat(VecX& q, int i, const Quat& r) {
  q[i] = r.x(); q[i + 1] = r.y(); q[i + 2] = r.z(); q[i + 3] = r.w();
}

}  // namespace

VecX neutralConfiguration(const Model& model) {
  VecX q = VecX::Zero(model.nq);
  for (const Joint& j : model.joints)
    if (const int at = jointTypeInfo(j.type).quaternion; at >= 0) q[j.idx_q + at + 3] = 1;  // w
  return q;
}

// Local coordinates per joint (θ has the layout of v):
//   Euclidean coordinates      θ = q − q₀              (planar: Δa, Δb, Δφ)
//   floating  θ = (θ_R, Δp)    R = R₀ exp(θ_R), p = p₀ + Δp (world)
//   ball      θ = θ_R
namespace {

/// One joint of retract (q = q0 beforehand).
void retractJoint(const Joint& j, const VecX& q0, const VecX& theta, VecX& q) {
  switch (j.type) {
    case JointType::Fixed: break;
    case JointType::Floating:
      q.segment<3>(j.idx_q) += theta.segment<3>(j.idx_v + 3);
      setQuat(q, j.idx_q + 3, quatAt(q0, j.idx_q + 3) * quatExp(theta.segment<3>(j.idx_v)));
      break;
    case JointType::Ball:
      setQuat(q, j.idx_q, quatAt(q0, j.idx_q) * quatExp(theta.segment<3>(j.idx_v)));
      break;
    case JointType::Revolute: case JointType::Continuous: case JointType::Prismatic:
    case JointType::Planar:
      q.segment(j.idx_q, j.nq) += theta.segment(j.idx_v, j.nv);
      break;
  }
}

/// One joint of localRate.
void jointRate(const Joint& j, const VecX& q0, const VecX& theta, const VecX& v,
               VecX& theta_dot) {
  const int iv = j.idx_v;
  switch (j.type) {
    case JointType::Fixed: break;
    case JointType::Floating: {
      const Vec3 th = theta.segment<3>(iv);
      const Quat r = quatAt(q0, j.idx_q + 3) * quatExp(th);
      theta_dot.segment<3>(iv) = dexpInv(th) * v.segment<3>(iv);
      theta_dot.segment<3>(iv + 3) = r * Vec3(v.segment<3>(iv + 3));
      break;
    }
    case JointType::Ball:
      theta_dot.segment<3>(iv) = dexpInv(theta.segment<3>(iv)) * v.segment<3>(iv);
      break;
    case JointType::Planar: {
      const double phi = q0[j.idx_q + 2] + theta[iv + 2];
      const double c = std::cos(phi), s = std::sin(phi);
      theta_dot[iv] = c * v[iv] - s * v[iv + 1];
      theta_dot[iv + 1] = s * v[iv] + c * v[iv + 1];
      theta_dot[iv + 2] = v[iv + 2];
      break;
    }
    case JointType::Revolute: case JointType::Continuous: case JointType::Prismatic:
      theta_dot[iv] = v[iv];
      break;
  }
}

}  // namespace

void retract(const Model& model, const VecX& q0, const VecX& theta, VecX& q) {
  q = q0;
  for (const Joint& j : model.joints) retractJoint(j, q0, theta, q);
}

namespace {

/// exp(θ̂) as a quaternion and dexp⁻¹(θ) ω from one sine and cosine of |θ|/2
/// (quatExp and dexpInv in spatial.hpp, with their series at small angles):
/// dexp⁻¹(θ) ω = ω + ½ θ × ω + c θ × (θ × ω),  c = (1 − (t/2) cot(t/2))/t².
Quat expWithRate(const Vec3& th, const Vec3& w, Vec3& th_dot) {
  const double t = th.norm(), half = 0.5 * t;
  const double s = std::sin(half), co = std::cos(half);
  const double k = t < 1e-4 ? 0.5 - t * t / 48.0 : s / t;
  const double c = t < 1e-3 ? 1.0 / 12.0 + t * t / 720.0 : (1.0 - half * co / s) / (t * t);
  const Vec3 txw = th.cross(w);
  th_dot = w + 0.5 * txw + c * th.cross(txw);
  return Quat(co, k * th.x(), k * th.y(), k * th.z());
}

}  // namespace

void retractWithRate(const Model& model, const VecX& q0, const VecX& theta, const VecX& v,
                     VecX& q, VecX& theta_dot) {
  q = q0;
  for (const Joint& j : model.joints) {
    const int iv = j.idx_v;
    Vec3 w_dot;
    switch (j.type) {
      case JointType::Floating: {
        const Quat r = quatAt(q0, j.idx_q + 3) * expWithRate(theta.segment<3>(iv), v.segment<3>(iv), w_dot);
        q.segment<3>(j.idx_q) += theta.segment<3>(iv + 3);
        setQuat(q, j.idx_q + 3, r);
        theta_dot.segment<3>(iv) = w_dot;
        theta_dot.segment<3>(iv + 3) = r * Vec3(v.segment<3>(iv + 3));
        break;
      }
      case JointType::Ball:
        setQuat(q, j.idx_q, quatAt(q0, j.idx_q) * expWithRate(theta.segment<3>(iv), v.segment<3>(iv), w_dot));
        theta_dot.segment<3>(iv) = w_dot;
        break;
      case JointType::Fixed: case JointType::Revolute: case JointType::Continuous:
      case JointType::Prismatic: case JointType::Planar:
        retractJoint(j, q0, theta, q);
        jointRate(j, q0, theta, v, theta_dot);
        break;
    }
  }
}

namespace {

/// ∫₀¹ exp(s φ̂) ds, the left Jacobian of SO(3): p(h) − p(0) = R₀ J(hω) h v
/// for a body twist (ω, v) held for a time h.
Mat3 so3LeftJacobian(const Vec3& phi) {
  const double a = phi.norm();
  const Mat3 K = skew(phi);
  // (1 − cos a)/a² and (a − sin a)/a³, by series where the quotients cancel
  // (1 − cos a is taken as 2 sin²(a/2), which does not).
  const double s = std::sin(a / 2);
  const double c1 = a < 1e-4 ? 0.5 - a * a / 24 : 2 * s * s / (a * a);
  const double c2 = a < 1e-4 ? 1.0 / 6 - a * a / 120 : (a - std::sin(a)) / (a * a * a);
  return Mat3::Identity() + c1 * K + c2 * K * K;
}

}  // namespace

void integrate(const Model& model, const VecX& q0, const VecX& v, double h, VecX& q) {
  q = q0;
  for (const Joint& j : model.joints) {
    const int iq = j.idx_q, iv = j.idx_v;
    switch (j.type) {
      case JointType::Fixed: break;
      case JointType::Floating: {
        const Vec3 phi = h * v.segment<3>(iv);
        const Quat r0 = quatAt(q0, iq + 3);
        q.segment<3>(iq) += r0 * (so3LeftJacobian(phi) * (h * v.segment<3>(iv + 3)));
        setQuat(q, iq + 3, r0 * quatExp(phi));
        break;
      }
      case JointType::Ball: setQuat(q, iq, quatAt(q0, iq) * quatExp(h * v.segment<3>(iv))); break;
      case JointType::Planar: {
        // SE(2): (a, b) moves by Rot(φ₀) ∫₀ʰ Rot(s ω) ds (v_a, v_b).
        const double w = h * v[iv + 2];
        const double sw = std::abs(w) < 1e-4 ? 1 - w * w / 6 : std::sin(w) / w;
        const double cw = std::abs(w) < 1e-4 ? w / 2 - w * w * w / 24
                                             : 2 * std::sin(w / 2) * std::sin(w / 2) / w;  // (1 − cos w)/w
        const double da = h * (sw * v[iv] - cw * v[iv + 1]), db = h * (cw * v[iv] + sw * v[iv + 1]);
        const double c = std::cos(q0[iq + 2]), s = std::sin(q0[iq + 2]);
        q[iq] += c * da - s * db;
        q[iq + 1] += s * da + c * db;
        q[iq + 2] += w;
        break;
      }
      case JointType::Revolute: case JointType::Continuous: case JointType::Prismatic:
        q.segment(iq, j.nq) += h * v.segment(iv, j.nv);
        break;
    }
  }
}

void localRate(const Model& model, const VecX& q0, const VecX& theta, const VecX& v,
               VecX& theta_dot) {
  for (const Joint& j : model.joints) jointRate(j, q0, theta, v, theta_dot);
}

void difference(const Model& model, const VecX& q0, const VecX& q1, VecX& theta) {
  for (const Joint& j : model.joints) {
    const int iv = j.idx_v;
    switch (j.type) {
      case JointType::Fixed: break;
      case JointType::Floating:
        theta.segment<3>(iv) = quatLog(quatAt(q0, j.idx_q + 3).conjugate() * quatAt(q1, j.idx_q + 3));
        theta.segment<3>(iv + 3) = q1.segment<3>(j.idx_q) - q0.segment<3>(j.idx_q);
        break;
      case JointType::Ball:
        theta.segment<3>(iv) = quatLog(quatAt(q0, j.idx_q).conjugate() * quatAt(q1, j.idx_q));
        break;
      case JointType::Revolute: case JointType::Continuous: case JointType::Prismatic:
      case JointType::Planar:
        theta.segment(iv, j.nv) = q1.segment(j.idx_q, j.nq) - q0.segment(j.idx_q, j.nq);
        break;
    }
  }
}

void configurationRate(const Model& model, const VecX& q, const VecX& v, VecX& qdot) {
  qdot.resize(model.nq);
  for (const Joint& j : model.joints) {
    const int iq = j.idx_q, iv = j.idx_v;
    auto quatRate = [&](int at, const Vec3& w) {
      // q̇ = ½ q ⊗ (0, ω) for the body angular velocity ω.
      const Quat r = quatAt(q, at);
      const Quat d = r * Quat(0, w.x(), w.y(), w.z());
      setQuat(qdot, at, Quat(0.5 * d.w(), 0.5 * d.x(), 0.5 * d.y(), 0.5 * d.z()));
    };
    switch (j.type) {
      case JointType::Fixed: break;
      case JointType::Floating:
        qdot.segment<3>(iq) = quatAt(q, iq + 3) * Vec3(v.segment<3>(iv + 3));
        quatRate(iq + 3, v.segment<3>(iv));
        break;
      case JointType::Ball: quatRate(iq, v.segment<3>(iv)); break;
      case JointType::Planar: {
        const double c = std::cos(q[iq + 2]), s = std::sin(q[iq + 2]);
        qdot[iq] = c * v[iv] - s * v[iv + 1];
        qdot[iq + 1] = s * v[iv] + c * v[iv + 1];
        qdot[iq + 2] = v[iv + 2];
        break;
      }
      case JointType::Revolute: case JointType::Continuous: case JointType::Prismatic:
        qdot[iq] = v[iv];
        break;
    }
  }
}

void normalizeQuaternions(const Model& model, VecX& q) {
  for (const Joint& j : model.joints)
    if (const int at = jointTypeInfo(j.type).quaternion; at >= 0) q.segment<4>(j.idx_q + at).normalize();
}

VecX randomConfiguration(const Model& model, std::mt19937& rng) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::normal_distribution<double> gauss;
  VecX q = neutralConfiguration(model);
  auto randomQuat = [&](int at) {
    // Uniform on S³. One draw per statement, the last component first (the
    // order g++ evaluated them in as constructor arguments, an order C++
    // leaves to the compiler): every compiler draws the same configurations.
    const double g3 = gauss(rng);
    const double g2 = gauss(rng);
    const double g1 = gauss(rng);
    const double g0 = gauss(rng);
    q.segment<4>(at) = Eigen::Vector4d(g0, g1, g2, g3).normalized();
  };
  for (const Joint& j : model.joints) {
    switch (j.type) {
      case JointType::Fixed: break;
      case JointType::Revolute: case JointType::Continuous: q[j.idx_q] = std::numbers::pi * unit(rng); break;
      case JointType::Prismatic: q[j.idx_q] = unit(rng); break;
      case JointType::Planar:
        q[j.idx_q] = unit(rng); q[j.idx_q + 1] = unit(rng); q[j.idx_q + 2] = std::numbers::pi * unit(rng);
        break;
      case JointType::Floating:
        for (int k = 0; k < 3; ++k) q[j.idx_q + k] = unit(rng);
        randomQuat(j.idx_q + 3);
        break;
      case JointType::Ball: randomQuat(j.idx_q); break;
    }
  }
  return q;
}

int degenerateQuaternionJoint(const Model& model, const VecX& q) {
  for (int k = 0; k < static_cast<int>(model.joints.size()); ++k) {
    const Joint& j = model.joints[k];
    const int at = jointTypeInfo(j.type).quaternion;
    if (at >= 0 && !(q.segment<4>(j.idx_q + at).squaredNorm() >= std::numeric_limits<double>::min()))
      return k;
  }
  return -1;
}

}  // namespace appell
