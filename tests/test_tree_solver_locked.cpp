// Joint-space rows on one one-DoF joint's velocity (joint limits) inside the
// tree solver's passes (tree_solver/locked.cpp): a closed row locks its joint.
// Against the dense Udwadia–Kalaba reference (tree_solver_common.hpp):
// v̇, Aᵀλ and the minimum-norm λ on random trees with such rows next to
// random body rows — duplicated, immobile and barely movable (compliant)
// ones, two rows on one joint, rows redundant with a body row — and the
// M-metric velocity projection; the rows are never loop rows, so a limit on
// every joint costs O(1) each; disagreeing rows on one joint are named.
#include "dense_reference.hpp"
#include "tree_solver_common.hpp"

#include <appell/joint_coupling.hpp>
#include <appell/joint_limit.hpp>

#include <gtest/gtest.h>

using namespace appell;
using namespace appell::test;

namespace {

/// Adds, on about half of the one-DoF joints, one row c q̇ (sometimes two:
/// the second redundant with the first) as its own constraint.
int addJointLocks(System& s, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0, 1), c(0.3, 3);
  int added = 0;
  for (int i = 0; i < s.model.nbodies; ++i) {
    const Joint& j = s.model.joints[i];
    if (j.nv != 1 || u(rng) < 0.5) continue;
    const int rows = u(rng) < 0.25 ? 2 : 1;
    for (int r = 0; r < rows; ++r) {
      MatX A(1, 1);
      const double sign = u(rng) < 0.5 ? -1 : 1;  // drawn first, then the size
      A(0, 0) = sign * c(rng);
      s.joint.push_back(std::make_shared<JointRows>(
          "lock" + std::to_string(r) + "@" + std::to_string(i), A, std::vector<int>{j.idx_v}));
      ++added;
    }
  }
  return added;
}

struct Compared {
  double vdot = 0, reaction = 0, lambda = 0, projection = 0, projected_residual = 0;
  double kkt_vdot = 0, kkt_lambda = 0;
  int rank = 0, ref_rank = 0, loops = 0;
};

Compared compare(const System& s) {
  const ConstraintList list = s.list();
  Data data(s.model);
  ConstraintData cd(s.model, list);
  evaluateConstraints(s.model, data, list, cd, 0.0, s.q, s.v);
  const Reference ref = denseReference(s.model, cd, s.q, s.v, s.tau);
  TreeSolver solver(s.model, list);
  ConstrainedResult out;
  solver.solve(s.model, data, list, cd, s.q, s.v, s.tau, out);
  EXPECT_TRUE(out.ok) << out.error;
  Compared c;
  c.loops = solver.loopRows();
  c.vdot = relErr(out.vdot, ref.vdot);
  c.reaction = std::max(relErr(out.reaction, ref.reaction),
                        relErr(cd.A.transpose() * out.lambda, ref.reaction));
  c.lambda = relErr(out.lambda, ref.lambda);
  c.rank = out.rank;
  c.ref_rank = ref.rank;
  ConstrainedResult kkt;
  makeSolver(Formulation::Multipliers, s.model, list)
      ->solve(s.model, data, list, cd, s.q, s.v, s.tau, kkt);
  c.kkt_vdot = relErr(kkt.vdot, ref.vdot);
  c.kkt_lambda = relErr(kkt.lambda, ref.lambda);
  VecX v = s.v, impulse;
  EXPECT_TRUE(solver.projectVelocity(s.model, data, list, cd, s.q, v, impulse))
      << solver.lastError();
  c.projection = relErr(v, denseProjection(s.model, cd, s.q, s.v));
  c.projected_residual = (cd.A * v + cd.b).lpNorm<Eigen::Infinity>() / std::max(1.0, cd.b.norm());
  return c;
}

}  // namespace

