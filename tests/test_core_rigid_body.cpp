// The torque-free rigid body: a floating joint, asymmetric inertia, no gravity.
//   • Energy, angular momentum (world frame, about the world origin) and linear
//     momentum are conserved: relative drift < 1e-10 over 10 s with the adaptive
//     Dormand–Prince integrator at tight tolerance.
//   • The body-frame angular velocity follows Euler's equations Ī ω̇ = (Ī ω) × ω
//     (integrated here independently, as a plain 3-vector ODE).
//   • Intermediate-axis theorem (Dzhanibekov effect): a spin about the middle
//     principal axis with a small perturbation flips — ω₂ changes sign after
//     about (1/λ) ln(Ω/δ), λ = Ω √((I₂−I₁)(I₃−I₂)/(I₁I₃)) — while spins about
//     the major and minor axes, perturbed alike, do not.
#include <appell/appell.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace appell;

namespace {

const Mat3 kInertia = Vec3(1.0, 2.0, 3.0).asDiagonal();  // principal moments I₁ < I₂ < I₃

/// A free body whose frame origin is not its centre of mass and whose principal
/// axes are the body axes.
Model freeBody(const Vec3& com = Vec3(0.1, -0.2, 0.05)) {
  ModelBuilder b;
  b.addBody("body", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(),
            Inertia{1.5, com, kInertia});
  b.setGravity(Vec3::Zero());
  return b.build();
}

struct AbaField : AccelerationField {
  const Model& model;
  Data data;
  VecX tau;
  explicit AbaField(const Model& m) : model(m), data(m), tau(VecX::Zero(m.nv)) {}
  bool operator()(double, const VecX& q, const VecX& v, VecX& a) override {
    a = aba(model, data, q, v, tau);
    return true;
  }
};

/// Euler's equations for the body-frame angular velocity, classical RK4.
Vec3 eulerRate(const Vec3& w) { return kInertia.inverse() * (kInertia * w).cross(w); }
Vec3 eulerStep(const Vec3& w, double h) {
  const Vec3 k1 = eulerRate(w), k2 = eulerRate(w + 0.5 * h * k1), k3 = eulerRate(w + 0.5 * h * k2),
             k4 = eulerRate(w + h * k3);
  return w + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
}

/// Body angular velocity (q: floating joint, v = (ω, v) body frame) after `T`
/// seconds and the times at which ω(axis) changed sign.
struct SpinRun {
  std::vector<double> t, w_axis;
  std::vector<double> flips;
  Vec3 w_end;
  double min_axis = 1e300, max_axis = -1e300;
};

SpinRun integrateEngine(const Model& model, const Vec3& w0, int axis, double T,
                    IntegratorOptions opt) {
  AbaField f(model);
  auto integ = makeIntegrator(IntegratorType::DormandPrince54, model, opt);
  VecX q = neutralConfiguration(model), v(6);
  v << w0, 0.2, -0.1, 0.3;
  double t = 0, h = 1e-3;
  SpinRun run;
  double prev = w0[axis];
  while (t < T) {
    const double t_prev = t;
    const StepResult r = integ->step(f, t, q, v, std::min(h, T - t));
    EXPECT_TRUE(r.ok);
    if (!r.ok) break;
    h = r.h_next;
    const double now = v[axis];
    if ((prev > 0) != (now > 0))  // linear interpolation of the crossing
      run.flips.push_back(t_prev + (t - t_prev) * prev / (prev - now));
    run.min_axis = std::min(run.min_axis, now);
    run.max_axis = std::max(run.max_axis, now);
    prev = now;
  }
  run.w_end = v.head<3>();
  return run;
}

SpinRun integrateEuler(const Vec3& w0, int axis, double T) {
  const double h = 1e-4;
  const int n = static_cast<int>(std::lround(T / h));
  Vec3 w = w0;
  SpinRun run;
  for (int s = 0; s < n; ++s) {
    const Vec3 w1 = eulerStep(w, h);
    if ((w[axis] > 0) != (w1[axis] > 0))
      run.flips.push_back(h * s + h * w[axis] / (w[axis] - w1[axis]));
    w = w1;
  }
  run.w_end = w;
  return run;
}

}  // namespace

