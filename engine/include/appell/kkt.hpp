// Dense multiplier (KKT) formulation — a reference solver, kept forever.
//
//   [ M  Aᵀ ] [ v̇ ]   [ τ − h  ]
//   [ A  0  ] [ −λ ] = [ −abias ]                        (docs/solvers.md)
//
// solved by the range-space method in the mass metric, which stays exact with
// redundant rows: M = LLᵀ (Cholesky), a = M⁻¹(τ − h), and a column-pivoted
// QR of the equilibrated B = L⁻¹AᵀD (each row scaled to unit M⁻¹-norm,
// A_i M⁻¹ A_iᵀ = 1). With y = Lᵀ(v̇ − a) the constraints read Bᵀy = D(c − A a),
// c = −abias, and Gauss' principle picks the y of least norm:
//     v̇ = a + L⁻ᵀ (A L⁻ᵀ)⁺ (c − A a)
// — the Udwadia–Kalaba formula with M^{1/2} replaced by the Cholesky factor
// (Udwadia & Kalaba, Proc. R. Soc. A 439 (1992) 407). λ is the minimum-norm
// solution of L⁻¹Aᵀλ = y, i.e. of Aᵀλ = M(v̇ − a).
//
// Rank: pivots |R_kk| ≤ rank_abs_tol + rank_rel_tol |R_00| are dropped (the
// redundant rows); each dropped row must then be reproduced by the kept ones
// to consistency_tol, otherwise the result is an error naming the rows.
// The workspace is sized at construction; solve() does not allocate (for up to
// 47 rows — Eigen's blocked Householder code allocates beyond that).
#pragma once

#include <appell/constrained_dynamics.hpp>

#include <memory>

namespace appell {

class KktSolver final : public ConstrainedSolver {
 public:
  KktSolver(const Model& model, const ConstraintList& constraints,
            const SolverOptions& options = {});
  ~KktSolver() override;

  Formulation formulation() const override { return Formulation::Multipliers; }
  bool usesDenseRows() const override { return true; }
  void solve(const Model& model, Data& data, const ConstraintList& constraints,
             ConstraintData& cdata, const VecX& q, const VecX& v, const VecX& tau,
             ConstrainedResult& out,
             SolveOutputs outputs = SolveOutputs::All) override;
  /// v⁺ = v − M⁻¹Aᵀμ with A v⁺ + b = 0, μ (`impulse`) of minimum norm: the
  /// M-orthogonal projection of v onto the constraint set.
  bool projectVelocity(const Model& model, Data& data, const ConstraintList& constraints,
                       ConstraintData& cdata, const VecX& q, VecX& v, VecX& impulse) override;

  const SolverOptions& options() const { return options_; }
  const std::string& lastError() const override { return last_error_; }

 private:
  struct Impl;
  SolverOptions options_;
  std::unique_ptr<Impl> impl_;
  std::string last_error_;
};

}  // namespace appell
