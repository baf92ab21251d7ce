// The O(n) tree solver against the dense Udwadia–Kalaba reference
// (tree_solver_common.hpp; the dense KKT solver: test_tree_solver_kkt.cpp):
// v̇ to 1e-10 relative, Aᵀλ, and the minimum-norm λ (redundant rows or not) —
// on random trees with every joint type, fixed and
// floating base, 1–6 rows per body, duplicated and scaled rows, rows a joint
// cannot move, and singular poses; inconsistent rows give an error naming them.
#include "dense_reference.hpp"
#include "tree_solver_common.hpp"

#include <gtest/gtest.h>

using namespace appell;
using namespace appell::test;

namespace {

struct Compared {
  double vdot = 0, reaction = 0, lambda = 0, constraint = 0;
  /// The dense KKT solver's errors in double against the same long-double
  /// reference: what the problem's own conditioning costs any double solver.
  double kkt_vdot = 0, kkt_lambda = 0;
  bool full_rank = false;
  int rank = 0, ref_rank = 0;
};

Compared compare(const System& s, const SolverOptions& opt = {}) {
  const ConstraintList list = s.list();
  Data data(s.model);
  ConstraintData cd(s.model, list);
  evaluateConstraints(s.model, data, list, cd, 0.0, s.q, s.v);
  const Reference ref = denseReference(s.model, cd, s.q, s.v, s.tau);
  TreeSolver solver(s.model, list, opt);
  ConstrainedResult out;
  solver.solve(s.model, data, list, cd, s.q, s.v, s.tau, out);
  EXPECT_TRUE(out.ok) << out.error;
  Compared c;
  c.vdot = relErr(out.vdot, ref.vdot);
  c.reaction = relErr(out.reaction, ref.reaction);
  if (cd.m > 0) {
    c.reaction = std::max(c.reaction, relErr(cd.A.transpose() * out.lambda, ref.reaction));
    c.constraint = (cd.A * out.vdot + cd.abias).lpNorm<Eigen::Infinity>() /
                   std::max(1.0, cd.abias.lpNorm<Eigen::Infinity>());
  }
  c.full_rank = ref.rank == cd.m;
  c.lambda = relErr(out.lambda, ref.lambda);  // the unique minimum-norm λ, redundant rows or not
  c.rank = out.rank;
  c.ref_rank = ref.rank;
  ConstrainedResult kkt;
  makeSolver(Formulation::Multipliers, s.model, list)->solve(s.model, data, list, cd, s.q, s.v, s.tau, kkt);
  c.kkt_vdot = relErr(kkt.vdot, ref.vdot);
  c.kkt_lambda = relErr(kkt.lambda, ref.lambda);
  return c;
}

/// Every row of every local constraint scaled by 10^u, u uniform in ±4: the
/// row equilibration must undo it.
void scaleRowsByDecades(System& s, std::mt19937& rng) {
  std::uniform_real_distribution<double> decades(-4.0, 4.0);
  for (auto& c : s.local)
    for (int r = 0; r < c->rows(); ++r) c->scaleRow(r, std::pow(10.0, decades(rng)));
}

/// One system solved at (q, v) by a tree solver with default options (fast)
/// and one with `other` (slow).
struct SolvedTwice {
  ConstraintList list;
  Data data;
  ConstraintData cd;
  TreeSolver fast, slow;
  ConstrainedResult a, b;
  SolvedTwice(const System& s, const SolverOptions& other)
      : list(s.list()), data(s.model), cd(s.model, list), fast(s.model, list),
        slow(s.model, list, other) {
    evaluateConstraints(s.model, data, list, cd, 0.0, s.q, s.v);
    fast.solve(s.model, data, list, cd, s.q, s.v, s.tau, a);
    slow.solve(s.model, data, list, cd, s.q, s.v, s.tau, b);
  }
};

}  // namespace

TEST(TreeSolver, MatchesDenseReferenceOnRandomTrees) {
  std::mt19937 rng(11);
  int cases = 0, full = 0;
  for (int n : {1, 2, 3, 5, 8, 13, 21, 34, 50}) {
    for (bool floating : {false, true}) {
      for (int rep = 0; rep < 6; ++rep) {
        const System s = randomSystem(n, floating, rng, RowRecipe{});
        const Compared c = compare(s);
        ++cases;
        full += c.full_rank;
        EXPECT_LT(c.vdot, 1e-10) << "n=" << n << " floating=" << floating << " rep=" << rep;
        EXPECT_LT(c.reaction, 1e-10) << "n=" << n << " floating=" << floating;
        EXPECT_LT(c.constraint, 1e-9) << "n=" << n << " floating=" << floating;
        EXPECT_EQ(c.rank, c.ref_rank) << "n=" << n << " floating=" << floating;
        EXPECT_LT(c.lambda, 1e-10) << "n=" << n << " floating=" << floating << " rep=" << rep;
      }
    }
  }
  // The sample must exercise both regimes.
  EXPECT_GT(full, 5);
  EXPECT_LT(full, cases);
}

TEST(TreeSolver, DuplicatedScaledAndImmobileRows) {
  std::mt19937 rng(12);
  const RowRecipe recipe{0.35, 0.35, 3};
  for (int n : {1, 2, 4, 9, 20, 40}) {
    for (bool floating : {false, true}) {
      for (int rep = 0; rep < 4; ++rep) {
        const System s = randomSystem(n, floating, rng, recipe);
        const Compared c = compare(s);
        EXPECT_LT(c.vdot, 1e-10) << "n=" << n << " floating=" << floating << " rep=" << rep;
        EXPECT_LT(c.reaction, 1e-10) << "n=" << n << " floating=" << floating;
        EXPECT_EQ(c.rank, c.ref_rank) << "n=" << n << " floating=" << floating;
        EXPECT_LT(c.lambda, 1e-9) << "n=" << n << " floating=" << floating << " rep=" << rep;
      }
    }
  }
}

