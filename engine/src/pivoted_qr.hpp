// Rank-revealing Householder QR with column pivoting (Businger & Golub 1965;
// Golub & Van Loan, "Matrix Computations", Alg. 5.4.1) for the tree solver's
// row stacks: at most 12 rows, exactly 6 columns.
//
// Why not Eigen's ColPivHouseholderQR: on these tiny blocks its generic
// Householder application and norm down-dating cost ~3.7k instructions per
// 5 × 6 stack, about four times this loop; and it always factors every
// column, where the tree solver stops at the numerical rank. Storage follows
// Eigen's convention (R on and above the diagonal, each reflector's essential
// part below it, H_k = 1 − τ_k v vᵀ with v = [0…0, 1, essential]), so the
// reflector loops of tree_solver_workspace.hpp apply Q as before.
#pragma once

#include <algorithm>
#include <cmath>

namespace appell::detail {

struct PivotedQR {
  static constexpr int kMaxRows = 12;
  double a[6][kMaxRows];  ///< input columns, column-major: a[c][r]
  double tau[6];          ///< reflector scalars
  int perm[6];            ///< column c of R is column perm[c] of the input (and of `a`)
  int rank = 0;           ///< = number of reflectors computed

  /// Factors the nb × 6 matrix held in `a`, stopping as soon as the largest
  /// remaining column norm is at most max(abs_tol, rel_tol · |R₀₀|): that norm
  /// is the next |R_kk|, so the kept rows are exactly those the rank rule of
  /// a full pivoted QR would keep. The unreduced remainder is left in place.
  void factor(int nb, double abs_tol, double rel_tol) {
    // Columns are pivoted through `perm` rather than swapped in memory: a
    // swap right after the scalar writes that stacked the rows stalls on
    // store forwarding, and costs more than the whole reflector update.
    for (int c = 0; c < 6; ++c) perm[c] = c;
    const int kmax = std::min(nb, 6);
    double thr = abs_tol;
    rank = 0;
    for (int k = 0; k < kmax; ++k) {
      // Pivot: the remaining column of largest norm (recomputed, not
      // down-dated: exact and cheap at ≤ 12 rows).
      int piv = k;
      double best = -1;
      for (int c = k; c < 6; ++c) {
        const double* x = a[perm[c]];
        double s = 0;
        for (int r = k; r < nb; ++r) s += x[r] * x[r];
        if (s > best) best = s, piv = c;
      }
      const double norm = std::sqrt(best);
      if (k == 0) thr = std::max(abs_tol, rel_tol * norm);
      if (!(norm > thr)) break;
      std::swap(perm[k], perm[piv]);
      // Reflector mapping column k to β e_k, β = −sign(a_kk) ‖·‖ (no cancellation).
      double* v = a[perm[k]];
      const double alpha = v[k];
      const double beta = alpha >= 0 ? -norm : norm;
      const double scale = 1.0 / (alpha - beta);
      for (int r = k + 1; r < nb; ++r) v[r] *= scale;
      tau[k] = (beta - alpha) / beta;
      v[k] = beta;
      for (int c = k + 1; c < 6; ++c) {
        double* x = a[perm[c]];
        double t = x[k];
        for (int r = k + 1; r < nb; ++r) t += v[r] * x[r];
        t *= tau[k];
        x[k] -= t;
        for (int r = k + 1; r < nb; ++r) x[r] -= t * v[r];
      }
      rank = k + 1;
    }
  }

  /// Entry (r, c) of the factored matrix in pivoted column order: R on and
  /// above the diagonal, reflector k's essential part below it in column k.
  double operator()(int r, int c) const { return a[perm[c]][r]; }
};

}  // namespace appell::detail
