// The equilibrium finder on systems whose equilibria are known in closed form,
// its honesty when there is none, and its input checks.
#include <gtest/gtest.h>

#include <appell/equilibria.hpp>

#include "ball.hpp"

#include <numbers>

using namespace appell;
using namespace appell::scenes;

namespace {

constexpr double kM = 2.0, kL = 0.4, kG = 9.81;

/// A pendulum: revolute about x, centre of mass at (0, 0, −l).
Model pendulum() {
  ModelBuilder b;
  b.addBody("bob", -1, SE3::Identity(), JointType::Revolute, Vec3::UnitX(),
            principalInertia(kM, Vec3(0.01, 0.01, 0.01), Vec3(0, 0, -kL)), "hinge");
  return b.build();
}

Model freeBody(const Vec3& gravity) {
  ModelBuilder b;
  b.setGravity(gravity);
  b.addBody("body", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(),
            principalInertia(1.0, Vec3(0.1, 0.2, 0.25)), "free");
  return b.build();
}

VecX scalar(double x) { return VecX::Constant(1, x); }

}  // namespace

TEST(Equilibria, PendulumHasTwoIsolatedEquilibria) {
  const Model m = pendulum();
  const MultiStartResult ms = findEquilibria(m, {}, {scalar(0.3), scalar(-0.2), scalar(2.9), scalar(3.4)});
  ASSERT_EQ(ms.runs.size(), 4u);
  for (const EquilibriumResult& r : ms.runs) {
    ASSERT_TRUE(r.converged) << r.message;
    EXPECT_LT(std::abs(std::sin(r.q[0])), 1e-12);
    EXPECT_EQ(r.manifold_dimension, 0);
    EXPECT_EQ(r.lambda.size(), 0);
  }
  EXPECT_EQ(ms.distinct.size(), 2u);  // 0 and π
}

TEST(Equilibria, JointForceShiftsThePendulumEquilibrium) {
  const Model m = pendulum();
  EquilibriumOptions o;
  o.tau = scalar(0.5 * kM * kG * kL);  // sin θ = τ / (m g l) = 1/2 (sign by the hinge axis)
  const EquilibriumResult r = findEquilibrium(m, {}, scalar(0.2), o);
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_NEAR(std::abs(std::sin(r.q[0])), 0.5, 1e-12);
  EXPECT_LT(std::cos(r.q[0]), 0.0 + 1.0);  // finite, on the branch near the guess
  EXPECT_LT(std::abs(r.q[0]), 1.0);
}

TEST(Equilibria, BallOnAPlaneRestsAnywhere) {
  const BuiltScene s = ball();
  // Start 1 cm above the plane and rotated: the gap must close; every
  // position and orientation is an equilibrium (dimension 2 + 3 = 5).
  VecX q = s.q0;
  q[2] += 0.01;
  VecX th = VecX::Zero(6), q1(7);
  th.head<3>() << 0.3, -0.2, 1.0;
  retract(s.model, q, th, q1);
  const EquilibriumResult r = findEquilibrium(s.model, s.constraints, q1);
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_LT(r.gap_residual, 1e-12);
  EXPECT_EQ(r.manifold_dimension, 5);
  EXPECT_NEAR(r.lambda[2], 0.5 * kG, 1e-10);  // the normal row carries the weight
  EXPECT_NEAR(r.lambda[0], 0.0, 1e-10);
  EXPECT_NEAR(r.lambda[1], 0.0, 1e-10);
}

TEST(Equilibria, WithoutGravityEveryConfigurationIsAnEquilibrium) {
  const Model m = freeBody(Vec3::Zero());
  std::mt19937 rng(1);
  const EquilibriumResult r = findEquilibrium(m, {}, randomConfiguration(m, rng));
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_EQ(r.iterations, 0);
  EXPECT_EQ(r.manifold_dimension, 6);
}

TEST(Equilibria, FallingBodyHasNoneAndTheFinderSaysSo) {
  const Model m = freeBody(Vec3(0, 0, -kG));
  std::mt19937 rng(2);
  const EquilibriumResult r = findEquilibrium(m, {}, randomConfiguration(m, rng));
  EXPECT_FALSE(r.converged);
  EXPECT_NE(r.message.find("no equilibrium near the guess"), std::string::npos) << r.message;
  // Nothing can balance the weight: |Q|₂ = m g wherever the body is, so the
  // scaled max-norm residual stays ≥ 1/√3.
  EXPECT_GT(r.residual, 0.57);
}

TEST(Equilibria, MovingSupportCannotHoldABodyAtRestOffItsAxis) {
  BallParams p;
  p.centre = Vec3(0.3, 0, 0);
  const BuiltScene off = ballOnTurntable(2.0, p);
  const EquilibriumResult r = findEquilibrium(off.model, off.constraints, off.q0);
  EXPECT_FALSE(r.converged);
  EXPECT_GT(r.motion_residual, 0.1);
  EXPECT_NE(r.message.find("support moves"), std::string::npos) << r.message;
  // On the turntable's axis the table point under the ball does not move.
  p.centre = Vec3::Zero();
  const BuiltScene on = ballOnTurntable(2.0, p);
  const EquilibriumResult r0 = findEquilibrium(on.model, on.constraints, on.q0);
  EXPECT_TRUE(r0.converged) << r0.message;
}

TEST(Equilibria, BadInputIsRejectedWithAReason) {
  const Model m = pendulum();
  EXPECT_THROW(findEquilibrium(m, {}, VecX::Zero(3)), std::invalid_argument);
  EXPECT_THROW(findEquilibrium(m, {}, scalar(std::nan(""))), std::invalid_argument);
  EquilibriumOptions o;
  o.tau = VecX::Zero(4);
  EXPECT_THROW(findEquilibrium(m, {}, scalar(0.1), o), std::invalid_argument);
  o = {};
  o.tolerance = -1;
  EXPECT_THROW(findEquilibrium(m, {}, scalar(0.1), o), std::invalid_argument);
  try {
    findEquilibrium(m, {}, VecX::Zero(3));
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("nq = 1"), std::string::npos) << e.what();
  }
}