TEST(TreeSolver, RowsAJointBarelyMovesAreHandedUpWithCompliance) {
  // A row whose own joint moves it with a small pivot σ, while an ancestor
  // moves it well. Resolving it at the small pivot would lose ~eps/σ⁴; the
  // solver hands it up with its compliance instead, and must match the dense
  // solvers with no refinement: within 1e-10 (λ: 1e-9) of the long-double
  // reference, or within 10× the dense KKT solver's own error in double
  // where the problem's conditioning costs more than that (at σ = 10⁻⁴ some
  // draws cost the KKT solver 4·10⁻¹⁰ in v̇ and 5·10⁻⁸ in λ), and on
  // average (geometric mean over the draws) within 10× of it (measured 4×).
  // Per draw the ratio scatters: over 300 further draws at σ = 10⁻⁴ it
  // reached 10³ in a few, with the stacks' QR or without it (certified
  // stacks) alike — the compliant elimination's accuracy, not a defect of
  // either compression.
  std::mt19937 rng(17);
  int checked = 0;
  double log_ratio = 0;  // Σ log10(error / the KKT solver's error), v̇
  for (double sigma : {3e-2, 1e-3, 1e-4}) {
    for (int n : {4, 9, 20}) {
      for (bool floating : {false, true}) {
        for (int rep = 0; rep < 3; ++rep) {
          System s = randomSystem(n, floating, rng, RowRecipe{0.2, 0.2, 1});
          addWeakRows(s, 3, sigma, rng);
          makeConsistent(s, rng);
          const Compared c = compare(s);
          ++checked;
          EXPECT_LT(c.vdot, std::max(1e-10, 10 * c.kkt_vdot))
              << "sigma=" << sigma << " n=" << n << " rep=" << rep << " kkt " << c.kkt_vdot;
          EXPECT_LT(c.reaction, std::max(1e-10, 10 * c.kkt_vdot)) << "sigma=" << sigma << " n=" << n << " rep=" << rep;
          EXPECT_EQ(c.rank, c.ref_rank) << "sigma=" << sigma << " n=" << n;
          EXPECT_LT(c.lambda, std::max(1e-9, 10 * c.kkt_lambda))
              << "sigma=" << sigma << " n=" << n << " rep=" << rep << " kkt " << c.kkt_lambda;
          log_ratio += std::log10(std::max(c.vdot, 1e-16) / std::max(c.kkt_vdot, 1e-16));
        }
      }
    }
  }
  EXPECT_EQ(checked, 54);
  EXPECT_LT(log_ratio / checked, 1.0);  // measured 0.60: 4×
}

TEST(TreeSolver, CompliantRowBeyondTheParentsSixRows) {
  // A free body with six rows of its own and a child whose row its revolute
  // joint barely moves: seven rows meet at the free body, so one combination
  // has no acceleration part there and is fixed by the child's compliance
  // alone. A has full rank (7 rows, 7 DoF): v̇ and λ are unique. (All of v̇
  // hangs on the weak row: the problem's conditioning grows like 1/σ², and by
  // σ = 10⁻³ the dense KKT solver in double misses the long-double reference
  // by 6·10⁻¹¹, by 4·10⁻⁹ at 10⁻⁴.)
  std::mt19937 rng(19);
  for (double sigma : {2e-2, 5e-3}) {
    for (int rep = 0; rep < 4; ++rep) {
      ModelBuilder b;
      // One draw per statement, the last argument first (g++'s order when
      // they were one argument list): every compiler builds the same bodies.
      const Inertia free_inertia = randomInertia(rng);
      const SE3 free_placement = randomPlacement(rng);
      b.addBody("free", -1, free_placement, JointType::Floating, Vec3::UnitZ(), free_inertia);
      const Inertia leaf_inertia = randomInertia(rng);
      const Vec3 leaf_axis = randomUnit(rng);
      const SE3 leaf_placement = randomPlacement(rng);
      b.addBody("leaf", 0, leaf_placement, JointType::Revolute, leaf_axis, leaf_inertia);
      System s;
      s.model = b.build();
      s.q = randomConfiguration(s.model, rng);
      s.v = randomVector(s.model.nv, rng);
      s.tau = randomVector(s.model.nv, rng);
      Rows K6(6, 6), K1(1, 6);
      for (int r = 0; r < 6; ++r) K6.row(r) = randomRow(rng).transpose();
      K1.row(0) = weakRow(s.model, 1, sigma, rng).transpose();
      s.local.push_back(std::make_shared<LocalRows>("six", 0, K6));
      s.local.push_back(std::make_shared<LocalRows>("weak", 1, K1));
      makeConsistent(s, rng);
      const Compared c = compare(s);
      EXPECT_TRUE(c.full_rank);
      EXPECT_LT(c.vdot, 1e-10) << "sigma=" << sigma;
      EXPECT_LT(c.reaction, 1e-10) << "sigma=" << sigma;
      EXPECT_LT(c.lambda, 1e-8) << "sigma=" << sigma;
      EXPECT_EQ(c.rank, 7);
    }
  }
}

