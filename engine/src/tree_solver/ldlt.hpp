// Square-root-free LDLᵀ of a small symmetric positive definite matrix, and
// the trace of its equilibrated inverse — the certificate the tree solver
// uses where a factorisation it can skip would only confirm that rows are
// independent (free_body.cpp: the free joint resolves them whole;
// backward.cpp: a stack needs no compression). The trace bounds the smallest
// eigenvalue from below, λ_min(E S E) ≥ 1/tr((E S E)⁻¹), and the LDLᵀ is
// invariant under the diagonal scaling E (van der Sluis 1969), so E never
// has to be formed.
#pragma once

#include <appell/spatial.hpp>

namespace appell::detail {

/// In-place LDLᵀ of the leading n × n of a (lower triangle read; the unit
/// factor L below the diagonal, D on it); inv_d gets 1/d_j. False when a
/// pivot is not positive.
inline bool ldlt(Mat6& a, int n, double inv_d[6]) {
  for (int j = 0; j < n; ++j) {
    double d = a(j, j);
    for (int k = 0; k < j; ++k) d -= a(j, k) * a(j, k) * a(k, k);
    if (!(d > 0)) return false;
    a(j, j) = d;
    inv_d[j] = 1.0 / d;
    for (int i = j + 1; i < n; ++i) {
      double s = a(i, j);
      for (int k = 0; k < j; ++k) s -= a(i, k) * a(j, k) * a(k, k);
      a(i, j) = s * inv_d[j];
    }
  }
  return true;
}

/// x ← S⁻¹ x for S = L D Lᵀ (ldlt's output).
inline void ldltSolve(const Mat6& l, const double inv_d[6], int n, double* x) {
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < i; ++k) x[i] -= l(i, k) * x[k];
  for (int i = 0; i < n; ++i) x[i] *= inv_d[i];
  for (int i = n - 1; i >= 0; --i)
    for (int k = i + 1; k < n; ++k) x[i] -= l(k, i) * x[k];
}

/// tr(E⁻¹ S⁻¹ E⁻¹) = Σᵢ (S⁻¹)ᵢᵢ/eᵢ² for S = L D Lᵀ and a diagonal E given
/// as w2ᵢ = 1/eᵢ², with (S⁻¹)ᵢᵢ = Σⱼ (L⁻¹)ⱼᵢ²/dⱼ: the trace of the inverse of
/// the equilibrated matrix E S E, without forming E (no square roots).
inline double equilibratedInverseTrace(const Mat6& l, const double inv_d[6], const double w2[6],
                                       int n) {
  double tr = 0;
  for (int c = 0; c < n; ++c) {  // column c of L⁻¹ (unit lower triangular)
    double x[6];
    x[c] = 1.0;
    double diag = inv_d[c];
    for (int r = c + 1; r < n; ++r) {
      double s = 0;
      for (int k = c; k < r; ++k) s -= l(r, k) * x[k];
      x[r] = s;
      diag += s * s * inv_d[r];
    }
    tr += w2[c] * diag;
  }
  return tr;
}

}  // namespace appell::detail
