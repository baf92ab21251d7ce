// Kinematics against central finite differences along a motion.
//
// The motion: q(t) = retract(q₀, θ(t)), v(t) = v + t·a, where θ(t) solves
// θ̇ = localRate(q₀, θ, v(t)), θ(0) = 0 (integrated here by a plain vector RK4
// with small sub-steps, independent of the engine's integrators). Along it the
// generalized velocity is v(t) and its rate is a, so
//   ṗ  = J v = pointVelocity,            p̈ = J a + J̇ v = pointAcceleration,
//   V  = J_s v = spatialVelocityWorld,    V̇ = spatialAccelerationWorld,
// and every one of them is checked against central differences of the
// quantity below it. The configuration manifold (retract, difference,
// localRate, configurationRate) is checked the same way, and quaternions are
// shown to stay unit over long integrations.
#include "random_tree.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

using namespace appell;

namespace {

struct Curve {
  const Model& model;
  VecX q0, v, a;
  /// q(t), v(t) of the motion described above.
  void at(double t, VecX& q, VecX& vt) const {
    const int n = 16;
    const double h = t / n;
    VecX th = VecX::Zero(model.nv), k1(model.nv), k2(model.nv), k3(model.nv), k4(model.nv);
    VecX tmp(model.nv);
    for (int s = 0; s < n; ++s) {
      const double ts = s * h;
      localRate(model, q0, th, v + ts * a, k1);
      tmp = th + 0.5 * h * k1;
      localRate(model, q0, tmp, v + (ts + 0.5 * h) * a, k2);
      tmp = th + 0.5 * h * k2;
      localRate(model, q0, tmp, v + (ts + 0.5 * h) * a, k3);
      tmp = th + h * k3;
      localRate(model, q0, tmp, v + (ts + h) * a, k4);
      th += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    }
    q.resize(model.nq);
    retract(model, q0, th, q);
    vt = v + t * a;
  }
};

/// World angular velocity from two orientations 2ε apart: log(R₊R₋ᵀ)/2ε.
Vec3 angularRate(const Mat3& Rp, const Mat3& Rm, double eps) {
  const Eigen::AngleAxisd aa(Rp * Rm.transpose());
  return aa.angle() * aa.axis() / (2 * eps);
}

std::vector<Model> models() {
  std::vector<Model> out;
  std::mt19937 rng(99);
  for (bool floating : {false, true})
    for (int n : {1, 2, 3, 4, 6, 9, 14, 20})
      for (int k = 0; k < 2; ++k) out.push_back(test::randomTree(n, floating, rng));
  return out;
}

Vec3 randomPoint(std::mt19937& rng) { return test::randomVector(3, rng, 0.7); }

}  // namespace

TEST(CoreKinematics, ModelsCoverEveryMovingJointType) {
  std::set<JointType> seen;
  for (const Model& m : models())
    for (const Joint& j : m.joints) seen.insert(j.type);
  EXPECT_EQ(seen.size(), 7u);
}