TEST(TreeSolver, FewRowsLeaveMostJointsAsPlainAba) {
  // One row on one leaf: the solver must equal ABA + one rank-one correction,
  // and with no rows at all it must equal ABA to round-off.
  std::mt19937 rng(13);
  for (bool floating : {false, true}) {
    System s = randomState(30, floating, rng);
    Data data(s.model);
    const VecX ddq = aba(s.model, data, s.q, s.v, s.tau);
    ConstraintList none;
    ConstraintData cd(s.model, none);
    evaluateConstraints(s.model, data, none, cd, 0.0, s.q, s.v);
    TreeSolver solver(s.model, none);
    ConstrainedResult out;
    solver.solve(s.model, data, none, cd, s.q, s.v, s.tau, out);
    ASSERT_TRUE(out.ok);
    EXPECT_LT(relErr(out.vdot, ddq), 1e-12);

    Rows K(1, 6);
    K.row(0) = randomRow(rng).transpose();
    s.local.push_back(std::make_shared<LocalRows>("leaf", s.model.nbodies - 1, K));
    makeConsistent(s, rng);
    const Compared c = compare(s);
    EXPECT_LT(c.vdot, 1e-10);
    EXPECT_LT(c.reaction, 1e-10);
  }
}

TEST(TreeSolver, SingularPoseOfAStretchedArm) {
  // Planar two-link arm along x at q = 0: its tip cannot accelerate along the
  // arm by joint accelerations (a singular pose). A row along x at the tip is
  // an all-zero row of A once the velocity term is accounted for: redundant
  // when consistent, an error naming it otherwise. The row along y resolves.
  ModelBuilder b;
  const Inertia rod{1.0, Vec3(0.5, 0, 0), Vec3(0.01, 0.1, 0.1).asDiagonal()};
  b.addBody("link1", -1, SE3::Identity(), JointType::Revolute, Vec3::UnitZ(), rod);
  SE3 X;
  X.p = Vec3(1, 0, 0);
  const int l2 = b.addBody("link2", 0, X, JointType::Revolute, Vec3::UnitZ(), rod);
  System s;
  s.model = b.build();
  s.q = VecX::Zero(2);
  s.v = VecX::Zero(2);
  s.tau = Eigen::Vector2d(0.3, -0.2);
  const Vec3 tip(1, 0, 0);
  Rows K(2, 6);
  K.row(0) << tip.cross(Vec3::UnitX()).transpose(), Vec3::UnitX().transpose();
  K.row(1) << tip.cross(Vec3::UnitY()).transpose(), Vec3::UnitY().transpose();
  s.local.push_back(std::make_shared<LocalRows>("tip", l2, K));
  std::mt19937 rng(14);
  makeConsistent(s, rng);
  const Compared c = compare(s);
  EXPECT_LT(c.vdot, 1e-12);
  EXPECT_LT(c.reaction, 1e-12);
  EXPECT_EQ(c.rank, 1);
  EXPECT_LT(c.lambda, 1e-12);

  // Same pose, an inconsistent right side on the immobile row.
  s.local[0]->kappa()[0] += 0.5;
  const ConstrainedResult out = treeSolve(s);
  EXPECT_FALSE(out.ok);
  EXPECT_NE(out.error.find("'tip'"), std::string::npos) << out.error;
}

TEST(TreeSolver, InconsistentDuplicateIsAnErrorNamingTheConstraints) {
  std::mt19937 rng(15);
  for (bool floating : {false, true}) {
    System s = randomState(12, floating, rng);
    // A row on body 7 and the same row, scaled, in a second constraint there;
    // an unrelated constraint on body 3.
    Rows K1(2, 6), K2(1, 6), K3(1, 6);
    K1.row(0) = randomRow(rng).transpose();
    K1.row(1) = randomRow(rng).transpose();
    K2.row(0) = -2.5 * K1.row(1);
    K3.row(0) = randomRow(rng).transpose();
    s.local.push_back(std::make_shared<LocalRows>("first", 7, K1));
    s.local.push_back(std::make_shared<LocalRows>("second", 7, K2));
    s.local.push_back(std::make_shared<LocalRows>("bystander", 3, K3));
    makeConsistent(s, rng);
    // Consistent: fine, with one redundant row at least (how many more the
    // joints between body 7 and the base leave depends on the tree drawn).
    const Compared c = compare(s);
    EXPECT_LT(c.vdot, 1e-10);
    EXPECT_EQ(c.rank, c.ref_rank);
    EXPECT_LE(c.rank, 3);
    // Now break the duplicate's right side.
    s.local[1]->kappa()[0] += 1e-3;
    const ConstrainedResult out = treeSolve(s);
    EXPECT_FALSE(out.ok);
    EXPECT_NE(out.error.find("'first'"), std::string::npos) << out.error;
    EXPECT_NE(out.error.find("'second'"), std::string::npos) << out.error;
    EXPECT_EQ(out.error.find("'bystander'"), std::string::npos) << out.error;
  }
}

