// Drift control: Newton on the holonomic gaps, then the impulse solve.
//  - after projectPositions + projectVelocity: |gap| and |A v + b| < 1e-12;
//  - the velocity correction is the M-orthogonal one: M(v⁺ − v) ∈ range(Aᵀ)
//    (optimality of min ‖v⁺ − v‖_M), equal to the closed form
//    v⁺ = v − M⁻¹Aᵀ(AM⁻¹Aᵀ)⁻¹(A v + b), and the same for both solvers;
//  - quaternions stay unit (the step is a retraction, not an addition);
//  - redundant gap rows are fine, contradictory ones an error (q untouched);
//  - Baumgarte (the option): a gap error obeys ë + 2αė + α²e = 0.
#include <appell/appell_maggi.hpp>
#include <appell/kkt.hpp>
#include <appell/projection.hpp>
#include <appell/simulator.hpp>

#include "random_tree.hpp"
#include "test_solver_rows.hpp"

#include <Eigen/SVD>
#include <gtest/gtest.h>

namespace appell {
namespace {

using test::RollingBall;

// A ball with a pendulum hanging inside it (a second body on a revolute
// joint): the rolling rows act on the ball, M couples both.
Model ballWithPendulum() {
  ModelBuilder b;
  b.addBody("ball", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(),
            Inertia{2.0, Vec3(0.01, -0.02, 0.0), Vec3(0.05, 0.06, 0.07).asDiagonal()}, "free");
  SE3 X;
  X.p = Vec3(0, 0, 0.1);
  b.addBody("bob", 0, X, JointType::Revolute, Vec3(1, 1, 0).normalized(),
            Inertia{0.5, Vec3(0, 0, -0.2), Vec3(0.01, 0.01, 0.002).asDiagonal()}, "hinge");
  return b.build();
}

double quatNormError(const VecX& q) { return std::abs(q.segment<4>(3).norm() - 1.0); }

TEST(Projection, PositionsThenVelocitiesReachRoundOffAndAreMOrthogonal) {
  const Model model = ballWithPendulum();
  const double R = 0.3;
  ConstraintList c{std::make_shared<RollingBall>("ball_contact", 0, R)};
  Data data(model);
  ConstraintData cd(model, c);
  std::mt19937 rng(11);
  KktSolver kkt(model, c);
  AppellSolver appell(model, c);
  for (int trial = 0; trial < 50; ++trial) {
    VecX q = randomConfiguration(model, rng);
    q[2] = R + 0.05 * std::uniform_real_distribution<double>(-1, 1)(rng);  // off the plane
    const VecX v0 = test::randomVector(model.nv, rng, 2.0);
    const PositionProjectionResult pr = projectPositions(model, data, c, cd, 0.0, q);
    ASSERT_TRUE(pr.ok) << pr.error;
    EXPECT_GT(pr.initial_residual, 0.0);
    EXPECT_LE(pr.residual, 1e-12);
    EXPECT_LE(pr.iterations, 3);  // the gap is linear in the ball's height: one step
    EXPECT_LT(quatNormError(q), 1e-15);
    evaluateConstraints(model, data, c, cd, 0.0, q, v0);
    EXPECT_LT(gapResidual(cd), 1e-12);

    const MatX M = crba(model, data, q);
    const MatX& A = cd.A;
    // Closed form of the M-orthogonal projection (A has full rank here).
    const MatX MiAt = M.ldlt().solve(A.transpose());
    const VecX expected = v0 - MiAt * (A * MiAt).ldlt().solve(A * v0 + cd.b);
    for (ConstrainedSolver* s : {static_cast<ConstrainedSolver*>(&kkt),
                                 static_cast<ConstrainedSolver*>(&appell)}) {
      VecX v = v0, mu;
      ASSERT_TRUE(s->projectVelocity(model, data, c, cd, q, v, mu));
      EXPECT_LT(velocityResidual(model, data, c, cd, q, v), 1e-12);
      EXPECT_LT((v - expected).norm(), 1e-12 * (1 + v0.norm()));
      // v⁺ = v − M⁻¹Aᵀμ, and M(v⁺ − v) lies in range(Aᵀ).
      EXPECT_LT((M * (v - v0) + A.transpose() * mu).norm(), 1e-12 * (1 + v0.norm()));
      Eigen::JacobiSVD<MatX> svd(A.transpose(), Eigen::ComputeThinU | Eigen::ComputeThinV);
      const VecX dp = M * (v - v0);
      const VecX outside = dp - A.transpose() * svd.solve(dp);
      EXPECT_LT(outside.norm(), 1e-12 * (1 + dp.norm()));
      // Optimality: any other admissible velocity is farther in the M metric.
      const VecX other = v + (MatX::Identity(model.nv, model.nv) -
                              A.transpose() * (A * A.transpose()).inverse() * A) *
                                 test::randomVector(model.nv, rng, 0.1);
      EXPECT_GT((other - v0).dot(M * (other - v0)), (v - v0).dot(M * (v - v0)));
    }
  }
}

TEST(Projection, RedundantGapRowsAreFineContradictoryOnesAnError) {
  const Model model = ballWithPendulum();
  ConstraintList dup{std::make_shared<RollingBall>("contact_a", 0, 0.3),
                     std::make_shared<RollingBall>("contact_b", 0, 0.3)};
  Data data(model);
  ConstraintData cd(model, dup);
  std::mt19937 rng(2);
  VecX q = randomConfiguration(model, rng);
  q[2] = 0.31;
  PositionProjectionResult pr = projectPositions(model, data, dup, cd, 0.0, q);
  ASSERT_TRUE(pr.ok) << pr.error;
  EXPECT_EQ(pr.rank, 1);
  EXPECT_LE(pr.residual, 1e-12);
  // Velocity projection with 6 rows of rank 3.
  VecX v = test::randomVector(model.nv, rng), mu;
  evaluateConstraints(model, data, dup, cd, 0.0, q, v);
  KktSolver kkt(model, dup);
  ASSERT_TRUE(kkt.projectVelocity(model, data, dup, cd, q, v, mu));
  EXPECT_LT(velocityResidual(model, data, dup, cd, q, v), 1e-12);
  EXPECT_LT((mu.head(3) - mu.tail(3)).norm(), 1e-12 * (1 + mu.norm()));  // minimum norm: equal split

  ConstraintList bad{std::make_shared<RollingBall>("small_ball", 0, 0.3),
                     std::make_shared<RollingBall>("big_ball", 0, 0.4)};
  ConstraintData cdb(model, bad);
  VecX q2 = q;
  pr = projectPositions(model, data, bad, cdb, 0.0, q2);
  EXPECT_FALSE(pr.ok);
  EXPECT_NE(pr.error.find("small_ball"), std::string::npos) << pr.error;
  EXPECT_NE(pr.error.find("big_ball"), std::string::npos) << pr.error;
  EXPECT_EQ(q2, q);
}

// Baumgarte only (no projection): a homogeneous ball released 1 mm above the
// plane with consistent velocities. The normal row then obeys
// ë + 2αė + α²e = 0 exactly, e(t) = e₀ (1 + αt) e^{−αt}. Every formulation:
// the correction is applied to the rows, which the tree solver reads too.
TEST(Projection, BaumgarteOptionGivesCriticallyDampedGap) {
  const Model model = test::ballModel(1.0, Vec3::Constant(0.4 * 0.09).asDiagonal(), Vec3::Zero());
  const double R = 0.3, alpha = 5.0, e0 = 1e-3;
  ConstraintList c{std::make_shared<RollingBall>("contact", 0, R)};
  SimulatorOptions so;
  so.project_positions = so.project_velocities = false;
  so.baumgarte = {true, alpha, alpha};
  IntegratorOptions io;
  io.rtol = io.atol = 1e-12;
  VecX q = neutralConfiguration(model);
  q[2] = R + e0;
  VecX v = VecX::Zero(6);
  v.head<3>() = Vec3(0, 2.0, 0);  // rolling about y... ω_y with ẋ = ω_y R
  v[3] = 2.0 * R;
  for (Formulation f : {Formulation::Multipliers, Formulation::Appell, Formulation::Tree}) {
    SCOPED_TRACE(toString(f));
    Simulator sim(model, c, makeSolver(f, model, c), IntegratorType::DormandPrince54, io, so);
    sim.setState(0, q, v);
    for (double t : {0.2, 0.5, 1.0}) {
      ASSERT_TRUE(sim.advanceTo(t, 1e-3).ok);
      const double expected = e0 * (1 + alpha * t) * std::exp(-alpha * t);
      EXPECT_NEAR(sim.gapResidual(), expected, 1e-9) << "t = " << t;
    }
  }
  // Without stabilisation the gap stays where it was (the rows fix ġ = 0 only).
  so.baumgarte.enabled = false;
  Simulator free_sim(model, c, std::make_unique<KktSolver>(model, c),
                     IntegratorType::DormandPrince54, io, so);
  free_sim.setState(0, q, v);
  ASSERT_TRUE(free_sim.advanceTo(1.0, 1e-3).ok);
  EXPECT_NEAR(free_sim.gapResidual(), e0, 1e-9);
}

TEST(Projection, ApplyBaumgarteAddsTheStatedTerms) {
  const Model model = ballWithPendulum();
  ConstraintList c{std::make_shared<RollingBall>("contact", 0, 0.3)};
  Data data(model);
  ConstraintData cd(model, c);
  std::mt19937 rng(9);
  VecX q = randomConfiguration(model, rng);
  const VecX v = test::randomVector(model.nv, rng);
  evaluateConstraints(model, data, c, cd, 0, q, v);
  const VecX before = cd.abias;
  applyBaumgarte(data, c, cd, v, 2.0, 3.0);
  const VecX expected = before + 4.0 * (cd.A * v + cd.b) + 9.0 * cd.gap;
  EXPECT_LT((cd.abias - expected).norm(), 1e-14 * (1 + expected.norm()));
  // The correction lives in the rows (κ): the dense form assembled from them
  // again — as a dense solver does — carries it too.
  cd.abias.setZero();
  assembleDenseRows(model, data, c, cd);
  EXPECT_LT((cd.abias - expected).norm(), 1e-14 * (1 + expected.norm()));
  EXPECT_NE(cd.gap[2], 0.0);
}

}  // namespace
}  // namespace appell