TEST(CoreKinematics, VelocitiesAndJacobiansMatchFiniteDifferences) {
  std::mt19937 rng(1);
  const double eps = 1e-5;
  for (const Model& model : models()) {
    Data data(model);
    Curve c{model, randomConfiguration(model, rng), test::randomVector(model.nv, rng, 1.5),
            test::randomVector(model.nv, rng, 1.5)};
    VecX qp, vp, qm, vm;
    c.at(eps, qp, vp);
    c.at(-eps, qm, vm);
    MatX J, Js;
    for (int body = 0; body < model.nbodies; ++body) {
      const Vec3 r = randomPoint(rng);
      forwardKinematics(model, data, qp);
      const Vec3 xp = pointPosition(data, body, r), op = data.oMi[body].p;
      const Mat3 Rp = data.oMi[body].R;
      forwardKinematics(model, data, qm);
      const Vec3 xm = pointPosition(data, body, r), om = data.oMi[body].p;
      const Mat3 Rm = data.oMi[body].R;
      const Vec3 w_fd = angularRate(Rp, Rm, eps);
      const Vec3 xdot_fd = (xp - xm) / (2 * eps);
      const Vec3 odot_fd = (op - om) / (2 * eps);

      forwardKinematics(model, data, c.q0, c.v);
      const Vec6 pv = pointVelocity(data, body, r);
      const double scale = 1 + pv.norm();
      EXPECT_LT((angular(pv) - w_fd).norm(), 1e-8 * scale) << "body " << body;
      EXPECT_LT((linear(pv) - xdot_fd).norm(), 1e-8 * scale) << "body " << body;

      pointJacobian(model, data, body, r, J);
      EXPECT_LT((J * c.v - pv).norm(), 1e-13 * scale) << "body " << body;
      // Columns of joints off the body's path are exactly zero.
      for (int k = 0; k < model.nv; ++k) {
        if (!model.isAncestor(model.body_of_v[k], body)) {
          EXPECT_EQ(J.col(k).norm(), 0.0);
        }
      }

      // World spatial velocity [ω; v_O], v_O = ȯ − ω × o for the body origin o.
      spatialJacobianWorld(model, data, body, Js);
      const Vec6 V = spatialVelocityWorld(data, body);
      EXPECT_LT((Js * c.v - V).norm(), 1e-13 * (1 + V.norm()));
      const Vec3 o = data.oMi[body].p;
      EXPECT_LT((angular(V) - w_fd).norm(), 1e-8 * (1 + V.norm()));
      EXPECT_LT((linear(V) - (odot_fd - w_fd.cross(o))).norm(), 1e-8 * (1 + V.norm()));
    }
  }
}

TEST(CoreKinematics, AccelerationsAndJdotVMatchFiniteDifferences) {
  std::mt19937 rng(2);
  const double eps = 1e-5;
  for (const Model& model : models()) {
    Data data(model);
    Curve c{model, randomConfiguration(model, rng), test::randomVector(model.nv, rng, 1.5),
            test::randomVector(model.nv, rng, 1.5)};
    Curve c0{model, c.q0, c.v, VecX::Zero(model.nv)};  // same velocity, a = 0
    VecX qp, vp, qm, vm, q0p, v0p, q0m, v0m;
    c.at(eps, qp, vp);
    c.at(-eps, qm, vm);
    c0.at(eps, q0p, v0p);
    c0.at(-eps, q0m, v0m);
    MatX Jp, Jm, J;
    for (int body = 0; body < model.nbodies; ++body) {
      const Vec3 r = randomPoint(rng);
      forwardKinematics(model, data, qp, vp);
      const Vec6 pvp = pointVelocity(data, body, r), Vp = spatialVelocityWorld(data, body);
      forwardKinematics(model, data, qm, vm);
      const Vec6 pvm = pointVelocity(data, body, r), Vm = spatialVelocityWorld(data, body);

      forwardKinematics(model, data, c.q0, c.v, c.a);
      const Vec6 pa = pointAcceleration(data, body, r);
      const Vec6 A = spatialAccelerationWorld(data, body);
      const double scale = 1 + pa.norm() + pvp.squaredNorm();
      EXPECT_LT((pa - (pvp - pvm) / (2 * eps)).norm(), 1e-7 * scale) << "body " << body;
      EXPECT_LT((A - (Vp - Vm) / (2 * eps)).norm(), 1e-7 * (1 + A.norm() + Vp.squaredNorm()))
          << "body " << body;

      // J̇ v: finite difference of J along the motion with velocity v.
      forwardKinematics(model, data, q0p);
      pointJacobian(model, data, body, r, Jp);
      forwardKinematics(model, data, q0m);
      pointJacobian(model, data, body, r, Jm);
      const Vec6 jdv_fd = (Jp - Jm) * c.v / (2 * eps);
      forwardKinematics(model, data, c.q0, c.v, VecX::Zero(model.nv));
      const Vec6 jdv = pointJacobianDotTimesV(data, body, r);
      EXPECT_LT((jdv - jdv_fd).norm(), 1e-7 * (1 + jdv.norm() + c.v.squaredNorm()))
          << "body " << body;
      // And p̈ = J a + J̇ v exactly.
      forwardKinematics(model, data, c.q0);
      pointJacobian(model, data, body, r, J);
      EXPECT_LT((J * c.a + jdv - pa).norm(), 1e-12 * scale) << "body " << body;
    }
  }
}