TEST(TreeSolver, InconsistentRowsSpreadOverATree) {
  // Rows on a fixed-base chain: a row on the last body repeated, through the
  // chain's fixed joints, on its parent — the inconsistency is found where the
  // rows meet, and both constraints are named.
  ModelBuilder b;
  std::mt19937 rng(16);
  // One draw per statement, the last argument first (g++'s order when they
  // were one argument list): every compiler builds the same chain.
  const Inertia base_inertia = randomInertia(rng);
  const Vec3 base_axis = randomUnit(rng);
  const SE3 base_placement = randomPlacement(rng);
  b.addBody("base", -1, base_placement, JointType::Revolute, base_axis, base_inertia);
  const Inertia plate_inertia = randomInertia(rng);
  const SE3 plate_placement = randomPlacement(rng);
  b.addBody("plate", 0, plate_placement, JointType::Fixed, Vec3::UnitZ(), plate_inertia);
  const Inertia tool_inertia = randomInertia(rng);
  const SE3 tool_placement = randomPlacement(rng);
  b.addBody("tool", 1, tool_placement, JointType::Fixed, Vec3::UnitZ(), tool_inertia);
  System s;
  s.model = b.build();
  s.q = randomConfiguration(s.model, rng);
  s.v = randomVector(s.model.nv, rng);
  s.tau = randomVector(s.model.nv, rng);
  Data data(s.model);
  forwardKinematics(s.model, data, s.q);
  // The same world covector seen from "tool" and from "plate".
  const Vec6 w_world = randomRow(rng);
  Rows Kt(1, 6), Kp(1, 6);
  Kt.row(0) = data.oMi[2].actInvForce(w_world).transpose();
  Kp.row(0) = 3.0 * data.oMi[1].actInvForce(w_world).transpose();
  s.local.push_back(std::make_shared<LocalRows>("on_tool", 2, Kt));
  s.local.push_back(std::make_shared<LocalRows>("on_plate", 1, Kp));
  makeConsistent(s, rng);
  EXPECT_LT(compare(s).vdot, 1e-11);
  s.local[0]->kappa()[0] += 0.1;
  const ConstrainedResult out = treeSolve(s);
  EXPECT_FALSE(out.ok);
  EXPECT_NE(out.error.find("'on_tool'"), std::string::npos) << out.error;
  EXPECT_NE(out.error.find("'on_plate'"), std::string::npos) << out.error;
}

TEST(TreeSolver, RejectsBadConstraints) {
  std::mt19937 rng(18);
  const Model model = randomTree(4, false, rng);
  Rows K(1, 6);
  K.row(0) = randomRow(rng).transpose();
  ConstraintList out_of_range{std::make_shared<LocalRows>("far", 9, K)};
  try {
    TreeSolver s(model, out_of_range);
    FAIL() << "expected an exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'far'"), std::string::npos);
  }
  ConstraintList nobody{std::make_shared<LocalRows>("ghost", -1, K)};
  EXPECT_THROW(TreeSolver(model, nobody), std::invalid_argument);
}

TEST(TreeSolver, ProjectVelocityIsTheMassMetricProjection) {
  std::mt19937 rng(20);
  for (int n : {1, 4, 12, 30}) {
    for (bool floating : {false, true}) {
      System s = randomSystem(n, floating, rng, RowRecipe{0.3, 0.3, 2});
      const ConstraintList list = s.list();
      Data data(s.model);
      ConstraintData cd(s.model, list);
      evaluateConstraints(s.model, data, list, cd, 0.0, s.q, s.v);
      const VecX ref = denseProjection(s.model, cd, s.q, s.v);
      TreeSolver solver(s.model, list);
      VecX v = s.v, mu;
      ASSERT_TRUE(solver.projectVelocity(s.model, data, list, cd, s.q, v, mu)) << solver.lastError();
      EXPECT_LT(relErr(v, ref), 1e-10) << "n=" << n;
      if (cd.m == 0) continue;
      EXPECT_LT((cd.A * v + cd.b).lpNorm<Eigen::Infinity>(), 1e-10 * std::max(1.0, cd.b.norm()));
      // v⁺ = v − M⁻¹Aᵀμ.
      const MatX M = crba(s.model, data, s.q);
      EXPECT_LT(relErr(M * (s.v - v), cd.A.transpose() * mu), 1e-9) << "n=" << n;
    }
  }
}

TEST(TreeSolver, LoopRowsBetweenBodiesAndOverJoints) {
  std::mt19937 rng(21);
  for (int n : {3, 8, 20}) {
    for (bool floating : {false, true}) {
      for (int rep = 0; rep < 3; ++rep) {
        System s = randomSystem(n, floating, rng, RowRecipe{0.2, 0.2, 1});
        std::uniform_int_distribution<int> body(0, n - 1), nr(1, 3);
        for (int c = 0; c < 2; ++c) {
          const int m = nr(rng);
          Rows Ka(m, 6), Kb(m, 6);
          for (int r = 0; r < m; ++r) {
            Ka.row(r) = randomRow(rng).transpose();
            Kb.row(r) = randomRow(rng).transpose();
          }
          // Body b drawn before body a: g++'s order when both were arguments.
          const int body_b = body(rng);
          const int body_a = body(rng);
          s.local.push_back(
              std::make_shared<LocalRows>("loop" + std::to_string(c), body_a, Ka, body_b, Kb));
        }
        MatX Aj(2, s.model.nv);
        for (int r = 0; r < 2; ++r) Aj.row(r) = randomVector(s.model.nv, rng).transpose();
        s.joint.push_back(std::make_shared<JointRows>("joint", Aj));
        makeConsistent(s, rng);
        const Compared c = compare(s);
        EXPECT_LT(c.vdot, 1e-10) << "n=" << n << " floating=" << floating << " rep=" << rep;
        EXPECT_LT(c.reaction, 1e-10) << "n=" << n << " floating=" << floating;
        EXPECT_EQ(c.rank, c.ref_rank);
        EXPECT_LT(c.lambda, 1e-10) << "n=" << n << " floating=" << floating << " rep=" << rep;
      }
    }
  }
}