TEST(CoreRigidBody, TorqueFreeBodyConservesEnergyAndMomentum) {
  const Model model = freeBody();
  Data data(model);
  AbaField f(model);
  IntegratorOptions opt;
  opt.rtol = 1e-12;
  opt.atol = 1e-14;
  auto integ = makeIntegrator(IntegratorType::DormandPrince54, model, opt);
  VecX q = neutralConfiguration(model), v(6);
  // A generic tumbling motion (no principal axis), plus drift of the frame.
  q.head<3>() << 0.5, -0.3, 1.0;
  v << 1.0, 0.6, -2.0, 0.3, -0.1, 0.2;
  const double E0 = kineticEnergy(model, data, q, v);
  const Vec6 h0 = momentum(model, data, q, v);
  const Vec3 w0 = v.head<3>();
  double t = 0, h = 1e-3, worst_E = 0, worst_L = 0, worst_P = 0;
  int steps = 0;
  const double T = 10.0;
  while (t < T) {
    const StepResult r = integ->step(f, t, q, v, std::min(h, T - t));
    ASSERT_TRUE(r.ok);
    h = r.h_next;
    ++steps;
    const Vec6 hm = momentum(model, data, q, v);
    worst_E = std::max(worst_E, std::abs(kineticEnergy(model, data, q, v) - E0) / E0);
    worst_L = std::max(worst_L, (angular(hm) - angular(h0)).norm() / angular(h0).norm());
    worst_P = std::max(worst_P, (linear(hm) - linear(h0)).norm() / linear(h0).norm());
  }
  std::printf("dopri5 rtol 1e-12: %d steps over 10 s; max relative drift: energy %.2e, "
              "angular momentum %.2e, linear momentum %.2e\n",
              steps, worst_E, worst_L, worst_P);
  EXPECT_LT(worst_E, 1e-10);
  EXPECT_LT(worst_L, 1e-10);
  EXPECT_LT(worst_P, 1e-10);

  // The rotation obeys Euler's equations whatever the frame origin.
  const SpinRun ref = integrateEuler(w0, 1, T);
  EXPECT_LT((v.head<3>() - ref.w_end).norm(), 1e-9 * w0.norm())
      << "engine " << v.head<3>().transpose() << " vs Euler " << ref.w_end.transpose();
  // The centre of mass moves uniformly: c(T) = c(0) + T ċ(0).
  forwardKinematics(model, data, q);
  const Vec3 c_end = data.oMi[0].apply(model.inertias[0].com);
  const Vec3 c_expect = Vec3(0.5, -0.3, 1.0) + model.inertias[0].com + T * linear(h0) / 1.5;
  EXPECT_LT((c_end - c_expect).norm(), 1e-9);
}

TEST(CoreRigidBody, IntermediateAxisFlips) {
  const Model model = freeBody();
  const double Omega = 2.0, delta = 1e-3 * Omega;
  const double I1 = 1, I2 = 2, I3 = 3;
  const double lambda = Omega * std::sqrt((I2 - I1) * (I3 - I2) / (I1 * I3));
  const double t_est = std::log(Omega / delta) / lambda;
  IntegratorOptions opt;
  opt.rtol = 1e-11;
  opt.atol = 1e-13;
  opt.h_max = 0.01;
  const double T = 3.0 * t_est;
  const SpinRun run = integrateEngine(model, Vec3(delta, Omega, delta), 1, T, opt);
  ASSERT_GE(run.flips.size(), 1u) << "no flip within " << T << " s";
  // The first flip comes after ≈ ln(Ω/δ)/λ: the perturbation grows like e^{λt}
  // until it is of the order of Ω (the O(1) constant is the ±2.5 e-foldings).
  std::printf("first flip at %.4f s, estimate ln(Ω/δ)/λ = %.4f s; flips: %zu; ω₂ ∈ [%.4f, %.4f]\n",
              run.flips[0], t_est, run.flips.size(), run.min_axis, run.max_axis);
  EXPECT_GT(run.flips[0], t_est - 2.5 / lambda);
  EXPECT_LT(run.flips[0], t_est + 2.5 / lambda);
  // It is a full reversal (the orbit hugs the separatrix): ω₂ reaches ≈ −Ω.
  EXPECT_LT(run.min_axis, -0.95 * Omega);
  // And it happens when Euler's equations say it does.
  const SpinRun ref = integrateEuler(Vec3(delta, Omega, delta), 1, T);
  ASSERT_EQ(ref.flips.size(), run.flips.size());
  for (size_t k = 0; k < ref.flips.size(); ++k) EXPECT_NEAR(run.flips[k], ref.flips[k], 1e-4);
}

TEST(CoreRigidBody, MajorAndMinorAxisSpinsAreStable) {
  const Model model = freeBody();
  const double Omega = 2.0, delta = 1e-3 * Omega;
  IntegratorOptions opt;
  opt.rtol = 1e-10;
  opt.atol = 1e-12;
  opt.h_max = 0.01;
  // 30 s is several times the intermediate-axis flip time above.
  const SpinRun minor_spin = integrateEngine(model, Vec3(Omega, delta, delta), 0, 30.0, opt);
  const SpinRun major_spin = integrateEngine(model, Vec3(delta, delta, Omega), 2, 30.0, opt);
  EXPECT_TRUE(minor_spin.flips.empty());
  EXPECT_TRUE(major_spin.flips.empty());
  // The spin component stays within the perturbation's size of Ω.
  EXPECT_GT(minor_spin.min_axis, Omega * (1 - 1e-3));
  EXPECT_GT(major_spin.min_axis, Omega * (1 - 1e-3));
}
