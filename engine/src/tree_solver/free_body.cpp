// Tree solver, the one-free-body case (a ball, a disk, a top, an ellipsoid:
// a model that is one body on a floating joint, every row its own). There
// Gauss' principle is one rigid body's, solved in closed form:
//   I a = f₀ + Kᵀ μ,   K a = k,   f₀ = τ − v ×* I v,
//   a₀ = I⁻¹ f₀,   (K I⁻¹ Kᵀ) μ = k − K a₀,   a = a₀ + I⁻¹ Kᵀ μ,
// with I = L Lᵀ (Model::spatial_inertia_factor) and Y = L⁻¹ Kᵀ, so that
// K I⁻¹ Kᵀ = Yᵀ Y and a = L⁻ᵀ(L⁻¹ f₀ + Y μ). I is constant in the body's
// frame, so L⁻¹ is formed once (TreeSolver's constructor) and a solve is
// m + 2 fixed-size 6 × 6 matrix-vector products and an m × m LDLᵀ
// factorisation (m ≤ 6 rows; no square roots): the general passes' answer without their dynamic-size
// machinery (compression, split, articulated inertia) and without the
// division chains of 6 × 6 triangular solves.
//
// It is taken only where it is that answer. The rows, equilibrated (E K),
// must be resolved whole by the free joint, which the general passes decide
// by 1/‖R⁻¹‖_F > kWeakPivot on the compression's triangular factor
// (backward.cpp, freeSplit) — with R the factor of E K's QR, ‖R⁻¹‖_F² =
// tr((E K Kᵀ E)⁻¹). Here the bound comes from the factor the solve needs
// anyway, S = YᵀY = E K I⁻¹ Kᵀ E = L D Lᵀ: since I⁻¹ ⪯ Id/λ_min(I),
//     tr(S⁻¹) ≥ λ_min(I) tr((E K Kᵀ E)⁻¹),  so  ‖R⁻¹‖_F² ≤ tr(S⁻¹)/λ_min(I),
// and λ_min(I) > kWeakPivot² tr(S⁻¹) (λ_min(I) formed once, tr(S⁻¹) from
// L and D) implies the passes' test. The bound loses up to cond(I) (a 1 g
// ball of 1 cm: 160²), so where it fails the Gram matrix's factor,
// E K Kᵀ E = Lg Dg Lgᵀ, decides as the passes do: tr(G⁻¹) = ‖R⁻¹‖_F².
// The closed form thus
// accepts exactly what the passes resolve whole, and pays for the second
// factorisation only near the threshold or on such bodies. Then no row is
// redundant, μ is unique, and the result agrees with the passes to round-off
// (tests/test_tree_solver.cpp, AFreeBodysClosedFormIsThePassesAnswer).
// Anything else — redundant or weak rows, sliding contacts' friction rows
// (zero rows), more than 6 rows — goes to the passes.
#include "tree_solver/workspace.hpp"

#include <cmath>

