// The tree solver against the dense KKT solver (kkt.hpp), the project's
// multiplier reference: same v̇, Aᵀλ, rank and redundancy count, the same
// minimum-norm λ (also when rows on different bodies are jointly redundant)
// and impulse, and the same verdict on inconsistent rows.
#include "tree_solver_common.hpp"

#include <gtest/gtest.h>

using namespace appell;
using namespace appell::test;

namespace {

/// The dense KKT and the tree solver on the rows of s, evaluated at its state.
struct BothSolvers {
  explicit BothSolvers(const System& s)
      : list(s.list()), data(s.model), cd(s.model, list), kkt(s.model, list), tree(s.model, list) {
    evaluateConstraints(s.model, data, list, cd, 0.0, s.q, s.v);
  }
  ConstraintList list;
  Data data;
  ConstraintData cd;
  KktSolver kkt;
  TreeSolver tree;
};

/// Both solvers' accelerations and reactions.
void solveBoth(const System& s, ConstrainedResult& ko, ConstrainedResult& to) {
  BothSolvers b(s);
  b.kkt.solve(s.model, b.data, b.list, b.cd, s.q, s.v, s.tau, ko);
  b.tree.solve(s.model, b.data, b.list, b.cd, s.q, s.v, s.tau, to);
}

/// Both solvers' velocity projections of s's state: projected v and impulse μ.
void projectBoth(const System& s, VecX& vk, VecX& mk, VecX& vt, VecX& mt) {
  BothSolvers b(s);
  vk = vt = s.v;
  ASSERT_TRUE(b.kkt.projectVelocity(s.model, b.data, b.list, b.cd, s.q, vk, mk)) << b.kkt.lastError();
  ASSERT_TRUE(b.tree.projectVelocity(s.model, b.data, b.list, b.cd, s.q, vt, mt))
      << b.tree.lastError();
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
      EXPECT_LT(relErr(to.lambda, ko.lambda), 1e-10) << "n=" << n;
    }
  }
}

namespace {

/// One world row copied (scaled) onto a body and two of its children whose
/// joints cannot move it: the children hand it up and the parent's
/// compression drops the copies, so the redundancy spans three bodies (as a
/// car's wheels do against the chassis).
void addCrossBodyCopies(System& s, std::mt19937& rng) {
  std::uniform_real_distribution<double> sc(0.2, 3);
  Data data(s.model);
  forwardKinematics(s.model, data, s.q, s.v);
  for (int p = 0; p < s.model.nbodies; ++p) {
    const auto& ch = s.model.children[p];
    std::vector<int> bodies{p};
    MatX Sw(6, 0);  // the children's motion subspaces, world frame
    for (int c : ch) {
      const Mat6X& S = s.model.joints[c].S;
      if (Sw.cols() + S.cols() >= 6 || bodies.size() == 3) break;
      MatX next(6, Sw.cols() + S.cols());
      next << Sw, data.oMi[c].toMotionMatrix() * S;
      Sw = next;
      bodies.push_back(c);
    }
    if (bodies.size() < 2) continue;
    Vec6 w = randomRow(rng);  // world covector with w·(S_c q̇_c) = 0
    w -= Sw * (Sw.transpose() * Sw).ldlt().solve(Sw.transpose() * w);
    for (int b : bodies) {
      Rows K(1, 6);
      K.row(0) = (sc(rng) * data.oMi[b].actInvForce(w)).transpose();
      s.local.push_back(
          std::make_shared<LocalRows>("copy@" + std::to_string(b), b, K));
    }
  }
}

}  // namespace

TEST(TreeSolver, MinimumNormLambdaWhenRedundancySpansBodies) {
  // The tree solver drops redundant rows compression by compression; its λ
  // must still be the global minimum-norm one, the dense solvers' λ.
  std::mt19937 rng(29);
  int cases = 0;
  for (int n : {4, 9, 20, 40}) {
    for (bool floating : {false, true}) {
      for (int variant = 0; variant < 3; ++variant) {
        System s = randomSystem(n, floating, rng, RowRecipe{0.1, 0.2, 1});
        addCrossBodyCopies(s, rng);
        if (variant == 1) addWeakRows(s, 3, 1e-3, rng);  // rows handed up with compliance
        if (variant == 2) {                              // a loop row and a joint-space copy
          std::uniform_int_distribution<int> body(0, n - 1);
          Rows Ka(1, 6), Kb(1, 6);
          Ka.row(0) = randomRow(rng).transpose();
          Kb.row(0) = randomRow(rng).transpose();
          // Body b drawn before body a: g++'s order when both were arguments.
          const int body_b = body(rng);
          const int body_a = body(rng);
          s.local.push_back(std::make_shared<LocalRows>("loop", body_a, Ka, body_b, Kb));
          addJointCopyOfLastRow(s, "joint_copy", 2.0);
        }
        makeConsistent(s, rng);
        ConstrainedResult ko, to;
        solveBoth(s, ko, to);
        ASSERT_TRUE(ko.ok) << ko.error;
        ASSERT_TRUE(to.ok) << to.error;
        SCOPED_TRACE("n=" + std::to_string(n) + " floating=" + std::to_string(floating) +
                     " variant=" + std::to_string(variant));
        EXPECT_GT(to.redundant, 0);
        EXPECT_EQ(to.redundant, ko.redundant);
        EXPECT_LT(relErr(to.vdot, ko.vdot), 1e-10);
        EXPECT_LT(relErr(to.reaction, ko.reaction), 1e-10);
        EXPECT_LT(relErr(to.lambda, ko.lambda), 1e-10);

        // The impulse of the velocity projection: the same minimum-norm μ.
        VecX vk, vt, mk, mt;
        projectBoth(s, vk, mk, vt, mt);
        EXPECT_LT(relErr(vt, vk), 1e-10);
        EXPECT_LT(relErr(mt, mk), 1e-10);
        ++cases;
      }
    }
  }
  EXPECT_EQ(cases, 24);
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
