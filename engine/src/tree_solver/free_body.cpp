// Tree solver, the one-free-body case (a ball, a disk, a top, an ellipsoid:
// a model that is one body on a floating joint, every row its own). There
// Gauss' principle is one rigid body's, solved in closed form:
//   I a = f₀ + Kᵀ μ,   K a = k,   f₀ = τ − v ×* I v,
//   a₀ = I⁻¹ f₀,   (K I⁻¹ Kᵀ) μ = k − K a₀,   a = a₀ + I⁻¹ Kᵀ μ,
// with I = L Lᵀ (Model::spatial_inertia_factor) and Y = L⁻¹ Kᵀ, so that
// K I⁻¹ Kᵀ = Yᵀ Y and a = L⁻ᵀ(L⁻¹ f₀ + Y μ). I is constant in the body's
// frame, so L⁻¹ is formed once (TreeSolver's constructor) and a solve is
// m + 2 fixed-size 6 × 6 matrix-vector products and an m × m LDLᵀ
// factorisation (m ≤ 6 rows): the general passes' answer without their
// dynamic-size machinery (compression, split, articulated inertia), and
// without a square root — their latency, not the flops, bounded this path.
//
// It is taken only where it is that answer. The rows, equilibrated (E K,
// E = diag(1/‖kᵢ‖)), must be resolved whole by the free joint, which the
// general passes decide by 1/‖R⁻¹‖_F > kWeakPivot on the compression's
// triangular factor (backward.cpp, freeSplit) — with R the factor of E K's
// QR, ‖R⁻¹‖_F² = tr((E K Kᵀ E)⁻¹). Here the bound comes from the factor the
// solve needs anyway, S = YᵀY = K I⁻¹ Kᵀ = L D Lᵀ: since I⁻¹ ⪯ Id/λ_min(I),
//     tr((E S E)⁻¹) ≥ λ_min(I) tr((E K Kᵀ E)⁻¹),
// so λ_min(I) > kWeakPivot² tr((E S E)⁻¹) implies the passes' test
// (λ_min(I) is formed once; tr((E S E)⁻¹) = Σᵢ ‖kᵢ‖² (S⁻¹)ᵢᵢ needs L, D and
// the rows' squared norms only). The bound loses up to cond(I) (a 1 g ball
// of 1 cm: 160²), so where it fails the Gram matrix K Kᵀ, factored the same
// way, decides as the passes do: tr((E K Kᵀ E)⁻¹) = ‖R⁻¹‖_F². The closed
// form thus accepts exactly what the passes resolve whole, and pays for the
// second factorisation only near the threshold or on such bodies. Then no
// row is redundant, λ is unique, and the result agrees with the passes to
// round-off (tests/test_tree_solver.cpp,
// AFreeBodysClosedFormIsThePassesAnswer). Anything else — redundant or weak
// rows, sliding contacts' friction rows (zero rows), more than 6 rows — goes
// to the passes.
#include "tree_solver/ldlt.hpp"
#include "tree_solver/workspace.hpp"

#include <cmath>

namespace appell::detail {

bool freeBodySolve(const Model& model, const Data& data, const ConstraintData& cdata,
                   TreeWorkspace& ws, bool impulse) {
  // The rows in the body frame as the columns of Kt = Kᵀ (the first m of
  // them): a world covector (n, f) is (Rᵀ(n − p × f), Rᵀf) there. Their
  // squared norms w2 = 1/eᵢ² give the equilibration E, which only the
  // acceptance test needs (the LDLᵀ solve is invariant under diagonal
  // scaling: van der Sluis 1969).
  Mat6 Kt;
  double k[6], w2[6];
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
      const Vec3 n = tb.sign * W.row(r).head<3>().transpose();
      const Vec3 f = tb.sign * W.row(r).tail<3>().transpose();
      Kt.col(m).head<3>().noalias() = Rt * (n - p.cross(f));
      Kt.col(m).tail<3>().noalias() = Rt * f;
      w2[m] = Kt.col(m).squaredNorm();
      if (!(w2[m] > ws.options.rank_abs_tol * ws.options.rank_abs_tol))
        return false;  // a zero row: the passes drop it
      k[m] = tb.rhs[r];
      global[m] = tb.global + r;
    }
  }

  double inv_d[6];
  // z = L⁻¹ f₀, Y = L⁻¹ Kt, S = Yᵀ Y = K I⁻¹ Kᵀ, r = k − Yᵀ z (= k − K a₀).
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
    // Resolved whole? σ_min(L)/‖(E S E)⁻½‖_F bounds the passes' test
    // (above), compared squared: λ_min(I) > kWeakPivot² tr((E S E)⁻¹). When
    // it is inconclusive — a small or anisotropic body, where the bound
    // loses cond(I) — the passes' own quantity decides: the equilibrated
    // Gram matrix's tr((E K Kᵀ E)⁻¹) = ‖R⁻¹‖_F² < 1/kWeakPivot².
    constexpr double kWeak2 = kWeakPivot * kWeakPivot;
    if (!(ws.free_body_lambda_min > kWeak2 * equilibratedInverseTrace(S, inv_d, w2, m))) {
      Mat6 G;  // the leading m × m only: the factorisation reads no more
      double inv_g[6];
      for (int i = 0; i < m; ++i)
        for (int j = 0; j <= i; ++j) G(i, j) = Kt.col(i).dot(Kt.col(j));
      if (!ldlt(G, m, inv_g) || !(1.0 > kWeak2 * equilibratedInverseTrace(G, inv_g, w2, m)))
        return false;
    }
    ldltSolve(S, inv_d, m, r);  // r = μ = λ
  }

  // a = L⁻ᵀ(z + Y λ).
  for (int i = 0; i < m; ++i) z += r[i] * Y.col(i);
  const Vec6 a = Linv.transpose() * z;
  // Gravity-shifted (ABA's trick): q̈ = a − ᵖXᵢ a_world; a free joint's
  // velocity product v × S q̇ = v × v is zero.
  ws.vdot.head<6>() = a - data.liMi[0].actInv(ws.a_world);
  ws.lambda.setZero();
  for (int i = 0; i < m; ++i) ws.lambda[global[i]] = r[i];
  ws.redundant = 0;
  ws.loop_rank = 0;
  return true;
}

}  // namespace appell::detail
