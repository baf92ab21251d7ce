// Linearization about steady motions of a rolling disk (relative equilibria),
// with position, heading and spin as cyclic coordinates (rollingDiskChain).
//
// Straight rolling of an upright disk at axle rate s: the lean-frame equations of
// Kane & Levinson (Dynamics: Theory and Applications, 1985, the rolling disk), linearised at θ = 0, u₁ = 0, u₂ = s, u₃ = 0 give
//   θ̇ = u₁,  u̇₁ = (6 s r u₃ + 4 g θ)/(5 r),  u̇₂ = 0,  u̇₃ = −2 s u₁,
// whose eigenvalues are 0, 0, ±√(4g/(5r) − 12 s²/5): stable (imaginary) iff
// s² > g/(3r). The two zeros are the neighbouring steady motions (another
// speed; a slow circle with a small lean), not a Jordan block.
#include <gtest/gtest.h>

#include <appell/appell_maggi.hpp>
#include <appell/kkt.hpp>
#include <appell/linearization.hpp>
#include <appell/tree_solver.hpp>

#include "rolling_disk.hpp"

#include <complex>

using namespace appell;
using namespace appell::scenes;

namespace {

const std::vector<int> kCyclic = {0, 1, 2, 4};  // a, b, ψ (planar) and the spin φ

}  // namespace

TEST(DiskLinearization, StraightRollingMatchesTheAnalyticEigenvalues) {
  const double g = 9.81;
  for (double s : {5.0, 1.0, -3.0}) {
    DiskChainParams p;
    p.spin_rate = s;
    const BuiltScene sc = rollingDiskChain(p);
    const double r = p.radius;
    const double mu2 = 4 * g / (5 * r) - 12 * s * s / 5;  // μ² of the nonzero pair
    std::vector<std::unique_ptr<ConstrainedSolver>> solvers;
    solvers.push_back(std::make_unique<KktSolver>(sc.model, sc.constraints));
    solvers.push_back(std::make_unique<AppellSolver>(sc.model, sc.constraints));
    solvers.push_back(std::make_unique<TreeSolver>(sc.model, sc.constraints));
    for (auto& solver : solvers) {
      LinearizationOptions o;
      o.cyclic = kCyclic;
      const LinearizationResult lin = linearize(sc.model, sc.constraints, *solver, sc.q0, sc.v0, o);
      EXPECT_LT(lin.steady_residual, 1e-10);
      EXPECT_LT(lin.symmetry_residual, 1e-7);
      EXPECT_LT(lin.constraint_residual, 1e-12);
      ASSERT_EQ(lin.dimension, 4);  // lean, lean rate, turn rate, axle rate
      EXPECT_NEAR(lin.drift[4], s, 1e-12);  // the spin angle drifts at s
      std::vector<std::complex<double>> ev(lin.eigenvalues.data(), lin.eigenvalues.data() + 4);
      std::sort(ev.begin(), ev.end(), [](auto a, auto b) { return std::abs(a) < std::abs(b); });
      EXPECT_LT(std::abs(ev[0]), 1e-6);
      EXPECT_LT(std::abs(ev[1]), 1e-6);
      const std::complex<double> mu = std::sqrt(std::complex<double>(mu2, 0));
      for (int k = 2; k < 4; ++k)
        EXPECT_LT(std::min(std::abs(ev[k] - mu), std::abs(ev[k] + mu)), 1e-6 * std::abs(mu))
            << toString(solver->formulation()) << " s = " << s << ": " << ev[k] << " vs ±" << mu;
      if (mu2 < 0) {
        EXPECT_LT(std::abs(ev[2].real()), 1e-6);  // stable: purely imaginary
      }
    }
  }
}

// Steady circular rolling with a lean: the chain model checks the steady
// condition (steadyDiskAxleRate) independently of any simulation: f_r = 0.
// (Chain axle a = R_x(θ) e_y, so ω·a = φ̇ + ψ̇ sin θ.)
TEST(DiskLinearization, SteadyCircularRollingIsARelativeEquilibrium) {
  for (double lean : {0.3, -0.6}) {
    DiskChainParams p;
    p.lean = lean;
    p.heading_rate = 2.0;
    const Vec3 I = thinDiskInertia(p.mass, p.radius);
    const double wa = steadyDiskAxleRate(p.mass, p.radius, I.x(), I.z(), 9.81, lean, p.heading_rate);
    p.spin_rate = wa - p.heading_rate * std::sin(lean);
    const BuiltScene sc = rollingDiskChain(p);
    KktSolver solver(sc.model, sc.constraints);
    LinearizationOptions o;
    o.cyclic = kCyclic;
    const LinearizationResult lin = linearize(sc.model, sc.constraints, solver, sc.q0, sc.v0, o);
    EXPECT_LT(lin.steady_residual, 1e-10) << "lean " << lean;
    EXPECT_LT(lin.symmetry_residual, 1e-7);
    ASSERT_EQ(lin.dimension, 4);
    // A two-parameter family of steady motions (lean, turn rate) gives two zeros;
    // the remaining pair is ±μ.
    EXPECT_EQ(countZeroEigenvalues(lin, 1e-6), 2) << lin.eigenvalues.transpose();
    std::vector<std::complex<double>> nz;
    for (Eigen::Index i = 0; i < 4; ++i)
      if (std::abs(lin.eigenvalues[i]) > 1e-6) nz.push_back(lin.eigenvalues[i]);
    ASSERT_EQ(nz.size(), 2u);
    EXPECT_LT(std::abs(nz[0] + nz[1]), 1e-6 * std::abs(nz[0]));

    // A wrong axle rate is not steady, and the linearization says so.
    DiskChainParams bad = p;
    bad.spin_rate *= 1.05;
    const BuiltScene sb = rollingDiskChain(bad);
    KktSolver solver_b(sb.model, sb.constraints);
    EXPECT_GT(linearize(sb.model, sb.constraints, solver_b, sb.q0, sb.v0, o).steady_residual, 1e-3);
  }
}

TEST(DiskLinearization, BadCyclicIndicesAreRejected) {
  const BuiltScene sc = rollingDiskChain();
  KktSolver solver(sc.model, sc.constraints);
  LinearizationOptions o;
  o.cyclic = {0, 7};
  EXPECT_THROW(linearize(sc.model, sc.constraints, solver, sc.q0, sc.v0, o), std::invalid_argument);
  o.cyclic = {1, 1};
  EXPECT_THROW(linearize(sc.model, sc.constraints, solver, sc.q0, sc.v0, o), std::invalid_argument);
  EXPECT_THROW(linearize(sc.model, sc.constraints, solver, sc.q0, VecX::Zero(3)), std::invalid_argument);
}