TEST(CoreKinematics, RetractDifferenceRoundTrip) {
  std::mt19937 rng(3);
  for (const Model& model : models()) {
    const VecX q0 = randomConfiguration(model, rng), q1 = randomConfiguration(model, rng);
    // θ with rotation parts shorter than π: difference recovers it.
    VecX theta = test::randomVector(model.nv, rng, 1.0), q(model.nq), back(model.nv);
    retract(model, q0, theta, q);
    difference(model, q0, q, back);
    EXPECT_LT((back - theta).norm(), 1e-13 * (1 + theta.norm()));
    // retract(q0, difference(q0, q1)) = q1 (as a configuration: quaternions ±).
    difference(model, q0, q1, back);
    retract(model, q0, back, q);
    Data d1(model), d2(model);
    forwardKinematics(model, d1, q);
    forwardKinematics(model, d2, q1);
    for (int i = 0; i < model.nbodies; ++i) {
      EXPECT_LT((d1.oMi[i].R - d2.oMi[i].R).norm(), 1e-13);
      EXPECT_LT((d1.oMi[i].p - d2.oMi[i].p).norm(), 1e-13);
    }
  }
}

// q̇ = G(q) v: configurationRate against the derivative of retract along the
// local-coordinate flow θ̇ = localRate(q₀, θ, v), at θ ≠ 0 (this exercises dexp⁻¹),
// and FK body velocities against the pose derivative along q + t q̇ (this ties
// configurationRate to the kinematics' meaning of v).
TEST(CoreKinematics, ConfigurationRateMatchesRetractAndKinematics) {
  std::mt19937 rng(4);
  const double eps = 1e-6;
  for (const Model& model : models()) {
    const VecX q0 = randomConfiguration(model, rng);
    const VecX theta = test::randomVector(model.nv, rng, 1.2);
    const VecX v = test::randomVector(model.nv, rng, 2.0);
    VecX q(model.nq), thdot(model.nv), qp(model.nq), qm(model.nq), qdot;
    retract(model, q0, theta, q);
    localRate(model, q0, theta, v, thdot);
    retract(model, q0, theta + eps * thdot, qp);
    retract(model, q0, theta - eps * thdot, qm);
    configurationRate(model, q, v, qdot);
    const VecX fd = (qp - qm) / (2 * eps);
    EXPECT_LT((qdot - fd).norm(), 1e-8 * (1 + qdot.norm()));

    // Pose derivative along the straight line q ± ε q̇ (first order is all it needs).
    Data data(model), dp(model), dm(model);
    forwardKinematics(model, data, q, v);
    forwardKinematics(model, dp, VecX(q + eps * qdot));
    forwardKinematics(model, dm, VecX(q - eps * qdot));
    for (int i = 0; i < model.nbodies; ++i) {
      // Body-frame twist from the pose derivative: ω̂ = Rᵀ Ṙ, v = Rᵀ ṗ.
      const Mat3 R = data.oMi[i].R;
      const Mat3 Rdot = (dp.oMi[i].R - dm.oMi[i].R) / (2 * eps);
      const Mat3 W = R.transpose() * Rdot;
      const Vec3 w(W(2, 1), W(0, 2), W(1, 0));
      const Vec3 lin = R.transpose() * (dp.oMi[i].p - dm.oMi[i].p) / (2 * eps);
      EXPECT_LT((w - angular(data.v[i])).norm(), 1e-7 * (1 + data.v[i].norm())) << "body " << i;
      EXPECT_LT((lin - linear(data.v[i])).norm(), 1e-7 * (1 + data.v[i].norm())) << "body " << i;
    }
  }
}