TEST(TreeSolver, NearlyParallelLoopRowsNeedNoRefinement) {
  // Loop rows that differ by δ: cond(Z) ~ 1/δ, cond(S) ~ 1/δ². Solving with
  // the Schur complement S itself lost eps/δ² (v̇ off by 3e-7 at δ = 1e-4
  // without refinement) and at δ = 1e-5 dropped a row at S's rank tolerance
  // (v̇ off by O(1), refinement or not); its square root Z loses about eps/δ,
  // with no refinement. At δ = 1e-5 the dense KKT solver in double misses the
  // long-double reference by up to 2e-10 too, hence the looser bound there
  // (5e-9: eps/δ = 2e-11 times the random system's own conditioning, which
  // GCC's and clang's roundings put between 1e-9 and 2e-9; for λ, or 20×
  // what the KKT solver misses by: one draw costs the KKT solver 1.2e-9 in
  // λ and the tree 1.2e-8). Over 200 further draws the λ errors of the
  // tree (QR or certified stacks alike) and of the KKT solver have the same
  // spread: medians 7e-11–1e-10, maxima 7e-8 at δ = 1e-5.
  std::mt19937 rng(23);
  std::normal_distribution<double> g;
  for (double delta : {1e-3, 1e-4, 1e-5}) {
    for (bool floating : {false, true}) {
      for (int rep = 0; rep < 3; ++rep) {
        System s = randomSystem(12, floating, rng, RowRecipe{0.0, 0.0, 1});
        std::uniform_int_distribution<int> body(0, s.model.nbodies - 1);
        Rows Ka(2, 6), Kb(2, 6);
        Ka.row(0) = randomRow(rng).transpose();
        Kb.row(0) = randomRow(rng).transpose();
        Ka.row(1) = Ka.row(0) + delta * Ka.row(0).norm() * randomRow(rng).normalized().transpose();
        Kb.row(1) = Kb.row(0) + delta * Kb.row(0).norm() * randomRow(rng).normalized().transpose();
        // Body b drawn before body a: g++'s order when both were arguments.
        const int body_b = body(rng);
        const int body_a = body(rng);
        s.local.push_back(std::make_shared<LocalRows>("near", body_a, Ka, body_b, Kb));
        MatX Aj(2, s.model.nv);
        for (int c = 0; c < s.model.nv; ++c) Aj(0, c) = g(rng), Aj(1, c) = g(rng);
        Aj.row(1) = Aj.row(0) + delta * Aj.row(0).norm() * Aj.row(1).normalized();
        s.joint.push_back(std::make_shared<JointRows>("near_joint", Aj));
        makeConsistent(s, rng);
        const Compared c = compare(s);
        const double tol = delta < 1e-4 ? 5e-9 : 1e-10;
        EXPECT_LT(c.vdot, tol) << "delta=" << delta << " floating=" << floating << " rep=" << rep;
        EXPECT_LT(c.reaction, tol) << "delta=" << delta << " floating=" << floating;
        EXPECT_EQ(c.rank, c.ref_rank) << "delta=" << delta;
        // cond(λ) ~ 1/δ; at δ = 1e-5 within 20× the KKT solver's own error.
        EXPECT_LT(c.lambda, delta < 1e-4 ? std::max(5e-9, 20 * c.kkt_lambda) : 1e-9)
            << "delta=" << delta << " floating=" << floating << " kkt " << c.kkt_lambda;
      }
    }
  }
}

TEST(TreeSolver, RedundantLoopRowCopiesATreeRow) {
  // A joint-space row equal to a tree row (its row of A): redundant, rank unchanged.
  std::mt19937 rng(22);
  System s = randomSystem(10, true, rng, RowRecipe{});
  Rows K(2, 6);
  K.row(0) = randomRow(rng).transpose();
  K.row(1) = randomRow(rng).transpose();
  s.local.push_back(std::make_shared<LocalRows>("tree_rows", 6, K));
  addJointCopyOfLastRow(s, "copy", 3.0);
  makeConsistent(s, rng);
  const Compared c = compare(s);
  EXPECT_LT(c.vdot, 1e-10);
  EXPECT_LT(c.reaction, 1e-10);
  EXPECT_EQ(c.rank, c.ref_rank);
  EXPECT_FALSE(c.full_rank);
  EXPECT_LT(c.lambda, 1e-10);  // the copy and the tree rows share the force at minimum norm
}

TEST(TreeSolver, InconsistentLoopRowsAreAnErrorNamingThem) {
  std::mt19937 rng(24);
  auto solveOk = [](const System& s, std::string& error) {
    const ConstrainedResult out = treeSolve(s);
    error = out.error;
    return out.ok;
  };
  std::string error;
  {
    // A joint-space row the tree rows make immobile (a copy of one of them)
    // with a right side of its own.
    System s = randomSystem(10, true, rng, RowRecipe{});
    Rows K(1, 6);
    K.row(0) = randomRow(rng).transpose();
    s.local.push_back(std::make_shared<LocalRows>("tree_row", 6, K));
    addJointCopyOfLastRow(s, "copy", -2.0);
    makeConsistent(s, rng);
    EXPECT_TRUE(solveOk(s, error)) << error;
    s.joint[0]->abias()[0] += 1e-3;
    EXPECT_FALSE(solveOk(s, error));
    EXPECT_NE(error.find("'copy'"), std::string::npos) << error;
  }
  {
    // Two loop constraints between the same bodies, one a scaled copy of the
    // other, and an unrelated loop (no tree rows: all three are mobile).
    System s = randomState(12, true, rng);
    Rows Ka(1, 6), Kb(1, 6), Oa(1, 6), Ob(1, 6);
    Ka.row(0) = randomRow(rng).transpose();
    Kb.row(0) = randomRow(rng).transpose();
    Oa.row(0) = randomRow(rng).transpose();
    Ob.row(0) = randomRow(rng).transpose();
    s.local.push_back(std::make_shared<LocalRows>("loop", 4, Ka, 9, Kb));
    s.local.push_back(std::make_shared<LocalRows>("loop_copy", 4, Rows(-2.0 * Ka), 9, Rows(-2.0 * Kb)));
    s.local.push_back(std::make_shared<LocalRows>("other", 2, Oa, 11, Ob));
    makeConsistent(s, rng);
    EXPECT_TRUE(solveOk(s, error)) << error;
    s.local[s.local.size() - 2]->kappa()[0] += 1e-3;
    EXPECT_FALSE(solveOk(s, error));
    EXPECT_NE(error.find("'loop'"), std::string::npos) << error;
    EXPECT_NE(error.find("'loop_copy'"), std::string::npos) << error;
    EXPECT_EQ(error.find("'other'"), std::string::npos) << error;
  }
}