// Protects: a closed joint row fixes q̈ and its force is read off the joint's
// force balance — the same v̇, Aᵀλ and minimum-norm λ as the dense
// reference, with every other kind of row around it, and never a loop row.
TEST(LockedJoints, MatchDenseReferenceOnRandomTrees) {
  std::mt19937 rng(41);
  int cases = 0, locks = 0, redundant = 0;
  for (const RowRecipe& recipe : {RowRecipe{}, RowRecipe{0.35, 0.35, 3}}) {
    for (int n : {1, 2, 3, 5, 8, 13, 21, 40}) {
      for (bool floating : {false, true}) {
        for (int rep = 0; rep < 5; ++rep) {
          System s = randomState(n, floating, rng, 1.5, 2.0);
          addRandomRows(s, rng, recipe);
          locks += addJointLocks(s, rng);
          makeConsistent(s, rng);
          const Compared c = compare(s);
          ++cases;
          redundant += c.ref_rank < static_cast<int>(s.list().size()) ? 1 : 0;
          const std::string at = "n=" + std::to_string(n) + " floating=" +
                                 std::to_string(floating) + " rep=" + std::to_string(rep);
          EXPECT_EQ(c.loops, 0) << at;
          EXPECT_LT(c.vdot, 1e-10) << at;
          EXPECT_LT(c.reaction, 1e-10) << at;
          EXPECT_EQ(c.rank, c.ref_rank) << at;
          EXPECT_LT(c.lambda, std::max(1e-9, 2 * c.kkt_lambda)) << at << " kkt " << c.kkt_lambda;
          // The reference projection is formed in double (M^{-½}, a pseudo-
          // inverse): 1e-9 against it, and the exact property A v⁺ + b = 0.
          EXPECT_LT(c.projection, 1e-9) << at;
          EXPECT_LT(c.projected_residual, 1e-10) << at;
        }
      }
    }
  }
  EXPECT_GT(locks, 100);
  EXPECT_GT(redundant, 10);
  EXPECT_EQ(cases, 160);
}

// Protects: a locked joint under rows handed up with compliance (a child
// joint that barely moves its rows) — the locked node takes the compliant
// split with no joint of its own.
TEST(LockedJoints, UnderCompliantRows) {
  std::mt19937 rng(43);
  for (double sigma : {3e-2, 1e-3}) {
    for (int n : {4, 9, 20}) {
      for (bool floating : {false, true}) {
        for (int rep = 0; rep < 3; ++rep) {
          System s = randomState(n, floating, rng, 1.5, 2.0);
          addRandomRows(s, rng, RowRecipe{0.2, 0.2, 1});
          addWeakRows(s, 3, sigma, rng);
          addJointLocks(s, rng);
          makeConsistent(s, rng);
          const Compared c = compare(s);
          const std::string at = "sigma=" + std::to_string(sigma) + " n=" + std::to_string(n) +
                                 " rep=" + std::to_string(rep);
          EXPECT_LT(c.vdot, std::max(1e-10, 2 * c.kkt_vdot)) << at;
          EXPECT_LT(c.reaction, std::max(1e-10, 2 * c.kkt_vdot)) << at;
          EXPECT_EQ(c.rank, c.ref_rank) << at;
          EXPECT_LT(c.lambda, std::max(1e-9, 2 * c.kkt_lambda)) << at;
        }
      }
    }
  }
}

// Protects: the minimum-norm split between a limit and a body row that fix
// the same motion. A pendulum at its limit with a point row along its swing:
// both rows only fix θ̈, so Aᵀλ = a λ_body + λ_limit is all that is
// determined, and the minimum-norm λ is (a, 1) Aᵀλ / (a² + 1).
TEST(LockedJoints, LimitRedundantWithABodyRowSplitsByMinimumNorm) {
  ModelBuilder b;
  b.addBody("bob", -1, SE3::Identity(), JointType::Revolute, Vec3::UnitY(),
            Inertia{2.0, Vec3(0, 0, -0.5), Vec3::Constant(0.01).asDiagonal()}, "hinge");
  Model model = b.build();
  model.joints[0].limits.lower = 0.0;
  System s;
  s.model = model;
  s.q = VecX::Zero(1);
  s.v = VecX::Zero(1);
  s.tau = VecX::Constant(1, 3.0);
  // Velocity of the body point (0, 0, −0.5) along x: ẋ = −0.5 θ̇ (ω about y).
  Rows K(1, 6);
  K.row(0) << 0, -0.5, 0, 1, 0, 0;  // w = [p × t; t], p = (0, 0, −0.5), t = x
  s.local.push_back(std::make_shared<LocalRows>("swing", 0, K));
  s.joint.push_back(std::make_shared<JointRows>("limit", MatX::Ones(1, 1), std::vector<int>{0}));
  std::mt19937 rng(5);
  makeConsistent(s, rng);
  const ConstraintList list = s.list();
  Data data(s.model);
  ConstraintData cd(s.model, list);
  evaluateConstraints(s.model, data, list, cd, 0.0, s.q, s.v);
  const double a = cd.A(0, 0);
  ASSERT_NEAR(std::abs(a), 0.5, 1e-15);
  TreeSolver solver(s.model, list);
  ConstrainedResult out;
  solver.solve(s.model, data, list, cd, s.q, s.v, s.tau, out);
  ASSERT_TRUE(out.ok) << out.error;
  EXPECT_EQ(out.rank, 1);
  EXPECT_EQ(out.redundant, 1);
  // The joint's balance: I θ̈ = τ + mg·(lever) + Aᵀλ; the reference's Aᵀλ.
  const Reference ref = denseReference(s.model, cd, s.q, s.v, s.tau);
  const double f = ref.reaction[0];
  EXPECT_NEAR(out.reaction[0], f, 1e-12 * std::max(1.0, std::abs(f)));
  EXPECT_NEAR(out.lambda[0], a * f / (a * a + 1), 1e-12);
  EXPECT_NEAR(out.lambda[1], f / (a * a + 1), 1e-12);
}

