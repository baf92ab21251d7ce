// Rank handling of the dense solvers (and the minimum-norm split of the tree
// solver, the contract of constrained_dynamics.hpp): redundant rows (minimum-norm λ, counted),
// inconsistent rows (an error naming the rows, never a wrong answer), rows no
// motion can influence, and the Emelyanova–Fufaev sleigh: equilibrium at φ = 0 with
// λ = ±m g sin α, where the fixed partition ẋ = ẏ cot φ is singular; the
// coordinate partition re-chooses itself there and stays accurate.
#include <appell/appell_maggi.hpp>
#include <appell/kkt.hpp>
#include <appell/tree_solver.hpp>

#include "random_tree.hpp"
#include "test_solver_rows.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace appell {
namespace {

using test::BodyRows;
using test::pointRow;

std::vector<std::unique_ptr<ConstrainedSolver>> allSolvers(const Model& model,
                                                          const ConstraintList& c) {
  std::vector<std::unique_ptr<ConstrainedSolver>> s;
  s.push_back(std::make_unique<KktSolver>(model, c));
  s.push_back(std::make_unique<AppellSolver>(model, c));
  s.push_back(std::make_unique<AppellSolver>(model, c, SolverOptions{},
                                             AppellOptions{NullSpace::CoordinatePartition}));
  return s;
}

// A free ball; a point at its surface held still by three rows, and the same
// three rows again, scaled by 2 (a second contact on the same rigid point).
TEST(SolverRedundancy, ScaledDuplicateRowsGiveMinimumNormSplit) {
  const Model model = test::ballModel(2.0, Vec3(0.1, 0.2, 0.3).asDiagonal(), Vec3(0.01, 0, 0.02));
  const Vec3 x(0, 0, -0.5);
  std::vector<Vec6> w{pointRow(x, Vec3::UnitX()), pointRow(x, Vec3::UnitY()),
                      pointRow(x, Vec3::UnitZ())};
  std::vector<Vec6> w2{2 * w[0], 2 * w[1], 2 * w[2]};
  ConstraintList c{std::make_shared<BodyRows>("pivot", 0, w),
                   std::make_shared<BodyRows>("pivot_again", 0, w2)};
  ConstraintList single{c[0]};
  Data data(model);
  ConstraintData cd(model, c), cd1(model, single);
  std::mt19937 rng(3);
  VecX q = randomConfiguration(model, rng);
  const VecX v = test::randomVector(6, rng), tau = test::randomVector(6, rng);
  evaluateConstraints(model, data, single, cd1, 0, q, v);
  KktSolver ref(model, single);
  ConstrainedResult r1;
  ref.solve(model, data, single, cd1, q, v, tau, r1);
  ASSERT_TRUE(r1.ok);
  EXPECT_EQ(r1.redundant, 0);
  evaluateConstraints(model, data, c, cd, 0, q, v);
  auto solvers = allSolvers(model, c);
  solvers.push_back(makeTreeSolver(model, c));
  for (auto& s : solvers) {
    SCOPED_TRACE(toString(s->formulation()));
    ConstrainedResult r;
    s->solve(model, data, c, cd, q, v, tau, r);
    ASSERT_TRUE(r.ok) << r.error;
    EXPECT_EQ(r.rank, 3);
    EXPECT_EQ(r.redundant, 3);
    EXPECT_LT((r.vdot - r1.vdot).norm(), 1e-12 * (1 + r1.vdot.norm()));
    EXPECT_LT((r.reaction - r1.reaction).norm(), 1e-12 * (1 + r1.reaction.norm()));
    // λ₁ + 2λ₂ = λ_single with least ‖λ‖: λ₁ = λ_single/5, λ₂ = 2λ_single/5.
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(r.lambda[k], r1.lambda[k] / 5, 1e-12 * (1 + r1.lambda.norm()));
      EXPECT_NEAR(r.lambda[3 + k], 2 * r1.lambda[k] / 5, 1e-12 * (1 + r1.lambda.norm()));
    }
  }
}

