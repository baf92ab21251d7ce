// Emelyanova & Fufaev (1978; docs/equilibria.md), example 1: the Chaplygin sleigh on an
// inclined plane. Equilibria of the second kind φ = 0, π with λ = ±m g sin α
// on the row ẋ sin φ − ẏ cos φ = 0 (the blade across the slope holds the
// sleigh); the partition ẋ = ẏ cot φ is singular exactly there. The usual
// sleigh (centre of mass along the blade) has no static equilibrium.
#include <gtest/gtest.h>

#include <appell/appell_maggi.hpp>
#include <appell/equilibria.hpp>
#include <appell/kkt.hpp>
#include <appell/tree_solver.hpp>

#include "sleigh.hpp"

#include <numbers>

using namespace appell;
using namespace appell::scenes;

namespace {

constexpr double kAlpha = 0.35, kL = 0.3;

/// Heading φ of the floating sleigh: blade direction in (e₁, d).
double headingOf(const VecX& q, double alpha) {
  const Incline f = inclineFrame(alpha);
  const Vec3 blade = floatingRotation(q, 0).col(0);
  return std::atan2(blade.dot(f.d), blade.dot(f.e1));
}

/// The paper's λ: the blade's lateral reaction force projected on the paper's row direction.
double bladeLambdaFloating(const EquilibriumResult& r, double alpha) {
  const Incline f = inclineFrame(alpha);
  const Vec3 blade = floatingRotation(r.q, 0).col(0);
  const Vec3 lateral = f.n.cross(blade).normalized();  // the contact module's row direction
  const Vec3 force = r.lambda[0] * lateral;
  return force.dot(bladeRowDirection(alpha, headingOf(r.q, alpha)));
}

std::vector<VecX> headingGuesses(const SleighParams& base, const std::vector<double>& phis,
                                 bool floating) {
  std::vector<VecX> out;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (double phi : phis) {
    SleighParams p = base;
    p.heading = phi;
    p.x = u(rng);
    p.y = u(rng);
    BuiltScene s = floating ? sleigh(p) : sleighReduced(p);
    if (floating) {
      // Start off the gaps too: tilt and lift the body a little.
      VecX th = VecX::Zero(6);
      th << 0.05 * u(rng), 0.05 * u(rng), 0.02 * u(rng), 0.03, -0.02, 0.04;
      VecX q(s.model.nq);
      retract(s.model, s.q0, th, q);
      out.push_back(q);
    } else {
      out.push_back(s.q0);
    }
  }
  return out;
}

}  // namespace

TEST(LateralSleigh, FloatingFinderFindsPhi0AndPiWithLambda) {
  const SleighParams p = lateralSleighParams(kL, kAlpha);
  const BuiltScene s = sleigh(p);
  const double mg = p.mass * 9.81;
  const auto guesses = headingGuesses(p, {0.4, -0.3, 0.9, std::numbers::pi + 0.3, std::numbers::pi - 0.6, 2.4}, true);
  bool found0 = false, foundPi = false;
  for (const VecX& g : guesses) {
    const EquilibriumResult r = findEquilibrium(s.model, s.constraints, g);
    ASSERT_TRUE(r.converged) << r.message;
    EXPECT_LT(r.gap_residual, 1e-10);
    const double phi = headingOf(r.q, kAlpha);
    EXPECT_LT(std::abs(std::sin(phi)), 1e-9) << "phi = " << phi;
    const double lam = bladeLambdaFloating(r, kAlpha);
    if (std::cos(phi) > 0) {
      found0 = true;
      EXPECT_NEAR(lam, mg * std::sin(kAlpha), 1e-9 * mg);
    } else {
      foundPi = true;
      EXPECT_NEAR(lam, -mg * std::sin(kAlpha), 1e-9 * mg);
    }
    // The three normal rows carry the weight's normal component.
    EXPECT_NEAR(r.lambda[1] + r.lambda[2] + r.lambda[3], mg * std::cos(kAlpha), 1e-9 * mg);
    // x and y are free: the equilibria form a 2-dimensional manifold.
    EXPECT_EQ(r.manifold_dimension, 2);
    EXPECT_EQ(r.redundant_rows, 0);
  }
  EXPECT_TRUE(found0);
  EXPECT_TRUE(foundPi);
}

TEST(LateralSleigh, ReducedFinderSolvesThePapersEquations) {
  const SleighParams p = lateralSleighParams(kL, kAlpha);
  const BuiltScene s = sleighReduced(p);
  const double mg = p.mass * 9.81;
  const auto guesses = headingGuesses(p, {0.5, -0.7, 2.6, 3.6}, false);
  const MultiStartResult ms = findEquilibria(s.model, s.constraints, guesses);
  bool found0 = false, foundPi = false;
  for (const EquilibriumResult& r : ms.runs) {
    ASSERT_TRUE(r.converged) << r.message;
    const double phi = r.q[2];
    // The paper's (3): λ sin φ = 0, m g sin α − λ cos φ = 0, m g l sin α sin φ = 0.
    EXPECT_LT(std::abs(std::sin(phi)), 1e-10);
    EXPECT_NEAR(mg * std::sin(kAlpha) - r.lambda[0] * std::cos(phi), 0.0, 1e-9 * mg);
    if (std::cos(phi) > 0) {
      found0 = true;
      EXPECT_NEAR(r.lambda[0], mg * std::sin(kAlpha), 1e-9 * mg);
    } else {
      foundPi = true;
      EXPECT_NEAR(r.lambda[0], -mg * std::sin(kAlpha), 1e-9 * mg);
    }
    EXPECT_EQ(r.manifold_dimension, 2);
    EXPECT_EQ(r.row_labels.at(0), "blade/lateral");
  }
  EXPECT_TRUE(found0);
  EXPECT_TRUE(foundPi);
  EXPECT_EQ(ms.distinct.size(), ms.runs.size());  // different x, y: all distinct points
}