// An RKMK stage takes q = retract(q₀, θ) and θ̇ = localRate(q₀, θ, v) in one
// call (retractWithRate: one half-angle sine and cosine per rotation). It
// must be the two separate maps to round-off, for every joint type, at
// rotations of up to ~2 rad and below the series thresholds (1e-3, 1e-4).
TEST(CoreKinematics, RetractWithRateIsRetractAndLocalRate) {
  std::mt19937 rng(5);
  for (const Model& model : models()) {
    for (double scale : {1.2, 5e-4, 5e-5, 0.0}) {
      const VecX q0 = randomConfiguration(model, rng);
      const VecX theta = test::randomVector(model.nv, rng, scale);
      const VecX v = test::randomVector(model.nv, rng, 2.0);
      VecX q1(model.nq), q2(model.nq), r1(model.nv), r2(model.nv);
      retract(model, q0, theta, q1);
      localRate(model, q0, theta, v, r1);
      retractWithRate(model, q0, theta, v, q2, r2);
      EXPECT_LT((q1 - q2).lpNorm<Eigen::Infinity>(), 4e-16 * (1 + q1.lpNorm<Eigen::Infinity>()))
          << "scale " << scale;
      EXPECT_LT((r1 - r2).lpNorm<Eigen::Infinity>(), 1e-15 * (1 + r1.lpNorm<Eigen::Infinity>()))
          << "scale " << scale;
    }
  }
}

// Quaternions are advanced by exact rotations (q ⊗ exp(θ)), so they stay unit
// to round-off however long the run: the deviation grows like a random walk of
// the rounding error (√N ε_mach), not with the step size.
class QuaternionNorm : public ::testing::TestWithParam<IntegratorType> {};

TEST_P(QuaternionNorm, StaysUnitOverManySteps) {
  ModelBuilder b;
  const Mat3 Ibar = Vec3(0.4, 0.9, 1.1).asDiagonal();
  const int base = b.addBody("base", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(),
                             Inertia{2.0, Vec3(0.05, -0.02, 0.1), Ibar});
  SE3 X;
  X.p = Vec3(0.3, 0.1, -0.2);
  b.addBody("arm", base, X, JointType::Ball, Vec3::UnitZ(), Inertia{0.5, Vec3(0.2, 0, 0), 0.1 * Ibar});
  const Model model = b.build();
  Data data(model);
  struct Field : AccelerationField {
    const Model& m;
    Data& d;
    VecX tau;
    Field(const Model& mm, Data& dd) : m(mm), d(dd), tau(VecX::Zero(mm.nv)) {}
    bool operator()(double, const VecX& q, const VecX& v, VecX& a) override {
      a = aba(m, d, q, v, tau);
      return true;
    }
  } field(model, data);
  IntegratorOptions opt;
  opt.rtol = 1e-9;
  opt.atol = 1e-12;
  auto integ = makeIntegrator(GetParam(), model, opt);
  std::mt19937 rng(5);
  VecX q = randomConfiguration(model, rng), v = test::randomVector(model.nv, rng, 3.0);
  double t = 0, h = 1e-3, worst = 0;
  const int steps = 100000;
  for (int s = 0; s < steps; ++s) {
    const StepResult r = integ->step(field, t, q, v, h);
    ASSERT_TRUE(r.ok);
    if (integ->adaptive()) h = r.h_next;
    worst = std::max({worst, std::abs(q.segment<4>(3).norm() - 1), std::abs(q.segment<4>(7).norm() - 1)});
  }
  std::printf("%s: %d steps to t = %.1f, max | |quat| - 1 | = %.2e\n", toString(GetParam()), steps,
              t, worst);
  // 100 000 exact-rotation products: ≈ √N · 1.1e-16 ≈ 4e-14 is the random-walk size.
  EXPECT_LT(worst, 1e-13);
}

INSTANTIATE_TEST_SUITE_P(Integrators, QuaternionNorm,
                         ::testing::Values(IntegratorType::SymplecticEuler, IntegratorType::RK4,
                                           IntegratorType::DormandPrince54),
                         [](const ::testing::TestParamInfo<IntegratorType>& p) {
                           return std::string(toString(p.param));
                         });

