// No heap allocation inside TreeSolver::solve() and projectVelocity() once the
// result vectors have their sizes: every allocation of this executable is
// counted (operator new and malloc & co., which Eigen uses), and the count
// over repeated solves must be zero — on random trees with redundant rows,
// with loop rows (also redundant ones), and with rows handed up with their
// compliance — the minimum-norm step included, with the factor formed anew
// and reused.
#include "tree_solver_common.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <new>

#include "alloc_counter.hpp"

using namespace appell;
using namespace appell::test;

namespace {

void expectNoAllocation(System& s) {
  const ConstraintList list = s.list();
  Data data(s.model);
  ConstraintData cd(s.model, list);
  evaluateConstraints(s.model, data, list, cd, 0.0, s.q, s.v);
  TreeSolver solver(s.model, list);
  ConstrainedResult out;
  VecX v, mu(cd.m);
  // Each call forms the factor anew (allocationsIn repeats the call), then
  // each call reuses it (same configuration and rows).
  for (bool fresh : {true, false}) {
    EXPECT_EQ(allocationsIn([&] {
                if (fresh) solver.forgetFactor();
                solver.solve(s.model, data, list, cd, s.q, s.v, s.tau, out);
              }),
              0)
        << (fresh ? "fresh" : "reused");
    EXPECT_TRUE(out.ok) << out.error;
    EXPECT_EQ(solver.lastFactorReused(), !fresh && !solver.lastSolveClosedForm());
    EXPECT_EQ(allocationsIn([&] {
                if (fresh) solver.forgetFactor();
                v = s.v;  // same size: no allocation
                solver.projectVelocity(s.model, data, list, cd, s.q, v, mu);
              }),
              0)
        << (fresh ? "fresh" : "reused");
    EXPECT_EQ(solver.lastFactorReused(), !fresh && !solver.lastSolveClosedForm());
  }
}

}  // namespace

TEST(TreeSolverAllocations, CounterSeesAllocations) {
  EXPECT_GT(allocationsIn([] { VecX x(100); x.setZero(); }), 0);
}

TEST(TreeSolverAllocations, NoneOnRandomTrees) {
  std::mt19937 rng(31);
  for (bool floating : {false, true}) {
    System s = randomSystem(30, floating, rng, RowRecipe{0.3, 0.3, 3});
    expectNoAllocation(s);
  }
}

TEST(TreeSolverAllocations, NoneWithRowsHandedUpWithCompliance) {
  // Rows the bodies' own joints barely move (tree_solver/soft.cpp), some on a
  // free body that already has six rows (compliant dropped combinations).
  std::mt19937 rng(33);
  for (bool floating : {false, true}) {
    System s = randomSystem(20, floating, rng, RowRecipe{0.3, 0.3, 2});
    addWeakRows(s, 4, 1e-3, rng);
    makeConsistent(s, rng);
    expectNoAllocation(s);
  }
}

namespace {

/// k random rows between bodies 5 and 9: a loop the tree passes cannot close.
void addLoopRows(System& s, int k) {
  Rows Ka(k, 6), Kb(k, 6);
  Ka.setRandom();
  Kb.setRandom();
  s.local.push_back(std::make_shared<LocalRows>("loop", 5, Ka, 9, Kb));
}

}  // namespace

TEST(TreeSolverAllocations, NoneWithLoopRows) {
  std::mt19937 rng(32);
  System s = randomSystem(12, true, rng, RowRecipe{0.2, 0.2, 1});
  addLoopRows(s, 2);
  s.joint.push_back(std::make_shared<JointRows>("joint", MatX::Random(1, s.model.nv)));
  makeConsistent(s, rng);
  expectNoAllocation(s);
}

TEST(TreeSolverAllocations, NoneWithRedundantLoopRows) {
  // The minimum-norm step (tree_solver/min_norm.cpp) with both kinds of
  // redundant directions: tree rows dropped at compressions and a loop row
  // that copies a tree row (the loop closure's null direction).
  std::mt19937 rng(34);
  System s = randomSystem(12, true, rng, RowRecipe{0.3, 0.3, 2});
  addLoopRows(s, 1);
  addJointCopyOfLastRow(s, "copy", 2.0);
  makeConsistent(s, rng);
  const ConstrainedResult out = treeSolve(s);
  ASSERT_TRUE(out.ok) << out.error;
  EXPECT_GT(out.redundant, 1);
  expectNoAllocation(s);
}

TEST(TreeSolverAllocations, NoneWithLockedJoints) {
  // Closed rows on one-DoF joints' velocities (tree_solver/locked.cpp): one
  // or two per joint, next to duplicated and compliant body rows, so the
  // locked split, the compliant split with no joint and the minimum-norm
  // row of a locked joint all run.
  std::mt19937 rng(35);
  for (bool floating : {false, true}) {
    System s = randomSystem(20, floating, rng, RowRecipe{0.3, 0.3, 2});
    addWeakRows(s, 3, 1e-3, rng);
    for (int i = 0; i < s.model.nbodies; ++i) {
      if (s.model.joints[i].nv != 1) continue;
      for (int r = 0; r < 1 + i % 2; ++r)
        s.joint.push_back(std::make_shared<JointRows>(
            "lock" + std::to_string(r) + "@" + std::to_string(i), MatX::Constant(1, 1, 1.0 + r),
            std::vector<int>{s.model.joints[i].idx_v}));
    }
    makeConsistent(s, rng);
    const ConstrainedResult out = treeSolve(s);
    ASSERT_TRUE(out.ok) << out.error;
    EXPECT_GT(out.redundant, 0);
    expectNoAllocation(s);
  }
}