namespace appell::detail {

namespace {

/// In-place LDLᵀ of the leading n × n of a (lower triangle read; the unit
/// factor L below the diagonal, D on it); inv_d gets 1/d_j. No square roots:
/// the acceptance test and the solve need only D and L. False when a pivot
/// is not positive.
bool ldlt(Mat6& a, int n, double inv_d[6]) {
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
void ldltSolve(const Mat6& l, const double inv_d[6], int n, double* x) {
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < i; ++k) x[i] -= l(i, k) * x[k];
  for (int i = 0; i < n; ++i) x[i] *= inv_d[i];
  for (int i = n - 1; i >= 0; --i)
    for (int k = i + 1; k < n; ++k) x[i] -= l(k, i) * x[k];
}

/// tr(S⁻¹) = tr(D⁻¹ L⁻¹ L⁻ᵀ) = Σᵢⱼ (L⁻¹)ᵢⱼ²/dᵢ for S = L D Lᵀ: the
/// ‖Ls⁻¹‖_F² of the Cholesky factor Ls = L D^½.
double inverseTrace(const Mat6& l, const double inv_d[6], int n) {
  double tr = 0;
  for (int c = 0; c < n; ++c) {  // column c of L⁻¹ (unit lower triangular)
    double x[6];
    x[c] = 1.0;
    tr += inv_d[c];
    for (int r = c + 1; r < n; ++r) {
      double s = 0;
      for (int k = c; k < r; ++k) s -= l(r, k) * x[k];
      x[r] = s;
      tr += s * s * inv_d[r];
    }
  }
  return tr;
}

}  // namespace

bool freeBodySolve(const Model& model, const Data& data, const ConstraintData& cdata,
                   TreeWorkspace& ws, bool impulse) {
  // The rows in the body frame, equilibrated, as the columns of Kt = (E K)ᵀ
  // (the first m of them); k_e = E k. A world covector (n, f) is (Rᵀ(n − p × f), Rᵀf)
  // in the body frame.
  Mat6 Kt;
  double k[6], e[6];
  int global[6];
  int m = 0;
  const Mat3 Rt = data.oMi[0].R.transpose();
  const Vec3& p = data.oMi[0].p;
  for (const TreeBlock& tb : ws.blocks) {
    if (tb.rows == 0) continue;
    if (cdata.isSliding(tb.constraint) || m + tb.rows > 6) return false;
    const RowBlock& blk = cdata.blocks[tb.constraint];
    const RowMatrix6& W = tb.sign > 0 ? blk.Wa : blk.Wb;
    for (int r = 0; r < tb.rows; ++r, ++m) {
      const Vec3 n = W.row(r).head<3>().transpose(), f = W.row(r).tail<3>().transpose();
      Kt.col(m).head<3>().noalias() = Rt * (n - p.cross(f));
      Kt.col(m).tail<3>().noalias() = Rt * f;
      const double nn = Kt.col(m).squaredNorm();
      if (!(nn > ws.options.rank_abs_tol * ws.options.rank_abs_tol))
        return false;  // a zero row: the passes drop it
      e[m] = 1.0 / std::sqrt(nn);
      Kt.col(m) *= tb.sign * e[m];
      k[m] = e[m] * tb.rhs[r];
      global[m] = tb.global + r;
    }
  }

  double inv_d[6];
  // z = L⁻¹ f₀, Y = L⁻¹ Kt, S = Yᵀ Y = E K I⁻¹ Kᵀ E, r = k_e − Yᵀ z (= k_e − E K a₀).
  const Mat6& Linv = ws.free_body_linv;
  Vec6 z = Vec6::Zero();
  if (!impulse) {
    const Vec6& v = data.v[0];
    z.noalias() = Linv * (ws.tau.head<6>() - crossForce(v, model.spatial_inertia[0] * v));
  }
  Mat6 Y, S;  // the first m columns, and the leading m × m
  double r[6];
  for (int i = 0; i < m; ++i) {
    Y.col(i).noalias() = Linv * Kt.col(i);
    r[i] = k[i] - Y.col(i).dot(z);
    for (int j = 0; j <= i; ++j) S(i, j) = Y.col(i).dot(Y.col(j));
  }
  if (m > 0) {
    if (!ldlt(S, m, inv_d)) return false;
    // Resolved whole? σ_min(L)/‖Ls⁻¹‖_F bounds the passes' test (above),
    // compared squared: λ_min(I) > kWeakPivot² tr(S⁻¹). When it is
    // inconclusive — a small or anisotropic body, where the bound loses
    // cond(L) — the passes' own quantity decides: the Gram factor's
    // 1/‖Lg⁻¹‖_F, i.e. 1 > kWeakPivot² tr(G⁻¹).
    constexpr double kWeak2 = kWeakPivot * kWeakPivot;
    if (!(ws.free_body_lambda_min > kWeak2 * inverseTrace(S, inv_d, m))) {
      Mat6 G;  // the leading m × m only: the factorisation reads no more
      double inv_g[6];
      for (int i = 0; i < m; ++i)
        for (int j = 0; j <= i; ++j) G(i, j) = Kt.col(i).dot(Kt.col(j));
      if (!ldlt(G, m, inv_g) || !(1.0 > kWeak2 * inverseTrace(G, inv_g, m))) return false;
    }
    ldltSolve(S, inv_d, m, r);  // r = μ_e
  }

  // a = L⁻ᵀ(z + Y μ_e); λ = E μ_e (the force on the body is K_eᵀ μ_e = Kᵀ E μ_e).
  for (int i = 0; i < m; ++i) z += r[i] * Y.col(i);
  const Vec6 a = Linv.transpose() * z;
  // Gravity-shifted (ABA's trick): q̈ = a − ᵖXᵢ a_world; a free joint's
  // velocity product v × S q̇ = v × v is zero.
  ws.vdot.head<6>() = a - data.liMi[0].actInv(ws.a_world);
  ws.lambda.setZero();
  for (int i = 0; i < m; ++i) ws.lambda[global[i]] = e[i] * r[i];
  ws.redundant = 0;
  ws.loop_rank = 0;
  return true;
}

}  // namespace appell::detail
