// Rank-revealing treatment of a set of constraint rows, shared by the dense
// KKT solver, the dense Appell solver and the position projection (private).
//
// The m rows are handed over as the COLUMNS of an n × m matrix B: B = Aᵀ for
// the Euclidean (Appell) metric, B = L⁻¹Aᵀ with M = LLᵀ for the mass metric
// (KKT, projections). Each column is scaled to unit norm (row equilibration,
// D), then factored with column pivoting (Businger–Golub):
//     B D P = Q R,      Q = [Q₁ Q₂]  (n × rank, n × (n − rank)).
// The numerical rank is the number of pivots with |R_kk| > abs_tol + rel_tol |R_00|
// (|R_00| = 1 after equilibration, so both tolerances are dimensionless).
// Q₁ spans the row space of the rows, Q₂ their null space (orthonormal).
//
// Everything is sized at construction: factor/solve/minNorm do not allocate
// (Eigen's Householder code runs unblocked below 48 reflectors).
#pragma once

#include <cmath>

#include <appell/constrained_dynamics.hpp>

#include <Eigen/Cholesky>
#include <Eigen/QR>

#include <string>
#include <vector>

namespace appell::detail {

class RowBasis {
 public:
  RowBasis(int n, int m);

  int n() const { return n_; }
  int m() const { return m_; }

  /// Equilibrates and factors the rows (columns of B, n × m). With
  /// `form_q` the orthogonal factor is formed explicitly (Q1(), Q2(), and
  /// minNorm() of an arbitrary y need it); without, y = Q₁z is applied from
  /// the Householder reflectors (O(n·min(n, m)) instead of O(n²·min(n, m))).
  void factor(const MatX& B, const SolverOptions& options, bool form_q = true);
  int rank() const { return rank_; }

  /// Orthonormal bases of the row space and of the null space of the rows
  /// (only after factor(…, form_q = true)).
  Eigen::Block<const MatX, Eigen::Dynamic, Eigen::Dynamic, true> Q1() const { return Q_.leftCols(rank_); }
  Eigen::Block<const MatX, Eigen::Dynamic, Eigen::Dynamic, true> Q2() const { return Q_.rightCols(n_ - rank_); }

  /// Solves Bᵀ y = d for the minimum-norm y = Q₁ z. The rows that the rank
  /// decision dropped must then hold as well: a residual above
  /// consistency_tol (1 + ‖D d‖∞) in equilibrated units makes it return false
  /// (describeInconsistency() says which rows).
  bool solveRows(const VecX& d, VecX& y);

  /// Minimum-norm λ with B λ = y for the y of the last solveRows() (y = Q₁z):
  /// K λ = z with K = Q₁ᵀB = R₁PᵀD⁻¹ (read off the factorization, no Q
  /// needed). Kᵀ (m × rank, padded to m × m so that its size is fixed) is
  /// factored by Householder QR, Kᵀ = Q_E R_E, and λ = Q_E [R_E⁻ᵀ z; 0].
  void minNormOfSolution(VecX& lambda);
  /// Minimum-norm λ with B λ = y for any y (its part outside range(B) is
  /// ignored; rangeResidual() reports ‖Q₂ᵀ y‖). Needs form_q.
  void minNorm(const VecX& y, VecX& lambda);
  double rangeResidual() const { return range_residual_; }

  /// Original row index of pivot position k (the first rank() are independent).
  int pivot(int k) const { return qr_.colsPermutation().indices()[k]; }
  /// |R(k,k)| / |R(0,0)| of the last kept pivot, k = rank() − 1 (1 when
  /// rank ≤ 1): how close the kept, equilibrated rows are to dependence — a
  /// Newton step on them is as ill-conditioned as its inverse.
  double weakestPivotRatio() const {
    if (rank_ <= 1) return 1.0;
    const auto& R = qr_.matrixQR();
    return std::abs(R(rank_ - 1, rank_ - 1)) / std::abs(R(0, 0));
  }
  /// Equilibration factor of row i (0 for a row that is numerically zero).
  double scale(int i) const { return D_[i]; }

  /// "rows 'c1'/label (#i) and … are inconsistent (residual …)" — names the
  /// dropped row with the largest residual and the independent rows it
  /// depends on. Allocates (error path only).
  /// `row_map` (optional) maps this basis' rows to rows of the dense system
  /// when only a subset was factored (the holonomic rows of a projection).
  std::string describeInconsistency(const ConstraintList& constraints,
                                    const ConstraintData& cdata,
                                    const std::vector<int>* row_map = nullptr) const;

 private:
  int n_, m_, k_;           // k_ = min(n, m)
  SolverOptions opt_;
  int rank_ = 0;
  VecX D_;                  // m
  MatX Be_;                 // n × m, equilibrated copy
  Eigen::ColPivHouseholderQR<MatX> qr_;
  MatX Q_;                  // n × n
  VecX work_n_, work_m_;
  VecX pd_;                 // m, P ᵀ D d
  VecX z_;                  // n (first rank used)
  // Minimum-norm multipliers.
  MatX E_;                  // m × m
  Eigen::HouseholderQR<MatX> eqr_;
  bool form_q_ = true;

  /// x ← H₀H₁…H_{k−1} x for the reflectors stored in `qr` (Q x without forming Q).
  template <class QR>
  static void applyQ(const QR& qr, int reflectors, VecX& x);
  /// λ from K λ = s (s: first rank entries of `w_`).
  void minNormFromRowSpace(VecX& lambda);
  VecX w_;                  // m
  double range_residual_ = 0;
  // Last inconsistency: pivot position of the worst dropped row (−1: a zero row
  // given by its original index in zero_row_), and its residual.
  int bad_pivot_ = -1, zero_row_ = -1;
  double bad_residual_ = 0;
};

/// Σ rows of the constraints (throws std::invalid_argument on a null entry).
int totalRows(const ConstraintList& constraints);
/// Throws std::invalid_argument naming `who` when sizes do not match the system.
void checkSizes(const char* who, const Model& model, int m, const ConstraintData& cdata,
                const VecX& q, const VecX& v, const VecX* tau);
/// The dense form A, abias of the rows in `cdata` (evaluated at q, v): a dense
/// solver's first step. Overwrites `data` with forwardKinematics(q, v, 0).
void assembleDense(const Model& model, Data& data, const ConstraintList& constraints,
                   ConstraintData& cdata, const VecX& q, const VecX& v);
/// Sizes the result (no allocation once sized) and clears its status.
void sizeResult(int nv, int m, ConstrainedResult& out);

/// "constraint 'name' row 'label' (#i)" for row i of the dense system.
std::string rowName(const ConstraintList& constraints, const ConstraintData& cdata, int i);

}  // namespace appell::detail
