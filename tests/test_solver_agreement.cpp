// Multipliers (KKT) and Appell/Maggi (orthonormal and coordinate-partition null
// spaces) on random trees with random body rows, including duplicated, scaled
// and combined rows: the same v̇ (to 1e-10 relative), the same reaction Aᵀλ,
// the same minimum-norm λ, all equal to the Udwadia–Kalaba formula
//   v̇ = a + M^{-1/2} (A M^{-1/2})⁺ (c − A a),   λ = (Aᵀ)⁺ (M v̇ + h − τ).
#include <appell/appell_maggi.hpp>
#include <appell/kkt.hpp>

#include "random_tree.hpp"
#include "test_solver_rows.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <gtest/gtest.h>

#include <random>

namespace appell {
namespace {

using test::BodyRows;
using test::pointRow;

struct Reference {
  VecX vdot, lambda;
  int rank = 0;
};

// Udwadia–Kalaba with the symmetric square root of M and SVD pseudo-inverses.
Reference udwadiaKalaba(const MatX& M, const VecX& h, const VecX& tau, const MatX& A,
                        const VecX& abias) {
  Eigen::SelfAdjointEigenSolver<MatX> es(M);
  const MatX Mis = es.eigenvectors() * es.eigenvalues().cwiseSqrt().cwiseInverse().asDiagonal() *
                   es.eigenvectors().transpose();
  const VecX a = M.ldlt().solve(tau - h);
  const VecX c = -abias;
  Reference ref;
  ref.vdot = a;
  if (A.rows() == 0) return ref;
  Eigen::JacobiSVD<MatX> svd(A * Mis, Eigen::ComputeThinU | Eigen::ComputeThinV);
  svd.setThreshold(1e-9);
  ref.vdot = a + Mis * svd.solve(c - A * a);
  Eigen::JacobiSVD<MatX> svdT(A.transpose(), Eigen::ComputeThinU | Eigen::ComputeThinV);
  svdT.setThreshold(1e-9);
  ref.lambda = svdT.solve(M * ref.vdot + h - tau);
  // Rank of the row-equilibrated A.
  MatX Ae = A;
  const double amax = A.rowwise().norm().maxCoeff();
  for (int i = 0; i < A.rows(); ++i) {
    const double nrm = A.row(i).norm();
    if (nrm > 1e-10 * amax) Ae.row(i) /= nrm; else Ae.row(i).setZero();
  }
  if (amax == 0) return ref;
  Eigen::JacobiSVD<MatX> svdE(Ae);
  svdE.setThreshold(1e-9);
  ref.rank = static_cast<int>(svdE.rank());
  return ref;
}

Vec6 randomRow(std::mt19937& rng) {
  return pointRow(test::randomVector(3, rng, 0.5), test::randomUnit(rng));
}

struct Case {
  Model model;
  ConstraintList constraints;
};

// Random rows on random bodies; with `redundant`, a second constraint on one
// body repeats some of its rows scaled and adds the sum of two of them.
Case randomCase(std::mt19937& rng, bool redundant) {
  std::uniform_int_distribution<int> nb(1, 6), coin(0, 1);
  Case c;
  const bool floating_base = coin(rng) == 1;  // before the size: g++'s order as arguments
  c.model = test::randomTree(nb(rng), floating_base, rng);
  const int nc = std::uniform_int_distribution<int>(1, std::min(3, c.model.nbodies))(rng);
  std::vector<std::vector<Vec6>> rows;
  for (int k = 0; k < nc; ++k) {
    const int body = std::uniform_int_distribution<int>(0, c.model.nbodies - 1)(rng);
    std::vector<Vec6> w;
    const int r = std::uniform_int_distribution<int>(1, 4)(rng);
    for (int j = 0; j < r; ++j) w.push_back(randomRow(rng));
    c.constraints.push_back(std::make_shared<BodyRows>("c" + std::to_string(k), body, w));
    rows.push_back(w);
    if (redundant && k == 0) {
      std::vector<Vec6> d{2.5 * w[0], -w[0]};
      if (r >= 2) d.push_back(w[0] + 0.5 * w[1]);
      c.constraints.push_back(std::make_shared<BodyRows>("dup", body, d));
    }
  }
  return c;
}

double rel(const VecX& a, const VecX& b) {
  return (a - b).lpNorm<Eigen::Infinity>() /
         std::max(1.0, std::max(a.lpNorm<Eigen::Infinity>(), b.lpNorm<Eigen::Infinity>()));
}

/// Shifts each row's κ (Ȧv + ḃ of joint-space rows) so that the assembled
/// abias = κ + W J̇v becomes `target`; `cd` holds evaluateConstraints at the
/// state in `data`, and afterwards its dense form again.
void setAccelerationBias(const Model& model, const Data& data, const ConstraintList& constraints,
                         ConstraintData& cd, const VecX& target) {
  for (size_t k = 0; k < constraints.size(); ++k) {
    const int o = cd.offset[k], m = constraints[k]->rows();
    RowBlock& blk = cd.blocks[k];
    if (constraints[k]->jointSpace()) blk.abias_joint = target.segment(o, m);
    else blk.kappa.head(m) += target.segment(o, m) - cd.abias.segment(o, m);
  }
  assembleDenseRows(model, data, constraints, cd);
}

TEST(SolverAgreement, ThousandRandomStatesKktAppellUdwadiaKalaba) {
  std::mt19937 rng(20261121);
  int states = 0, redundant_states = 0, full_rank_states = 0;
  double worst_vdot = 0, worst_reaction = 0, worst_lambda = 0, worst_uk = 0, worst_ref_lambda = 0;
  for (int ci = 0; states < 1000; ++ci) {
    const bool redundant = ci % 3 == 2;
    Case c = randomCase(rng, redundant);
    const Model& model = c.model;
    Data data(model);
    ConstraintData cd(model, c.constraints);
    KktSolver kkt(model, c.constraints);
    AppellSolver orth(model, c.constraints);
    AppellSolver part(model, c.constraints, {}, {NullSpace::CoordinatePartition});
    for (int s = 0; s < 10; ++s, ++states) {
      const VecX q = randomConfiguration(model, rng);
      const VecX v = test::randomVector(model.nv, rng, 2.0);
      const VecX tau = test::randomVector(model.nv, rng, 5.0);
      evaluateConstraints(model, data, c.constraints, cd, 0.0, q, v);
      // Rows limited by a body's few joint DoF may be dependent without their
      // velocity products being so; a consistent right-hand side is A w. Set
      // in the rows (κ), from which the dense solvers assemble abias.
      setAccelerationBias(model, data, c.constraints, cd,
                          -cd.A * test::randomVector(model.nv, rng, 3.0));
      ConstrainedResult rk, ro, rp;
      kkt.solve(model, data, c.constraints, cd, q, v, tau, rk);
      orth.solve(model, data, c.constraints, cd, q, v, tau, ro);
      part.solve(model, data, c.constraints, cd, q, v, tau, rp);
      ASSERT_TRUE(rk.ok) << rk.error;
      ASSERT_TRUE(ro.ok) << ro.error;
      ASSERT_TRUE(rp.ok) << rp.error;

      const MatX M = crba(model, data, q);
      const VecX h = nonLinearEffects(model, data, q, v);
      const Reference ref = udwadiaKalaba(M, h, tau, cd.A, cd.abias);
      EXPECT_EQ(rk.rank, ref.rank);
      EXPECT_EQ(ro.rank, ref.rank);
      EXPECT_EQ(rp.rank, ref.rank);
      EXPECT_EQ(rk.redundant, cd.m - ref.rank);
      EXPECT_EQ(ro.redundant, rk.redundant);

      // The constrained equations themselves.
      EXPECT_LT(rel(M * rk.vdot + h, tau + cd.A.transpose() * rk.lambda), 1e-10);
      EXPECT_LT(rel(cd.A * rk.vdot, -cd.abias), 1e-10);
      EXPECT_LT(rel(cd.A * ro.vdot, -cd.abias), 1e-10);

      for (const ConstrainedResult* r : {&ro, &rp}) {
        worst_vdot = std::max(worst_vdot, rel(r->vdot, rk.vdot));
        worst_reaction = std::max(worst_reaction, rel(r->reaction, rk.reaction));
        worst_lambda = std::max(worst_lambda, rel(r->lambda, rk.lambda));
        EXPECT_LT(rel(r->vdot, rk.vdot), 1e-10);
        EXPECT_LT(rel(r->reaction, rk.reaction), 1e-10);
      }
      worst_uk = std::max(worst_uk, rel(rk.vdot, ref.vdot));
      EXPECT_LT(rel(rk.vdot, ref.vdot), 1e-9);
      EXPECT_LT(rel(ro.vdot, ref.vdot), 1e-9);
      EXPECT_LT(rel(rp.vdot, ref.vdot), 1e-9);
      if (cd.m > 0) {
        worst_ref_lambda = std::max(worst_ref_lambda, rel(rk.lambda, ref.lambda));
        EXPECT_LT(rel(rk.lambda, ref.lambda), 1e-8);  // SVD reference, squared conditioning
      }
      // The minimum-norm λ is unique, with or without redundant rows.
      EXPECT_LT(rel(ro.lambda, rk.lambda), 1e-9);
      EXPECT_LT(rel(rp.lambda, rk.lambda), 1e-9);
      if (rk.redundant > 0) ++redundant_states; else ++full_rank_states;
    }
  }
  EXPECT_GT(redundant_states, 200);
  EXPECT_GT(full_rank_states, 200);
  std::printf("states %d (redundant %d): max rel diff vdot %.2e, reaction %.2e, lambda %.2e; "
              "KKT vs Udwadia-Kalaba vdot %.2e, lambda %.2e\n",
              states, redundant_states, worst_vdot, worst_reaction, worst_lambda, worst_uk,
              worst_ref_lambda);
}

}  // namespace
}  // namespace appell
