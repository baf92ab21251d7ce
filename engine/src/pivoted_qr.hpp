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
  double a[kMaxRows][6];  ///< the stacked rows, row-major: nb rows are contiguous
  double tau[6];          ///< reflector scalars
  int perm[6];            ///< column c of R is column perm[c] of the input (and of `a`)
  int rank = 0;           ///< = number of reflectors computed

  /// Factors the nb × 6 matrix held in `a`, stopping as soon as the largest
  /// remaining column norm is at most max(abs_tol, rel_tol · |R₀₀|): that norm
  /// is the next |R_kk|, so the kept rows are exactly those the rank rule of
  /// a full pivoted QR would keep. The unreduced remainder is left in place.
  void factor(int nb, double abs_tol, double rel_tol) {
    // Columns are pivoted through `perm` rather than swapped in memory. The
    // tail norms of the next step are summed inside the update that changes
    // them (exact sums, no down-dating), and the reflector is applied
    // unnormalised, H = 1 − γ u uᵀ with u = x − β e_k, γ = 1/(−β u_k): one
    // division per step, overlapping the dot products. Row-major storage
    // keeps a stack in ≤ 9 contiguous cache lines (it lives in the workspace
    // of every body).
    double n2[6] = {0, 0, 0, 0, 0, 0};
    for (int r = 0; r < nb; ++r)
      for (int c = 0; c < 6; ++c) n2[c] += a[r][c] * a[r][c];
    for (int c = 0; c < 6; ++c) perm[c] = c;
    const int kmax = std::min(nb, 6);
    double thr2 = abs_tol * abs_tol;
    rank = 0;
    for (int k = 0; k < kmax; ++k) {
      int piv = k;
      for (int c = k + 1; c < 6; ++c)
        if (n2[c] > n2[piv]) piv = c;
      const double best = n2[piv];
      if (k == 0) thr2 = std::max(thr2, rel_tol * rel_tol * best);
      if (!(best > thr2)) break;  // |R_kk| = √best at most the tolerance
      std::swap(perm[k], perm[piv]);
      std::swap(n2[k], n2[piv]);
      const int pk = perm[k];
      const double alpha = a[k][pk];
      const double norm = std::sqrt(best);
      const double beta = alpha >= 0 ? -norm : norm;  // no cancellation in u_k
      const double uk = alpha - beta;
      const double gamma = 1.0 / (-beta * uk);
      for (int c = k + 1; c < 6; ++c) {
        const int pc = perm[c];
        double d = uk * a[k][pc];
        for (int r = k + 1; r < nb; ++r) d += a[r][pk] * a[r][pc];
        const double t = gamma * d;
        a[k][pc] -= t * uk;
        double s = 0;
        for (int r = k + 1; r < nb; ++r) {
          a[r][pc] -= t * a[r][pk];
          s += a[r][pc] * a[r][pc];
        }
        n2[c] = s;
      }
      // Eigen's normalisation: essential part u_r / u_k, τ = u_k² γ.
      const double inv_uk = -beta * gamma;
      for (int r = k + 1; r < nb; ++r) a[r][pk] *= inv_uk;
      tau[k] = uk * uk * gamma;
      a[k][pk] = beta;
      rank = k + 1;
    }
  }

  /// Entry (r, c) of the factored matrix in pivoted column order: R on and
  /// above the diagonal, reflector k's essential part below it in column k.
  double operator()(int r, int c) const { return a[r][perm[c]]; }
};

}  // namespace appell::detail