// One body on a floating joint (a ball, a disk, a top) is solved in closed
// form (tree_solver/free_body.cpp) when its rows are resolved whole; redundant
// or weak rows go to the passes. Both must give the passes' answer: v̇, λ and
// Aᵀλ to round-off, and the velocity projection too — and the closed form
// must actually be taken for the well-posed cases (else this tests nothing).
// Every other case scales its rows by up to 10⁴ either way, and some make two
// rows nearly dependent: the closed form factors the rows unequilibrated and
// equilibrates only its acceptance test, so it must decide as the passes do
// whatever the scales — exactly when the equilibrated rows' tr((E K Kᵀ E)⁻¹)
// is below 1/kWeakPivot² (the free split's test, kWeakPivot = 5e-2) — and
// solve as they do.
TEST(TreeSolver, AFreeBodysClosedFormIsThePassesAnswer) {
  std::mt19937 rng(31);
  SolverOptions passes_only;
  passes_only.free_body_closed_form = false;
  int closed = 0, fallback = 0, closed_scaled = 0, weak_closed = 0, weak_passes = 0;
  for (int rep = 0; rep < 300; ++rep) {
    // One constraint of 1–6 rows, sometimes with duplicates (redundant: the passes).
    System s = randomSystem(1, true, rng, RowRecipe{rep % 3 == 0 ? 0.3 : 0.0, 0.0, 1});
    // Near-dependent rows, either side of the threshold: row 1 → row 0 + δ row 1.
    const bool weak = rep % 4 == 1 && rep % 3 != 0 && !s.local.empty() && s.local[0]->rows() >= 2;
    if (weak) {
      Rows& K = s.local[0]->rowsA();
      K.row(1) = K.row(0) + std::pow(10.0, -2.5 * std::uniform_real_distribution<double>(0, 1)(rng)) * K.row(1);
    }
    // The passes' test on the body-frame rows, densely (a margin keeps
    // round-off off the boundary).
    double weak_test = 0;  // kWeakPivot² tr((E K Kᵀ E)⁻¹): < 1 resolves whole
    if (!s.local.empty()) {
      MatX EK = s.local[0]->rowsA();
      for (int r = 0; r < EK.rows(); ++r) EK.row(r).normalize();
      weak_test = 25e-4 * MatX(EK * EK.transpose()).inverse().trace();
    }
    const bool scaled = rep % 2 == 1;
    if (scaled) scaleRowsByDecades(s, rng);
    SolvedTwice two(s, passes_only);
    auto& [list, data, cd, fast, slow, a, b] = two;
    ASSERT_TRUE(a.ok && b.ok) << a.error << b.error;
    EXPECT_FALSE(slow.lastSolveClosedForm());
    (fast.lastSolveClosedForm() ? closed : fallback)++;
    if (scaled && fast.lastSolveClosedForm()) ++closed_scaled;
    if (weak && std::abs(weak_test - 1) > 1e-6) {
      EXPECT_EQ(fast.lastSolveClosedForm(), weak_test < 1) << "rep " << rep << ": " << weak_test;
      ++(weak_test < 1 ? weak_closed : weak_passes);
    }
    EXPECT_LT(relErr(a.vdot, b.vdot), 1e-11) << "rep " << rep;
    EXPECT_LT(relErr(a.lambda, b.lambda), 1e-11) << "rep " << rep;
    EXPECT_LT(relErr(a.reaction, b.reaction), 1e-11) << "rep " << rep;
    EXPECT_EQ(a.rank, b.rank);
    if (fast.lastSolveClosedForm()) {
      const Reference ref = denseReference(s.model, cd, s.q, s.v, s.tau);
      EXPECT_LT(relErr(a.vdot, ref.vdot), 1e-10) << "rep " << rep;
      EXPECT_LT(relErr(a.lambda, ref.lambda), 1e-10) << "rep " << rep;
      EXPECT_EQ(a.redundant, 0);
    }
    VecX va = s.v, vb = s.v, ma, mb;
    ASSERT_TRUE(fast.projectVelocity(s.model, data, list, cd, s.q, va, ma)) << fast.lastError();
    ASSERT_TRUE(slow.projectVelocity(s.model, data, list, cd, s.q, vb, mb)) << slow.lastError();
    EXPECT_LT(relErr(va, vb), 1e-11) << "rep " << rep;
    EXPECT_LT(relErr(ma, mb), 1e-11) << "rep " << rep;
  }
  EXPECT_GT(closed, 100);
  EXPECT_GT(closed_scaled, 50);
  EXPECT_GT(weak_closed, 5);
  EXPECT_GT(weak_passes, 5);
  EXPECT_GT(fallback, 20);
}