TEST(SolverRedundancy, ContradictoryRowsAreAnErrorNamingThem) {
  const Model model = test::ballModel(1.0, Vec3(0.1, 0.1, 0.1).asDiagonal(), Vec3::Zero());
  const Vec6 w = pointRow(Vec3(0, 0, -1), Vec3::UnitX());
  // Same row, different acceleration offsets: A v̇ = −0 and A v̇ = −1 together.
  ConstraintList c{std::make_shared<BodyRows>("left_wheel", 0, std::vector<Vec6>{w}),
                   std::make_shared<BodyRows>("right_wheel", 0, std::vector<Vec6>{w},
                                              std::vector<double>{0.0},
                                              std::vector<double>{1.0})};
  Data data(model);
  ConstraintData cd(model, c);
  const VecX q = neutralConfiguration(model), v = VecX::Zero(6), tau = VecX::Zero(6);
  evaluateConstraints(model, data, c, cd, 0, q, v);
  auto solvers = allSolvers(model, c);
  solvers.push_back(makeTreeSolver(model, c));
  for (auto& s : solvers) {
    SCOPED_TRACE(toString(s->formulation()));
    ConstrainedResult r;
    s->solve(model, data, c, cd, q, v, tau, r);
    EXPECT_FALSE(r.ok);
    EXPECT_NE(r.error.find("inconsistent"), std::string::npos) << r.error;
    EXPECT_NE(r.error.find("left_wheel"), std::string::npos) << r.error;
    EXPECT_NE(r.error.find("right_wheel"), std::string::npos) << r.error;
  }
  // Velocity level: the same rows with different b.
  ConstraintList cb{c[0], std::make_shared<BodyRows>("right_wheel", 0, std::vector<Vec6>{w},
                                                     std::vector<double>{0.5})};
  ConstraintData cdb(model, cb);
  evaluateConstraints(model, data, cb, cdb, 0, q, v);
  for (auto& s : allSolvers(model, cb)) {
    VecX vv = test::randomVector(6, *std::make_unique<std::mt19937>(1).get());
    const VecX before = vv;
    VecX mu;
    EXPECT_FALSE(s->projectVelocity(model, data, cb, cdb, q, vv, mu));
    EXPECT_EQ(vv, before);  // untouched
  }
}

// A body welded to the world: its rows cannot be influenced by any motion.
TEST(SolverRedundancy, RowsNoMotionCanMoveAreRedundantOrInconsistent) {
  ModelBuilder b;
  b.addBody("base", -1, SE3::Identity(), JointType::Revolute, Vec3::UnitZ(),
            Inertia{1, Vec3(0.3, 0, 0), Vec3(0.1, 0.1, 0.1).asDiagonal()});
  b.addBody("welded", -1, SE3::Identity(), JointType::Fixed, Vec3::UnitZ(),
            Inertia{1, Vec3::Zero(), Vec3(0.1, 0.1, 0.1).asDiagonal()});
  const Model model = b.build();
  const Vec6 w = pointRow(Vec3(1, 0, 0), Vec3::UnitY());
  Data data(model);
  const VecX q = VecX::Constant(1, 0.3), v = VecX::Constant(1, 0.7), tau = VecX::Constant(1, 0.2);
  for (double kappa : {0.0, 2.0}) {
    ConstraintList c{std::make_shared<BodyRows>("stuck", 1, std::vector<Vec6>{w},
                                                std::vector<double>{0.0},
                                                std::vector<double>{kappa})};
    ConstraintData cd(model, c);
    evaluateConstraints(model, data, c, cd, 0, q, v);
    for (auto& s : allSolvers(model, c)) {
      ConstrainedResult r;
      s->solve(model, data, c, cd, q, v, tau, r);
      if (kappa == 0) {
        ASSERT_TRUE(r.ok) << r.error;
        EXPECT_EQ(r.rank, 0);
        EXPECT_EQ(r.redundant, 1);
        EXPECT_EQ(r.lambda[0], 0.0);
        EXPECT_NEAR(r.vdot[0], aba(model, data, q, v, tau)[0], 1e-12);
      } else {
        EXPECT_FALSE(r.ok);
        EXPECT_NE(r.error.find("stuck"), std::string::npos) << r.error;
      }
    }
  }
}

