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
// reflector loops of tree_solver/workspace.hpp apply Q as before.
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <cmath>

namespace appell::detail {

struct PivotedQR {
  static constexpr int kMaxRows = 12;
  alignas(16) double a[kMaxRows][6];  ///< the stacked rows, row-major (nb rows contiguous)
  double tau[6];                      ///< reflector scalars
  int perm[6];                        ///< column c of R is column perm[c] of the input (and of `a`)
  int rank = 0;                       ///< = number of reflectors computed

  /// Factors the nb × 6 matrix held in `a`, stopping as soon as the largest
  /// remaining column norm is at most max(abs_tol, rel_tol · |R₀₀|): that norm
  /// is the next |R_kk|, so the kept rows are exactly those the rank rule of
  /// a full pivoted QR would keep. The unreduced remainder is left in place.
  ///
  /// Columns are pivoted by index, never moved. Each step works on whole
  /// 6-wide rows (three SSE packets; columns already pivoted are masked), so
  /// the inner loops have a fixed length: the tail norms of the next step are
  /// summed inside the update, and the reflector is applied unnormalised,
  /// H = 1 − γ u uᵀ with u = x − β e_k, γ = 1/(−β u_k) — one division per step.
  void factor(int nb, double abs_tol, double rel_tol) {
    using A6 = Eigen::Array<double, 6, 1>;
    using Row = Eigen::Map<A6, Eigen::Aligned16>;
    A6 n2 = A6::Zero();
    for (int r = 0; r < nb; ++r) n2 += Row(a[r]).square();
    A6 live = A6::Ones();  // 1 for the columns not pivoted yet
    const int kmax = std::min(nb, 6);
    double thr2 = abs_tol * abs_tol;
    rank = 0;
    for (int k = 0; k < kmax; ++k) {
      int pk = -1;
      double best = -1;
      for (int c = 0; c < 6; ++c)
        if (live[c] != 0 && n2[c] > best) best = n2[c], pk = c;
      if (k == 0) thr2 = std::max(thr2, rel_tol * rel_tol * best);
      if (!(best > thr2)) break;  // |R_kk| = √best at most the tolerance
      perm[k] = pk;
      live[pk] = 0;
      const double alpha = a[k][pk];
      const double norm = std::sqrt(best);
      const double beta = alpha >= 0 ? -norm : norm;  // no cancellation in u_k
      const double uk = alpha - beta;
      const double gamma = 1.0 / (-beta * uk);
      double u[kMaxRows];
      for (int r = k + 1; r < nb; ++r) u[r] = a[r][pk];
      A6 d = uk * Row(a[k]);
      for (int r = k + 1; r < nb; ++r) d += u[r] * Row(a[r]);
      const A6 t = gamma * d * live;
      Row(a[k]) -= uk * t;
      n2.setZero();
      for (int r = k + 1; r < nb; ++r) {
        Row row(a[r]);
        row -= u[r] * t;
        n2 += row.square();
      }
      // Eigen's normalisation: essential part u_r / u_k, τ = u_k² γ.
      const double inv_uk = -beta * gamma;
      for (int r = k + 1; r < nb; ++r) a[r][pk] = u[r] * inv_uk;
      tau[k] = uk * uk * gamma;
      a[k][pk] = beta;
      rank = k + 1;
    }
    int c = rank;  // the unpivoted columns complete Π in their input order
    for (int j = 0; j < 6; ++j)
      if (live[j] != 0) perm[c++] = j;
  }

  /// Entry (r, c) of the factored matrix in pivoted column order: R on and
  /// above the diagonal, reflector k's essential part below it in column k.
  double operator()(int r, int c) const { return a[r][perm[c]]; }
};

}  // namespace appell::detail
