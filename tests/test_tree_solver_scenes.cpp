// The tree solver on the scaling scenes (tests/fixtures): N-trailer, wheeled
// snake, fleet, cars in a row — real knife-edge, rolling and sliding rows from
// the contacts module, with their redundancy. After projecting v onto the
// constraints (so redundant acceleration rows are consistent), v̇ and Aᵀλ
// and the minimum-norm λ agree with the long-double Udwadia–Kalaba reference
// and the dense KKT solver to 1e-10, the rank agrees, and the projection
// itself agrees with the dense one.
#include "dense_reference.hpp"
#include "tree_solver_common.hpp"

#include "car_row.hpp"
#include "fleet.hpp"
#include "ntrailer.hpp"
#include "wheeled_snake.hpp"

#include <gtest/gtest.h>

using namespace appell;
using namespace appell::test;

namespace {

void checkScene(scenes::ScalingScene s) {
  SCOPED_TRACE(s.name + " with " + std::to_string(s.model.nbodies) + " bodies");
  Data data(s.model);
  ConstraintData cd(s.model, s.constraints);
  TreeSolver solver(s.model, s.constraints);
  evaluateConstraints(s.model, data, s.constraints, cd, 0.0, s.q, s.v);
  const VecX vp = denseProjection(s.model, cd, s.q, s.v);
  VecX v = s.v, mu;
  ASSERT_TRUE(solver.projectVelocity(s.model, data, s.constraints, cd, s.q, v, mu))
      << solver.lastError();
  EXPECT_LT(relErr(v, vp), 1e-10);
  evaluateConstraints(s.model, data, s.constraints, cd, 0.0, s.q, v);
  EXPECT_LT(velocityResidual(data, s.constraints, cd, v), 1e-10);
  std::mt19937 rng(41);
  const VecX tau = randomVector(s.model.nv, rng, 5.0);
  const Reference ref = denseReference(s.model, cd, s.q, v, tau);
  ConstrainedResult out;
  solver.solve(s.model, data, s.constraints, cd, s.q, v, tau, out);
  ASSERT_TRUE(out.ok) << out.error;
  EXPECT_LT(relErr(out.vdot, ref.vdot), 1e-10);
  EXPECT_LT(relErr(out.reaction, ref.reaction), 1e-10);
  EXPECT_LT(relErr(cd.A.transpose() * out.lambda, ref.reaction), 1e-10);
  EXPECT_EQ(out.rank, ref.rank);
  // The minimum-norm λ, also where rows are redundant (the car's wheels),
  // and the dense KKT solver's: the reactions do not depend on the formulation.
  EXPECT_LT(relErr(out.lambda, ref.lambda), 1e-10);
  KktSolver kkt(s.model, s.constraints);
  ConstrainedResult ko;
  kkt.solve(s.model, data, s.constraints, cd, s.q, v, tau, ko);
  ASSERT_TRUE(ko.ok) << ko.error;
  EXPECT_LT(relErr(out.lambda, ko.lambda), 1e-10);
  EXPECT_EQ(out.redundant, ko.redundant);
  // An integrator stage asks for v̇ alone: the same v̇ to the bit and the same
  // rank, without the minimum-norm sweep.
  ConstrainedResult stage;
  solver.solve(s.model, data, s.constraints, cd, s.q, v, tau, stage, SolveOutputs::Accelerations);
  ASSERT_TRUE(stage.ok) << stage.error;
  EXPECT_EQ(stage.vdot, out.vdot);
  EXPECT_EQ(stage.rank, out.rank);
  EXPECT_EQ(stage.redundant, out.redundant);
}

}  // namespace

TEST(TreeSolverScenes, NTrailer) {
  for (int n : {1, 2, 5, 12}) checkScene(scenes::nTrailer(n));
}
TEST(TreeSolverScenes, WheeledSnake) {
  for (int n : {1, 3, 6}) checkScene(scenes::wheeledSnake(n));
}
TEST(TreeSolverScenes, Fleet) {
  for (int n : {1, 4}) checkScene(scenes::fleet(n));
}
TEST(TreeSolverScenes, CarRowHasRedundantRows) {
  for (int n : {1, 3}) {
    checkScene(scenes::carRow(n));
    const auto s = scenes::carRow(n);
    ConstraintData cd(s.model, s.constraints);
    Data data(s.model);
    evaluateConstraints(s.model, data, s.constraints, cd, 0.0, s.q, s.v);
    TreeSolver solver(s.model, s.constraints);
    ConstrainedResult out;
    VecX v = s.v, mu;
    ASSERT_TRUE(solver.projectVelocity(s.model, data, s.constraints, cd, s.q, v, mu));
    evaluateConstraints(s.model, data, s.constraints, cd, 0.0, s.q, v);
    solver.solve(s.model, data, s.constraints, cd, s.q, v, VecX::Zero(s.model.nv), out);
    EXPECT_GT(out.redundant, 0);
  }
}
