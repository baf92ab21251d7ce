// ABA, CRBA and RNEA describe one mechanics: ABA(τ) = M⁻¹(τ − h) and
// RNEA(ABA(τ)) = τ, on random trees with every joint type.
#include "random_tree.hpp"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

using namespace appell;

namespace {

double relErr(const VecX& a, const VecX& b) { return (a - b).norm() / std::max(1.0, b.norm()); }

}  // namespace

class RandomTrees : public ::testing::TestWithParam<std::tuple<int, bool>> {};

TEST_P(RandomTrees, AbaMatchesCrbaAndRnea) {
  const auto [n, floating] = GetParam();
  std::mt19937 rng(1000 * n + floating);
  for (int trial = 0; trial < 5; ++trial) {
    const Model model = test::randomTree(n, floating, rng);
    Data data(model);
    const VecX q = randomConfiguration(model, rng);
    const VecX v = test::randomVector(model.nv, rng);
    const VecX tau = test::randomVector(model.nv, rng, 10.0);

    const VecX ddq = aba(model, data, q, v, tau);
    const MatX M = crba(model, data, q);
    const VecX h = nonLinearEffects(model, data, q, v);
    const VecX ddq_ref = M.ldlt().solve(tau - h);
    EXPECT_LT(relErr(ddq, ddq_ref), 1e-10 * M.norm() * M.inverse().norm())
        << "n=" << n << " floating=" << floating;
    const VecX tau_back = rnea(model, data, q, v, ddq);
    EXPECT_LT(relErr(tau_back, tau), 1e-12) << "n=" << n;
    // M is symmetric positive definite.
    EXPECT_LT((M - M.transpose()).norm(), 1e-12 * M.norm());
    EXPECT_GT(Eigen::SelfAdjointEigenSolver<MatX>(M).eigenvalues().minCoeff(), 0.0);
  }
}

INSTANTIATE_TEST_SUITE_P(Sizes, RandomTrees,
                         ::testing::Combine(::testing::Values(1, 2, 5, 12, 50),
                                            ::testing::Bool()));
