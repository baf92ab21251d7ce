// The tree solver against the dense KKT solver (kkt.hpp), the project's
// multiplier reference: same v̇, Aᵀλ, rank and redundancy count, same λ when
// A has full row rank, and the same verdict on inconsistent rows.
#include "test_tree_solver_common.hpp"

#include <gtest/gtest.h>

using namespace appell;
using namespace appell::test;

namespace {

/// Both solvers on the rows of s at its state.
void solveBoth(const System& s, ConstrainedResult& ko, ConstrainedResult& to) {
  const ConstraintList list = s.list();
  Data data(s.model);
  ConstraintData cd(s.model, list);
  evaluateConstraints(s.model, data, list, cd, 0.0, s.q, s.v);
  KktSolver kkt(s.model, list);
  TreeSolver tree(s.model, list);
  kkt.solve(s.model, data, list, cd, s.q, s.v, s.tau, ko);
  tree.solve(s.model, data, list, cd, s.q, s.v, s.tau, to);
}

}  // namespace

TEST(TreeSolver, AgreesWithDenseKkt) {
  std::mt19937 rng(17);
  for (int n : {3, 10, 25}) {
    for (bool floating : {false, true}) {
      const System s = randomSystem(n, floating, rng, RowRecipe{0.2, 0.2, 2});
      ConstrainedResult ko, to;
      solveBoth(s, ko, to);
      ASSERT_TRUE(ko.ok) << ko.error;
      ASSERT_TRUE(to.ok) << to.error;
      EXPECT_LT(relErr(to.vdot, ko.vdot), 1e-10) << "n=" << n;
      EXPECT_LT(relErr(to.reaction, ko.reaction), 1e-10) << "n=" << n;
      EXPECT_EQ(to.rank, ko.rank);
      EXPECT_EQ(to.redundant, ko.redundant);
      if (ko.redundant == 0) {
        EXPECT_LT(relErr(to.lambda, ko.lambda), 1e-8);
      }
    }
  }
}

TEST(TreeSolver, KktAgreesOnInconsistency) {
  std::mt19937 rng(19);
  System s = randomState(12, true, rng);
  Rows K1(2, 6), K2(1, 6);
  K1.row(0) = randomRow(rng).transpose();
  K1.row(1) = randomRow(rng).transpose();
  K2.row(0) = -2.5 * K1.row(1);
  s.local.push_back(std::make_shared<LocalRows>("first", 7, K1));
  s.local.push_back(std::make_shared<LocalRows>("second", 7, K2));
  makeConsistent(s, rng);
  s.local[1]->kappa()[0] += 1e-3;
  ConstrainedResult ko, to;
  solveBoth(s, ko, to);
  EXPECT_FALSE(ko.ok);
  EXPECT_FALSE(to.ok);
}