TEST(LateralSleigh, UsualSleighHasNoEquilibriumAndTheFinderSaysSo) {
  const SleighParams p = usualSleighParams(0.3, kAlpha);
  const double mg = p.mass * 9.81;
  for (bool floating : {true, false}) {
    const BuiltScene s = floating ? sleigh(p) : sleighReduced(p);
    for (const VecX& g : headingGuesses(p, {0.0, 0.5, 1.5, -1.2, std::numbers::pi, 2.0}, floating)) {
      const EquilibriumResult r = findEquilibrium(s.model, s.constraints, g);
      EXPECT_FALSE(r.converged) << "false equilibrium at " << r.q.transpose();
      EXPECT_NE(r.message.find("no equilibrium near the guess"), std::string::npos) << r.message;
      // The residual cannot be made small: gravity along the slope has nothing to balance it.
      EXPECT_GT(r.force_residual, 1e-3 * mg) << r.message;
    }
  }
}

// The Appell solver at φ = 0, where ẋ = ẏ cot φ is singular: with an
// orthonormal null-space basis (and with a pivoted partition) it holds the
// sleigh at rest with λ = m g sin α, and agrees with the KKT solve nearby.
TEST(LateralSleigh, AppellAccurateAtTheSecondKindEquilibrium) {
  const SleighParams p = lateralSleighParams(kL, kAlpha);
  const BuiltScene s = sleighReduced(p);
  const double mg = p.mass * 9.81;
  AppellOptions partition;
  partition.null_space = NullSpace::CoordinatePartition;
  std::vector<std::unique_ptr<ConstrainedSolver>> solvers;
  solvers.push_back(std::make_unique<KktSolver>(s.model, s.constraints));
  solvers.push_back(std::make_unique<AppellSolver>(s.model, s.constraints));
  solvers.push_back(std::make_unique<AppellSolver>(s.model, s.constraints, SolverOptions{}, partition));
  solvers.push_back(std::make_unique<TreeSolver>(s.model, s.constraints));
  Data data(s.model);
  ConstraintData cd(s.model, s.constraints);
  const VecX tau = VecX::Zero(3);
  for (double phi : {0.0, 1e-12, -1e-9, std::numbers::pi}) {
    VecX q = s.q0;
    q[2] = phi;
    const VecX v = VecX::Zero(3);
    for (auto& solver : solvers) {
      ConstrainedResult r;
      evaluateConstraints(s.model, data, s.constraints, cd, 0, q, v);
      solver->solve(s.model, data, s.constraints, cd, q, v, tau, r);
      ASSERT_TRUE(r.ok) << toString(solver->formulation()) << ": " << r.error;
      // At φ = 0 exactly, rest; at φ = ±ε the residual acceleration is O(ε).
      EXPECT_LT(r.vdot.lpNorm<Eigen::Infinity>(), 1e-8) << toString(solver->formulation()) << " phi " << phi;
      EXPECT_NEAR(r.lambda[0], std::cos(phi) * mg * std::sin(kAlpha), 1e-9 * mg)
          << toString(solver->formulation()) << " phi " << phi;
    }
  }
  // Moving states near φ = 0: all formulations agree to round-off.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int k = 0; k < 200; ++k) {
    VecX q = s.q0;
    q[2] = (k % 2 ? 1e-10 : 1e-3) * u(rng) + (k % 4 < 2 ? 0.0 : std::numbers::pi);
    VecX v(3);
    v << u(rng), u(rng), 2 * u(rng);
    projectVelocity(s.model, s.constraints, q, v);
    ConstrainedResult ref;
    evaluateConstraints(s.model, data, s.constraints, cd, 0, q, v);
    solvers[0]->solve(s.model, data, s.constraints, cd, q, v, tau, ref);
    ASSERT_TRUE(ref.ok);
    for (size_t j = 1; j < solvers.size(); ++j) {
      ConstrainedResult r;
      evaluateConstraints(s.model, data, s.constraints, cd, 0, q, v);
      solvers[j]->solve(s.model, data, s.constraints, cd, q, v, tau, r);
      ASSERT_TRUE(r.ok) << r.error;
      EXPECT_LT((r.vdot - ref.vdot).norm(), 1e-10 * (1 + ref.vdot.norm())) << toString(solvers[j]->formulation());
      EXPECT_LT((r.lambda - ref.lambda).norm(), 1e-10 * (1 + ref.lambda.norm()));
    }
  }
}