// Emelyanova & Fufaev (1978), example 1: the sleigh on an incline. Blade across the slope (φ = 0, π) with
// the centre of mass straight up or down the slope from the blade: an
// equilibrium held by the blade alone, λ = ±m g sin α (m: the mass moving in y).
TEST(SolverRedundancy, LateralSleighEquilibriumAtSingularPartition) {
  const double m = 3.0, l = 0.4, alpha = 0.3, mc = 0.05;
  const Model model = test::sleighModel(m, 0.2, l, alpha, mc);
  ConstraintList c{test::knifeEdge(2)};
  Data data(model);
  ConstraintData cd(model, c);
  // The x carriage only slides along x: its weight (along y) rests on the rail.
  const double weight = (m + mc) * 9.81 * std::sin(alpha);
  for (double phi : {0.0, std::numbers::pi}) {
    const VecX q = Eigen::Vector3d(0.2, -0.1, phi), v = VecX::Zero(3), tau = VecX::Zero(3);
    evaluateConstraints(model, data, c, cd, 0, q, v);
    // The blade row at φ = 0 has no ẋ component: ẋ cannot be a dependent velocity.
    EXPECT_NEAR(cd.A(0, 0), 0.0, 1e-15);
    for (auto& s : allSolvers(model, c)) {
      ConstrainedResult r;
      s->solve(model, data, c, cd, q, v, tau, r);
      ASSERT_TRUE(r.ok) << r.error;
      EXPECT_LT(r.vdot.norm(), 1e-12);
      EXPECT_NEAR(std::abs(r.lambda[0]), weight, 1e-12 * weight);
      // The reaction holds the weight along y: Aᵀλ = −gravity force.
      EXPECT_NEAR(r.reaction[1], -weight, 1e-12 * weight);
    }
  }
}

// Sweep φ from π/2 to 0 and beyond: the partition chosen at φ = π/2 makes ẋ
// dependent (|sin φ| is the largest coefficient); approaching φ = 0 its
// conditioning 1/|sin φ| passes the limit and the solver re-chooses ẏ,
// says so, and agrees with the KKT solver everywhere, at φ = 0 included.
TEST(SolverRedundancy, CoordinatePartitionReChoosesNearSingularity) {
  const Model model = test::sleighModel(2.0, 0.15, 0.3, 0.2, 0.1);
  ConstraintList c{test::knifeEdge(2)};
  Data data(model);
  ConstraintData cd(model, c);
  KktSolver kkt(model, c);
  AppellSolver orth(model, c);
  AppellSolver part(model, c, {}, {NullSpace::CoordinatePartition, 50.0});
  std::mt19937 rng(5);
  int changes_seen = 0;
  double worst = 0;
  for (int k = 0; k <= 400; ++k) {
    const double phi = std::numbers::pi / 2 * (1 - k / 400.0) - (k == 400 ? 0.0 : 0.0);
    VecX q = Eigen::Vector3d(0.1, 0.2, phi);
    VecX v = test::randomVector(3, rng);
    v[0] = v[1] * std::cos(phi) / (std::abs(std::sin(phi)) > 1e-3 ? std::sin(phi) : 1.0);
    const VecX tau = test::randomVector(3, rng);
    evaluateConstraints(model, data, c, cd, 0, q, v);
    ConstrainedResult rk, ro, rp;
    kkt.solve(model, data, c, cd, q, v, tau, rk);
    orth.solve(model, data, c, cd, q, v, tau, ro);
    part.solve(model, data, c, cd, q, v, tau, rp);
    ASSERT_TRUE(rk.ok && ro.ok && rp.ok) << rk.error << ro.error << rp.error;
    const double scale = 1 + rk.vdot.norm();
    worst = std::max(worst, (rp.vdot - rk.vdot).norm() / scale);
    EXPECT_LT((ro.vdot - rk.vdot).norm(), 1e-11 * scale) << "phi " << phi;
    EXPECT_LT((rp.vdot - rk.vdot).norm(), 1e-11 * scale) << "phi " << phi;
    EXPECT_LT(std::abs(rp.lambda[0] - rk.lambda[0]), 1e-11 * (1 + std::abs(rk.lambda[0])));
    EXPECT_LE(part.partitionCondition(), 50.0);
    if (k == 0) {
      ASSERT_EQ(part.dependentVelocities(), std::vector<int>{0});  // ẋ at φ = π/2
    }
    if (part.partitionChangedLastSolve()) {
      ++changes_seen;
      // 1/|sin φ| crossed 50: the re-choice happens near φ = asin(1/50).
      EXPECT_NEAR(std::abs(std::sin(phi)), 1.0 / 50, 0.01);
    }
  }
  EXPECT_EQ(changes_seen, 1);
  EXPECT_EQ(part.partitionChanges(), 1);
  EXPECT_EQ(part.dependentVelocities(), std::vector<int>{1});  // ẏ at φ = 0
  const std::string msg = part.partitionMessage();
  EXPECT_NE(msg.find("{0} -> {1}"), std::string::npos) << msg;
  std::printf("partition vs KKT worst rel vdot %.2e; %s\n", worst, msg.c_str());
}

}  // namespace
}  // namespace appell