// A body whose one stack (one constraint's rows, or one child's handed-up
// rows) is certified independent skips the compression's QR
// (SolverOptions::certify_independent_stacks, backward.cpp). The
// certificate is a sufficient condition for the QR to keep every row, so the
// two solvers must agree to round-off, rank included — on random trees with
// duplicated and immobile rows, rows scaled by 10^±4, and rows made nearly
// dependent (row 1 → row 0 + δ row 1): δ = 1e-13, dependent for the solver;
// 1e-5, independent but below the certificate's floor (the QR decides);
// 1e-2, certified.
TEST(TreeSolver, AnIndependentStackNeedsNoQr) {
  std::mt19937 rng(43);
  SolverOptions qr_only;
  qr_only.certify_independent_stacks = false;
  int certified = 0, stacks_refused = 0, inconsistent = 0;
  for (int rep = 0; rep < 120; ++rep) {
    const int n = 1 + rep % 13;
    const RowRecipe recipe = rep % 3 == 0 ? RowRecipe{0.35, 0.35, 3} : RowRecipe{0.0, 0.0, 2};
    System s = randomState(n, rep % 2 == 1, rng, 1.5, 2.0);
    addRandomRows(s, rng, recipe);
    constexpr double kDeltas[] = {1e-2, 1e-5, 1e-13};
    const double delta = kDeltas[(rep / 2) % 3];
    for (auto& c : s.local) {
      if (c->rows() >= 2 && rep % 4 != 0) {
        Rows& K = c->rowsA();
        K.row(1) = K.row(0) + delta * K.row(1);
      }
    }
    makeConsistent(s, rng);  // right sides some acceleration satisfies
    if (rep % 5 == 1) scaleRowsByDecades(s, rng);
    SolvedTwice two(s, qr_only);
    auto& [list, data, cd, fast, slow, a, b] = two;
    EXPECT_EQ(slow.certifiedStacks(), 0);
    // Many nearly dependent rows in one tree can leave a residual above the
    // consistency tolerance: then both find it.
    EXPECT_EQ(a.ok, b.ok) << "rep " << rep << ": " << a.error << " | " << b.error;
    if (!a.ok || !b.ok) {
      ++inconsistent;
      continue;
    }
    certified += fast.certifiedStacks();
    if (delta < 1e-12 && fast.certifiedStacks() < static_cast<int>(s.local.size())) ++stacks_refused;
    EXPECT_EQ(a.rank, b.rank) << "rep " << rep;
    EXPECT_EQ(a.redundant, b.redundant) << "rep " << rep;
    // Two round-offs of the same solve, amplified by the rows' conditioning:
    // measured at most 3e-12 (v̇, Aᵀλ) and 3e-11 (λ) for δ = 1e-2, 8e-9 and
    // 8e-8 for δ = 1e-5 (cond² ≈ 1e10), 3e-13 and 1e-10 for δ = 1e-13
    // (dropped: redundant); the bounds keep a margin of 10–30.
    constexpr double kTolV[] = {1e-10, 1e-7, 1e-11}, kTolLambda[] = {1e-9, 1e-6, 1e-9};
    const int d = (rep / 2) % 3;
    const double tol = kTolV[d];
    EXPECT_LT(relErr(a.vdot, b.vdot), tol) << "rep " << rep;
    EXPECT_LT(relErr(a.reaction, b.reaction), tol) << "rep " << rep;
    EXPECT_LT(relErr(a.lambda, b.lambda), kTolLambda[d]) << "rep " << rep;
    VecX va = s.v, vb = s.v, ma, mb;
    const bool pa = fast.projectVelocity(s.model, data, list, cd, s.q, va, ma);
    const bool pb = slow.projectVelocity(s.model, data, list, cd, s.q, vb, mb);
    EXPECT_EQ(pa, pb) << "rep " << rep << ": " << fast.lastError() << " | " << slow.lastError();
    if (pa && pb) {
      EXPECT_LT(relErr(va, vb), tol) << "rep " << rep;
    }
  }
  EXPECT_GT(certified, 100);
  EXPECT_GT(stacks_refused, 5);
  EXPECT_LT(inconsistent, 5);
}

namespace {

// A loop row between two random bodies and, with `gear`, a joint-space row
// over every velocity (both closed by the loop closure, loops.cpp).
void addLoopRows(System& s, std::mt19937& rng, bool gear) {
  std::uniform_int_distribution<int> body(0, s.model.nbodies - 1);
  Rows Ka(1, 6), Kb(1, 6);
  Ka.row(0) = randomRow(rng).transpose();
  Kb.row(0) = randomRow(rng).transpose();
  // Body b drawn before body a: g++'s order when both were arguments.
  const int body_b = body(rng);
  const int body_a = body(rng);
  s.local.push_back(std::make_shared<LocalRows>("loop", body_a, Ka, body_b, Kb));
  if (gear)
    s.joint.push_back(std::make_shared<JointRows>(
        "gear", MatX(randomVector(s.model.nv, rng).transpose())));
}

// A row on the last velocity alone — a revolute joint's on a fixed base: it
// locks that joint (locked.cpp).
void addLockRow(System& s) {
  s.joint.push_back(std::make_shared<JointRows>("lock", MatX::Constant(1, 1, 2.0),
                                                std::vector<int>{s.model.nv - 1}));
}

}  // namespace

