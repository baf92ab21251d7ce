// The three dynamics algorithms (RNEA, CRBA, ABA), the energies and the
// momentum describe one mechanics. On random trees of 1–50 bodies with every
// joint type, fixed and floating base, random states and random external body
// forces, they must agree to round-off:
//   RNEA(q, v, ABA(q, v, τ, f), f) = τ                     (1e-12 relative)
//   M·ABA(τ, f) = τ − h + Σ Jᵢᵀ fᵢ   (CRBA, RNEA(a = 0), world Jacobians)
//   T = ½ vᵀ M v
// and obey the balance laws along the motion they define (checked by central
// finite differences along a curve with velocity v and acceleration v̇):
//   dE/dt = τᵀ v + Σ fᵢ·vᵢ        (power balance, E = T + V)
//   dV/dt = g(q)ᵀ v                 (g = h(q, 0), the gravity part of RNEA)
//   dh/dt = Σ external wrenches     (momentum, floating base, unactuated root)
#include "random_tree.hpp"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/SVD>

#include <algorithm>
#include <array>
#include <cmath>
#include <set>

using namespace appell;

namespace {

double rel(const VecX& a, const VecX& b, double scale) { return (a - b).norm() / scale; }

/// Generalized force of body-frame spatial forces: Σ Jᵢᵀ (world force of fᵢ),
/// built from the world spatial Jacobians — independent of RNEA/ABA code.
VecX generalizedForce(const Model& model, Data& data, const VecX& q, const BodyForces& f) {
  forwardKinematics(model, data, q);
  VecX Q = VecX::Zero(model.nv);
  MatX J;
  for (int i = 0; i < model.nbodies; ++i) {
    spatialJacobianWorld(model, data, i, J);
    Q += J.transpose() * data.oMi[i].actForce(f[i]);
  }
  return Q;
}

BodyForces randomForces(const Model& model, std::mt19937& rng, double scale) {
  BodyForces f(model.nbodies);
  for (auto& fi : f) fi = test::randomVector(6, rng, scale);
  return f;
}

/// A hand-built tree holding every joint type (and a massless fixed attachment
/// and a massless moving body that carries a massive child), so every type is
/// exercised whatever the random generator draws.
Model allJointTypesTree(bool floating_base, std::mt19937& rng) {
  using test::randomInertia;
  using test::randomPlacement;
  using test::randomUnit;
  ModelBuilder b;
  // One draw per statement, the last argument first (the order g++ drew
  // them in when they were one argument list, which C++ leaves to the
  // compiler): every compiler builds the same tree.
  auto add = [&](const std::string& name, int parent, JointType type, bool massless = false) {
    const Inertia inertia = massless ? Inertia{} : randomInertia(rng);
    const Vec3 axis = randomUnit(rng);
    const SE3 placement = randomPlacement(rng);
    return b.addBody(name, parent, placement, type, axis, inertia);
  };
  const int root = add("root", -1, floating_base ? JointType::Floating : JointType::Revolute);
  const int rev = add("rev", root, JointType::Revolute);
  const int cont = add("cont", rev, JointType::Continuous);
  add("pris", cont, JointType::Prismatic);
  const int planar = add("planar", root, JointType::Planar);
  const int ball = add("ball", planar, JointType::Ball);
  add("free", ball, JointType::Floating);
  add("fixed", rev, JointType::Fixed);
  add("sensor", cont, JointType::Fixed, true);
  const int massless = add("massless_link", root, JointType::Revolute, true);
  add("payload", massless, JointType::Revolute);
  return b.build();
}

struct Case {
  Model model;
  std::string name;
};

std::vector<Case> allCases() {
  std::vector<Case> cases;
  std::mt19937 rng(20261121);
  for (bool floating : {false, true}) {
    for (int n = 1; n <= 50; ++n)
      for (int trial = 0; trial < 2; ++trial)
        cases.push_back({test::randomTree(n, floating, rng),
                         "random n=" + std::to_string(n) + (floating ? " floating" : " fixed") +
                             " trial " + std::to_string(trial)});
    cases.push_back({allJointTypesTree(floating, rng),
                     std::string("all-joint-types ") + (floating ? "floating" : "fixed")});
  }
  return cases;
}

}  // namespace

TEST(CoreDynamics, EveryJointTypeIsCovered) {
  std::set<JointType> seen;
  for (const Case& c : allCases())
    for (const Joint& j : c.model.joints) seen.insert(j.type);
  EXPECT_EQ(seen.size(), 7u);
}

