// Linearization about equilibria with known spectra.
#include <gtest/gtest.h>

#include <appell/kkt.hpp>
#include <appell/linearization.hpp>

#include "sleigh.hpp"

#include <Eigen/SVD>

#include <complex>

using namespace appell;
using namespace appell::scenes;

// Pendulum: μ² = ∓ m g l / I_hinge at the bottom / top.
TEST(Linearization, PendulumSpectrumAtBottomAndTop) {
  const double m = 2.0, l = 0.4, g = 9.81, Ic = 0.01;
  ModelBuilder b;
  b.addBody("bob", -1, SE3::Identity(), JointType::Revolute, Vec3::UnitX(),
            principalInertia(m, Vec3(Ic, Ic, Ic), Vec3(0, 0, -l)), "hinge");
  const Model model = b.build();
  const ConstraintList none;
  KktSolver solver(model, none);
  const double w2 = m * g * l / (Ic + m * l * l);
  for (double q0 : {0.0, 3.141592653589793}) {
    const LinearizationResult lin =
        linearize(model, none, solver, VecX::Constant(1, q0), VecX::Zero(1));
    ASSERT_EQ(lin.dimension, 2);
    EXPECT_LT(lin.steady_residual, 1e-12);
    const std::complex<double> mu = q0 == 0.0 ? std::complex<double>(0, std::sqrt(w2))
                                              : std::complex<double>(std::sqrt(w2), 0);
    for (int k = 0; k < 2; ++k)
      EXPECT_LT(std::min(std::abs(lin.eigenvalues[k] - mu), std::abs(lin.eigenvalues[k] + mu)),
                1e-7 * std::sqrt(w2));
  }
}

// The lateral sleigh resting across the slope (φ = 0), an equilibrium of the second
// kind. State on 𝓜: (x, y, φ) and the 2 admissible velocities (u along the
// blade, ω = φ̇): dimension 5. In the paper's variant the only forces are the
// weight at G and the lateral blade reaction at P, and P − G is itself lateral:
// neither has a moment about G, so I_G ω̇ = 0 exactly — yaw is neutral, not
// pendulum-like. Linearized: δω → δφ̇, δφ → δu̇ = g sin α δφ, δu → δẋ; x and y
// are free. So L is nilpotent: one Jordan chain (ω, φ, u, x) of length 4 and
// the free y: nullity(Lᵏ) = 2, 3, 4, 5 for k = 1…4, every eigenvalue 0.
TEST(Linearization, LateralSleighAcrossTheSlopeIsNilpotent) {
  const SleighParams p = lateralSleighParams(0.3, 0.35);
  const BuiltScene s = sleighReduced(p);
  KktSolver solver(s.model, s.constraints);
  const LinearizationResult lin = linearize(s.model, s.constraints, solver, s.q0, VecX::Zero(3));
  ASSERT_EQ(lin.dimension, 5);
  EXPECT_LT(lin.steady_residual, 1e-12);
  const double nL = lin.matrix.norm();
  auto nullity = [&](const MatX& M, int k) {  // tolerance relative to ‖L‖ᵏ, not to ‖M‖
    Eigen::JacobiSVD<MatX> svd(M);
    const VecX& sv = svd.singularValues();
    int r = 0;
    while (r < sv.size() && sv[r] > 1e-6 * std::pow(nL, k)) ++r;
    return static_cast<int>(M.cols()) - r;
  };
  MatX Lk = lin.matrix;
  for (int k = 1; k <= 4; ++k) {
    EXPECT_EQ(nullity(Lk, k), std::min(5, k + 1)) << "k = " << k << "\n" << lin.matrix;
    Lk = Lk * lin.matrix;
  }
  EXPECT_LT(Lk.norm(), 1e-6 * std::pow(lin.matrix.norm(), 5));
  // The nonlinear statement behind it: φ̈ = 0 on every state of the lateral variant.
  Data data(s.model);
  ConstraintData cd(s.model, s.constraints);
  std::mt19937 rng(5);
  for (int k = 0; k < 100; ++k) {
    VecX q, v;
    randomState(s, rng, 3.0, 1.0, 2.0, q, v);
    evaluateConstraints(s.model, data, s.constraints, cd, 0, q, v);
    ConstrainedResult r;
    solver.solve(s.model, data, s.constraints, cd, q, v, VecX::Zero(3), r);
    ASSERT_TRUE(r.ok);
    EXPECT_NEAR(r.vdot[2], 0.0, 1e-12 * (1 + r.vdot.norm()));
  }
}