// forwardKinematicsIfStale (the tree solver's kinematics after the rows'):
// it recomputes whenever q or v differ from the state Data was last computed
// for, or when only positions were — and skips otherwise, which the poisoned
// pose below makes visible.
TEST(CoreKinematics, KinematicsAreRecomputedExactlyWhenTheStateChanged) {
  std::mt19937 rng(5);
  const Model model = test::randomTree(6, true, rng);
  Data data(model), fresh(model);
  VecX q = randomConfiguration(model, rng);
  VecX v = test::randomVector(model.nv, rng);
  auto sameAsFresh = [&](const VecX& qq, const VecX& vv) {
    forwardKinematics(model, fresh, qq, vv);
    for (int i = 0; i < model.nbodies; ++i)
      if (!data.oMi[i].toMotionMatrix().isApprox(fresh.oMi[i].toMotionMatrix(), 1e-15) ||
          !data.v[i].isApprox(fresh.v[i], 1e-15))
        return false;
    return true;
  };
  forwardKinematics(model, data, q, v);
  q[2] += 1e-3;  // a changed q (in place, as integrators do)
  forwardKinematicsIfStale(model, data, q, v);
  EXPECT_TRUE(sameAsFresh(q, v));
  v[model.nv - 1] += 1e-3;  // a changed v
  forwardKinematicsIfStale(model, data, q, v);
  EXPECT_TRUE(sameAsFresh(q, v));
  forwardKinematics(model, data, q);  // positions only: the velocities are not current
  data.v[0].setConstant(7);
  forwardKinematicsIfStale(model, data, q, v);
  EXPECT_TRUE(sameAsFresh(q, v));
  data.oMi[model.nbodies - 1].p.setConstant(7);  // the same (q, v): not recomputed
  forwardKinematicsIfStale(model, data, q, v);
  EXPECT_EQ(data.oMi[model.nbodies - 1].p, Vec3::Constant(7));
}

// A quaternion off the unit sphere (a caller's q that drifted, or scaled on
// purpose) stands for the rotation of q/|q|: the poses, the velocities and
// ABA's accelerations are those of the normalised q (to round-off), and every
// pose is a rotation. Before, R was the unit-quaternion formula applied to q,
// no rotation, and the dynamics silently wrong.
TEST(CoreKinematics, AQuaternionOffTheUnitSphereIsItsNormalisedRotation) {
  std::mt19937 rng(8);
  int quaternions = 0;
  for (const Model& model : models()) {
    const VecX q = randomConfiguration(model, rng);
    const VecX v = test::randomVector(model.nv, rng), tau = test::randomVector(model.nv, rng);
    VecX scaled = q;
    for (const Joint& j : model.joints) {
      const int at = j.type == JointType::Floating ? j.idx_q + 3 : j.idx_q;
      if (j.type != JointType::Floating && j.type != JointType::Ball) continue;
      scaled.segment<4>(at) *= std::uniform_real_distribution<double>(0.5, 2.0)(rng);
      ++quaternions;
    }
    Data a(model), b(model);
    forwardKinematics(model, a, q, v);
    forwardKinematics(model, b, scaled, v);
    for (int i = 0; i < model.nbodies; ++i) {
      EXPECT_LT((b.oMi[i].R.transpose() * b.oMi[i].R - Mat3::Identity()).norm(), 1e-14);
      EXPECT_LT((a.oMi[i].R - b.oMi[i].R).norm(), 1e-14);
      EXPECT_LT((a.oMi[i].p - b.oMi[i].p).norm(), 1e-14);
      EXPECT_LT((a.v[i] - b.v[i]).norm(), 1e-13 * (1 + a.v[i].norm()));
    }
    const VecX qdd_a = aba(model, a, q, v, tau), qdd_b = aba(model, b, scaled, v, tau);
    EXPECT_LT((qdd_a - qdd_b).norm(), 1e-11 * (1 + qdd_a.norm()));
  }
  EXPECT_GT(quaternions, 10);
}