// RNEA(ABA(τ, f), f) = τ and ABA = CRBA⁻¹(τ − h + Σ Jᵀ f).
TEST(CoreDynamics, AbaCrbaRneaAgreeWithExternalForces) {
  std::mt19937 rng(7);
  double worst_rnea = 0, worst_residual = 0, worst_forward = 0;
  for (const Case& c : allCases()) {
    const Model& model = c.model;
    Data data(model);
    for (int state = 0; state < 3; ++state) {
      const VecX q = randomConfiguration(model, rng);
      const VecX v = test::randomVector(model.nv, rng, 2.0);
      const VecX tau = test::randomVector(model.nv, rng, 10.0);
      const bool with_f = state > 0;
      const BodyForces fext = randomForces(model, rng, with_f ? 5.0 : 0.0);
      const BodyForces* fp = with_f ? &fext : nullptr;

      const VecX ddq = aba(model, data, q, v, tau, fp);
      ASSERT_TRUE(ddq.allFinite()) << c.name;

      // Inverse dynamics of the forward-dynamics answer returns the torque.
      const VecX tau_back = rnea(model, data, q, v, ddq, fp);
      const double e_rnea = rel(tau_back, tau, tau.norm());
      worst_rnea = std::max(worst_rnea, e_rnea);
      EXPECT_LT(e_rnea, 1e-12) << c.name << " state " << state;

      // Against the dense formulation M v̇ = τ − h + Σ Jᵀ f.
      const MatX M = crba(model, data, q);
      const VecX h = nonLinearEffects(model, data, q, v);
      const VecX Q = generalizedForce(model, data, q, fext);
      const VecX rhs = tau - h + Q;
      // Backward error (conditioning-free): the ABA answer satisfies the
      // CRBA equations to round-off of the terms involved.
      const double scale = M.norm() * ddq.norm() + tau.norm() + h.norm() + Q.norm();
      const double e_res = (M * ddq - rhs).norm() / scale;
      worst_residual = std::max(worst_residual, e_res);
      EXPECT_LT(e_res, 1e-13) << c.name << " state " << state;
      // Forward error, bounded by the condition number of M.
      const VecX ddq_ref = M.ldlt().solve(rhs);
      Eigen::JacobiSVD<MatX> svd(M);
      const double cond = svd.singularValues()(0) / svd.singularValues().tail(1)(0);
      const double e_fwd = rel(ddq, ddq_ref, ddq_ref.norm()) / cond;
      worst_forward = std::max(worst_forward, e_fwd);
      EXPECT_LT(e_fwd, 1e-13) << c.name << " cond " << cond;

      // M is symmetric positive definite.
      EXPECT_LT((M - M.transpose()).norm(), 1e-14 * M.norm()) << c.name;
      EXPECT_GT(svd.singularValues().tail(1)(0), 0.0) << c.name;
      EXPECT_EQ(M.ldlt().info(), Eigen::Success) << c.name;
      EXPECT_TRUE(M.ldlt().isPositive()) << c.name;

      // Kinetic energy is the quadratic form of the mass matrix.
      const double T = kineticEnergy(model, data, q, v);
      EXPECT_NEAR(T, 0.5 * v.dot(M * v), 1e-13 * (1 + std::abs(T))) << c.name;
      EXPECT_GE(T, 0.0);
    }
  }
  std::printf("worst: rnea(aba) %.2e, crba residual %.2e, forward/cond %.2e\n", worst_rnea,
              worst_residual, worst_forward);
}

// A wrong sign or frame for external forces would not survive this: a force
// applied to one body through ABA equals the joint torque Jᵀf applied directly.
TEST(CoreDynamics, ExternalForceEqualsJacobianTransposeTorque) {
  std::mt19937 rng(11);
  for (bool floating : {false, true}) {
    const Model model = allJointTypesTree(floating, rng);
    Data data(model);
    const VecX q = randomConfiguration(model, rng);
    const VecX v = test::randomVector(model.nv, rng);
    const VecX tau = test::randomVector(model.nv, rng, 3.0);
    for (int body = 0; body < model.nbodies; ++body) {
      BodyForces f(model.nbodies, Vec6::Zero());
      f[body] = test::randomVector(6, rng, 4.0);
      const VecX a1 = aba(model, data, q, v, tau, &f);
      const VecX Q = generalizedForce(model, data, q, f);
      const VecX a2 = aba(model, data, q, v, tau + Q);
      EXPECT_LT((a1 - a2).norm(), 1e-11 * (1 + a2.norm())) << model.body_names[body];
    }
  }
}

// The momentum about the world origin, from its definition body by body:
// P = Σ mᵢ ċᵢ, L = Σ (cᵢ × mᵢ ċᵢ + Rᵢ Īᵢ Rᵢᵀ ωᵢ).
TEST(CoreDynamics, MomentumMatchesBodyByBodyDefinition) {
  std::mt19937 rng(13);
  for (const Case& c : allCases()) {
    const Model& model = c.model;
    Data data(model);
    const VecX q = randomConfiguration(model, rng);
    const VecX v = test::randomVector(model.nv, rng, 2.0);
    const Vec6 h = momentum(model, data, q, v);
    forwardKinematics(model, data, q, v);
    Vec3 L = Vec3::Zero(), P = Vec3::Zero();
    for (int i = 0; i < model.nbodies; ++i) {
      const Inertia& I = model.inertias[i];
      const Vec6 pv = pointVelocity(data, i, I.com);
      const Vec3 x = pointPosition(data, i, I.com);
      const Mat3& R = data.oMi[i].R;
      P += I.mass * linear(pv);
      L += x.cross(I.mass * linear(pv)) + R * I.inertia_com * R.transpose() * angular(pv);
    }
    EXPECT_LT((angular(h) - L).norm(), 1e-12 * (1 + L.norm())) << c.name;
    EXPECT_LT((linear(h) - P).norm(), 1e-12 * (1 + P.norm())) << c.name;
  }
}