// The factor of the backward pass depends on the configuration and the rows
// only, so a solve or projection at the same ones reuses it
// (FactorRecord): an integrator stage's factor serves the projection after
// the step and the end-of-step solve. Reused, it must give bit for bit what a
// fresh solver gives — with redundant and immobile rows (minimum norm), loop
// rows between bodies and over v (whose unit responses and their SVD are
// kept with the factor), a joint row that locks a joint, a constraint opened
// and closed, and a new configuration — and it must be reused exactly when
// nothing changed.
TEST(TreeSolver, AReusedFactorIsBitForBitAFreshOne) {
  std::mt19937 rng(41);
  SolverOptions opt;
  opt.free_body_closed_form = false;  // one floating body must use the passes too
  int reused = 0;
  for (int n : {1, 5, 20}) {
    for (bool floating : {false, true}) {
      System s = randomSystem(n, floating, rng, RowRecipe{0.2, 0.2, 1});
      std::uniform_int_distribution<int> body(0, n - 1);
      {  // at least one constraint, first in the list: the one opened below
        Rows K(2, 6);
        K.row(0) = randomRow(rng).transpose();
        K.row(1) = randomRow(rng).transpose();
        s.local.insert(s.local.begin(), std::make_shared<LocalRows>("own", body(rng), K));
      }
      if (n > 1) addLoopRows(s, rng, /*gear=*/true);
      if (!floating) addLockRow(s);
      makeConsistent(s, rng);
      const ConstraintList list = s.list();
      Data data(s.model);
      ConstraintData cd(s.model, list);
      TreeSolver solver(s.model, list, opt);
      auto same = [&](const VecX& q, const VecX& v, const char* what) -> bool {
        evaluateConstraints(s.model, data, list, cd, 0.0, q, v);
        TreeSolver fresh(s.model, list, opt);
        ConstrainedResult a, b;
        solver.solve(s.model, data, list, cd, q, v, s.tau, a);
        fresh.solve(s.model, data, list, cd, q, v, s.tau, b);
        if (!(a.ok && b.ok)) {
          ADD_FAILURE() << what << ": " << a.error << b.error;
          return false;
        }
        EXPECT_TRUE(a.vdot == b.vdot) << what << " n=" << n;
        EXPECT_TRUE(a.lambda == b.lambda) << what << " n=" << n;
        EXPECT_TRUE(a.reaction == b.reaction) << what << " n=" << n;
        EXPECT_EQ(a.redundant, b.redundant) << what;
        EXPECT_FALSE(fresh.lastFactorReused());
        return solver.lastFactorReused();
      };
      // Solves at the velocities the rows were made consistent for (immobile
      // rows' right sides hold only there), projections at any.
      const VecX v2 = randomVector(s.model.nv, rng);
      EXPECT_FALSE(same(s.q, s.v, "first solve"));
      // A projection at the same pose (other velocities: the covectors do not change).
      evaluateConstraints(s.model, data, list, cd, 0.0, s.q, v2);
      VecX va = v2, vb = v2, ma, mb;
      TreeSolver fresh(s.model, list, opt);
      ASSERT_TRUE(solver.projectVelocity(s.model, data, list, cd, s.q, va, ma)) << solver.lastError();
      ASSERT_TRUE(fresh.projectVelocity(s.model, data, list, cd, s.q, vb, mb)) << fresh.lastError();
      EXPECT_TRUE(solver.lastFactorReused());
      EXPECT_TRUE(va == vb && ma == mb) << "projection n=" << n;
      // A solve at other velocities (right sides made consistent there): the
      // factor is reused, the velocity products are new.
      s.v = randomVector(s.model.nv, rng);
      makeConsistent(s, rng);
      EXPECT_TRUE(same(s.q, s.v, "solve at other velocities"));
      // Open the first constraint: other rows, a new factor; close it again.
      cd.setActive(0, false);
      EXPECT_FALSE(same(s.q, s.v, "constraint 0 open"));
      cd.setActive(0, true);
      EXPECT_FALSE(same(s.q, s.v, "constraint 0 closed again"));
      // Another configuration (its rows' right sides made consistent there),
      // a valid one: the last coordinate may be a quaternion's.
      s.q[s.model.nq - 1] += 0.1;
      normalizeQuaternions(s.model, s.q);
      makeConsistent(s, rng);
      EXPECT_FALSE(same(s.q, s.v, "new configuration"));
      reused += same(s.q, s.v, "same configuration again") ? 1 : 0;
    }
  }
  EXPECT_EQ(reused, 6);
}

// An integrator stage asks for v̇ only, and the forward pass then skips the
// multipliers — v̇ never reads them, except below a body that hands rows up
// with their compliance (softForward reads the multipliers its parent
// unrolls), where they are kept. Either way v̇ must be bit for bit the full
// solve's: on random trees with redundant and immobile rows, loop rows, a
// locked joint, and rows their joints barely move (compliance).
TEST(TreeSolver, AccelerationsAloneAreTheFullSolvesBitForBit) {
  std::mt19937 rng(43);
  int soft = 0;
  for (int n : {3, 9, 20}) {
    for (bool floating : {false, true}) {
      for (double sigma : {0.0, 1e-3}) {
        System s = randomSystem(n, floating, rng, RowRecipe{0.2, 0.2, 1});
        if (sigma > 0) addWeakRows(s, 3, sigma, rng), ++soft;
        addLoopRows(s, rng, /*gear=*/false);
        if (!floating) addLockRow(s);
        makeConsistent(s, rng);
        const ConstraintList list = s.list();
        Data data(s.model);
        ConstraintData cd(s.model, list);
        evaluateConstraints(s.model, data, list, cd, 0.0, s.q, s.v);
        TreeSolver a(s.model, list), b(s.model, list);
        ConstrainedResult all, acc;
        a.solve(s.model, data, list, cd, s.q, s.v, s.tau, all, SolveOutputs::All);
        b.solve(s.model, data, list, cd, s.q, s.v, s.tau, acc, SolveOutputs::Accelerations);
        ASSERT_TRUE(all.ok && acc.ok) << all.error << acc.error;
        EXPECT_TRUE(all.vdot == acc.vdot) << "n=" << n << " sigma=" << sigma;
        // And the factor the v̇-only solve left serves a full solve after it.
        ConstrainedResult again;
        b.solve(s.model, data, list, cd, s.q, s.v, s.tau, again, SolveOutputs::All);
        EXPECT_TRUE(b.lastFactorReused());
        EXPECT_TRUE(again.vdot == all.vdot && again.lambda == all.lambda) << "n=" << n;
      }
    }
  }
  EXPECT_EQ(soft, 6);
}