// Protects: limits and couplings are classified by their columns — a limit
// (one velocity of a one-DoF joint) is taken by its joint's node, a mimic
// coupling (two joints) stays a loop row; so a chain with a limit on every
// joint has no loop rows and no k × n workspace.
TEST(LockedJoints, LimitsAreNotLoopRowsCouplingsAre) {
  ModelBuilder b;
  int parent = -1;
  for (int i = 0; i < 6; ++i)
    parent = b.addBody("l" + std::to_string(i), parent, SE3{Mat3::Identity(), Vec3(0, 0, -0.2)},
                       JointType::Revolute, Vec3::UnitY(),
                       Inertia{1.0, Vec3(0, 0, -0.1), Vec3::Constant(0.01).asDiagonal()},
                       "j" + std::to_string(i));
  Model model = b.build();
  ConstraintList list;
  for (int i = 0; i < 6; ++i) {
    model.joints[i].limits.lower = -0.5;
    model.joints[i].limits.upper = 0.5;
  }
  for (int i = 0; i < 6; ++i)
    for (LimitSide side : {LimitSide::Lower, LimitSide::Upper})
      list.push_back(std::make_shared<JointLimit>(model, i, side));
  EXPECT_EQ(TreeSolver(model, list).loopRows(), 0);
  list.push_back(std::make_shared<JointCoupling>(model, 5, 4, 1.0, 0.0));
  EXPECT_EQ(TreeSolver(model, list).loopRows(), 1);
}

// Protects: two closed rows on one joint that ask for different q̈ are an
// error naming both — not a least-squares compromise.
TEST(LockedJoints, DisagreeingRowsOnOneJointAreNamed) {
  ModelBuilder b;
  b.addBody("bob", -1, SE3::Identity(), JointType::Revolute, Vec3::UnitY(),
            Inertia{1.0, Vec3(0, 0, -0.5), Vec3::Constant(0.01).asDiagonal()}, "hinge");
  System s;
  s.model = b.build();
  s.q = VecX::Zero(1);
  s.v = VecX::Zero(1);
  s.tau = VecX::Zero(1);
  s.joint.push_back(std::make_shared<JointRows>("first", MatX::Ones(1, 1), std::vector<int>{0}));
  s.joint.push_back(std::make_shared<JointRows>("second", MatX::Ones(1, 1), std::vector<int>{0}));
  s.joint[0]->abias()[0] = 1.0;  // q̈ = −1
  s.joint[1]->abias()[0] = -1.0;  // q̈ = +1
  const ConstrainedResult out = treeSolve(s);
  EXPECT_FALSE(out.ok);
  EXPECT_NE(out.error.find("'first'"), std::string::npos) << out.error;
  EXPECT_NE(out.error.find("'second'"), std::string::npos) << out.error;
  s.joint[1]->abias()[0] = 1.0;  // the same q̈: redundant, not inconsistent
  const ConstrainedResult ok = treeSolve(s);
  ASSERT_TRUE(ok.ok) << ok.error;
  EXPECT_NEAR(ok.vdot[0], -1.0, 1e-15);
  EXPECT_NEAR(ok.lambda[0], ok.lambda[1], 1e-15);  // the minimum-norm split of one force
}