// Balance laws along the motion ABA defines. The curve q(t) = retract(q, t·T v),
// v(t) = v + t·v̇ has (q̇, v̇) right at t = 0, which is all a first derivative sees.
TEST(CoreDynamics, PowerMomentumAndPotentialBalances) {
  std::mt19937 rng(17);
  const double eps = 1e-5;
  int momentum_checks = 0;
  for (const Case& c : allCases()) {
    const Model& model = c.model;
    Data data(model);
    const VecX q = randomConfiguration(model, rng);
    const VecX v = test::randomVector(model.nv, rng);
    VecX tau = test::randomVector(model.nv, rng, 5.0);
    const BodyForces fext = randomForces(model, rng, 3.0);
    const bool free_root = model.joints[0].type == JointType::Floating;
    // With a floating root and no torque at it, only gravity and fext act on the
    // system from outside, so they alone change its momentum.
    const int nroots = static_cast<int>(std::count(model.parent.begin(), model.parent.end(), -1));
    if (free_root) tau.head(6).setZero();
    const VecX ddq = aba(model, data, q, v, tau, &fext);

    VecX rate(model.nv), theta(model.nv), qp(model.nq), qm(model.nq);
    localRate(model, q, VecX::Zero(model.nv), v, rate);
    theta = eps * rate;
    retract(model, q, theta, qp);
    theta = -eps * rate;
    retract(model, q, theta, qm);
    const VecX vp = v + eps * ddq, vm = v - eps * ddq;

    auto energy = [&](const VecX& qq, const VecX& vv) {
      return kineticEnergy(model, data, qq, vv) + potentialEnergy(model, data, qq);
    };
    const double dE = (energy(qp, vp) - energy(qm, vm)) / (2 * eps);
    // Power of the external body forces: fᵢ·vᵢ in body coordinates.
    forwardKinematics(model, data, q, v);
    double power = tau.dot(v);
    double power_scale = std::abs(tau.dot(v));
    for (int i = 0; i < model.nbodies; ++i) {
      power += fext[i].dot(data.v[i]);
      power_scale += std::abs(fext[i].dot(data.v[i]));
    }
    const MatX M = crba(model, data, q);
    power_scale += std::abs(ddq.dot(M * v)) + 1.0;
    EXPECT_NEAR(dE, power, 1e-7 * power_scale) << c.name;

    // dV/dt = g(q)ᵀ v: the gravity torques of RNEA are the gradient of V.
    const double dV = (potentialEnergy(model, data, qp) - potentialEnergy(model, data, qm)) / (2 * eps);
    const VecX g = nonLinearEffects(model, data, q, VecX::Zero(model.nv));
    EXPECT_NEAR(dV, g.dot(v), 1e-7 * (1 + g.norm() * v.norm())) << c.name;

    if (free_root && nroots == 1) {
      ++momentum_checks;
      const Vec6 dh = (momentum(model, data, qp, vp) - momentum(model, data, qm, vm)) / (2 * eps);
      forwardKinematics(model, data, q);
      Vec6 wrench = Vec6::Zero();
      for (int i = 0; i < model.nbodies; ++i) {
        const Inertia& I = model.inertias[i];
        const Vec3 x = data.oMi[i].apply(I.com);
        wrench += spatial(x.cross(I.mass * model.gravity), I.mass * model.gravity);
        wrench += data.oMi[i].actForce(fext[i]);
      }
      EXPECT_LT((dh - wrench).norm(), 1e-7 * (1 + wrench.norm() + M.norm() * ddq.norm()))
          << c.name;
    }
  }
  EXPECT_GE(momentum_checks, 50);
}

// Without gravity or forces, a body at rest stays at rest and a free body's
// acceleration is the Euler/Newton answer: I ω̇ = −ω × I ω (body frame).
TEST(CoreDynamics, FreeBodyIsEulerNewton) {
  ModelBuilder b;
  const Mat3 Ibar = Vec3(1.0, 2.0, 2.5).asDiagonal();
  b.addBody("body", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(),
            Inertia{3.0, Vec3::Zero(), Ibar});
  b.setGravity(Vec3::Zero());
  const Model model = b.build();
  Data data(model);
  std::mt19937 rng(3);
  const VecX q = randomConfiguration(model, rng);
  VecX v(6);
  v << 0.3, -1.2, 0.7, 1.0, 2.0, -0.5;
  const VecX ddq = aba(model, data, q, v, VecX::Zero(6));
  const Vec3 w = v.head<3>(), u = v.tail<3>();
  const Vec3 wdot = Ibar.ldlt().solve(-w.cross(Ibar * w));
  // Body-frame linear velocity of a free body's origin: u̇ = −ω × u in the body
  // frame (the world-frame velocity is constant).
  const Vec3 udot = -w.cross(u);
  EXPECT_LT((ddq.head<3>() - wdot).norm(), 1e-14);
  EXPECT_LT((ddq.tail<3>() - udot).norm(), 1e-14);
}
