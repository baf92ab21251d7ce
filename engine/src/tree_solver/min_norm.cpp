// Tree solver, the minimum-norm λ (the contract of constrained_dynamics.hpp):
//
//     λ = argmin ‖λ‖  subject to  Aᵀλ = Aᵀλ₀,
//
// λ₀ being the multipliers of the passes. When A has full row rank λ₀ is the
// only solution and nothing is done. Otherwise null(Aᵀ) is spanned by
//   - the dropped combinations of each compression with no compliance: their
//     stacked rows' force vanishes (Q₂ᵀ E B = 0), and unrolled down the tree
//     with the adjoints of the passes they move no acceleration;
//   - the combinations a root hands to the world (no joint moves them);
//   - the loop closure's redundant directions (Z v = 0: the loop force B_Lᵀv is
//     absorbed by the tree rows, the tree multipliers L v absorb it).
// The passes set the first two kinds' multipliers t to zero, which is the
// minimum-norm choice only within a compression. Here they are chosen
// globally, by the same dynamic programming as the passes: the λ of every
// row below body i is affine in the multipliers δν of the rows i handed up
// (and in the free t of i's subtree), so the least-squares cost of its subtree
//     Vᵢ(δν) = min_t ½ Σ_{rows below i} (λ_r + δλ_r)² = ½‖Rᵢ δν + ρᵢ‖² + const
// is a quadratic in at most 6 unknowns, kept in square-root form (Rᵢ square,
// from a Householder QR of the stack's least-squares system — no normal
// equations; the square-root information form of sequential least squares,
// Bierman, "Factorization Methods for Discrete Sequential Estimation", 1977). A compression's stacked multipliers are δλ = E Q [δμ; D δμ + Z t]
// (D: the eliminated compliant directions, zero for hard rows; Z: the free
// directions), each stacked segment weighted by its cost-to-go (own rows:
// 1; a child: R_c; the previous compression: its R). Leaves to root the QR
// eliminates t and hands Vᵢ up; root to leaves the optimal t and δν are
// replayed into λ. The loop directions are then made orthogonal to the tree
// ones with the same operation, and removed by a projection on their span
// (modified Gram–Schmidt, applied twice: Giraud, Langou & Rozložník, 2005).
//
// Cost: only the bodies whose λ free multipliers move (the free bodies and
// the chains of handed-up rows below them) take part, each with one QR of its
// stack (at most 12 × 13; the last compression's kept unknowns are taken as
// the handed-up δν directly, δμ = U₂ δν): O(n) however many rows are
// redundant, O(k m) more per redundant loop direction, nothing when no row
// is redundant. Nothing allocates (every size is bounded at compile time or
// by the constructor).
#include "tree_solver/workspace.hpp"

#include <cmath>

namespace appell::detail {

namespace {

/// Householder triangularisation of the first `nvar` columns of F (all
/// columns transformed): F ← Qᵀ F with Qᵀ F[:, 0:nvar] upper trapezoidal.
/// Q is not kept: F is a least-squares system ‖F [x; 1]‖, whose minimiser
/// and residual Q does not change.
void triangularize(LsSystem& F, int nvar) {
  const int nr = F.rows, nc = F.cols;
  for (int k = 0; k < nvar && k < nr; ++k) {
    double* ck = F.col[k];
    double s2 = 0;
    for (int r = k; r < nr; ++r) s2 += ck[r] * ck[r];
    if (s2 == 0) continue;
    const double alpha = ck[k], norm = std::sqrt(s2);
    const double beta = alpha >= 0 ? -norm : norm;
    const double uk = alpha - beta;  // u = [uk, ck(k+1:)], H = 1 − γ u uᵀ
    const double gamma = 1.0 / (-beta * uk);
    for (int c = k + 1; c < nc; ++c) {
      double* cj = F.col[c];
      double d = uk * cj[k];
      for (int r = k + 1; r < nr; ++r) d += ck[r] * cj[r];
      d *= gamma;
      cj[k] -= d * uk;
      for (int r = k + 1; r < nr; ++r) cj[r] -= d * ck[r];
    }
    ck[k] = beta;
    for (int r = k + 1; r < nr; ++r) ck[r] = 0;
  }
}

/// x = −R⁻¹ (B y + b) with F = [R B b], R upper triangular n × n (y may be
/// empty). A zero pivot (a free direction no row sees) leaves x_r at zero.
template <typename Mat, typename Vec>
void backSolve(const Mat& F, int n, const KVec& y, Vec& x) {
  const int ny = static_cast<int>(y.size());
  for (int r = n - 1; r >= 0; --r) {
    double s = F(r, n + ny);
    for (int c = 0; c < ny; ++c) s += F(r, n + c) * y[c];
    for (int c = r + 1; c < n; ++c) s += F(r, c) * x[c];
    x[r] = F(r, r) != 0 ? -s / F(r, r) : 0.0;
  }
}

/// The cost-to-go weight of stacked segment s: own rows 1 (nullptr), a
/// child's R_c, the previous compression's R (upper triangular).
const SmallMat* segmentWeight(const TreeWorkspace& ws, const Node& nd, int e, const Segment& g) {
  if (g.kind == Segment::Block) return nullptr;
  return g.kind == Segment::Child ? &ws.nodes[g.id].mnR : &nd.comp[e - 1].mnR;
}

/// Stacked multipliers E Q [δμ; D δμ + Z t] of compression cp.
void stacked(const Compression& cp, const KVec& dmu, const BufVec& t, BufVec& y) {
  const int r = cp.rank, nb = cp.nrows;
  y.setZero(nb);
  y.head(r) = dmu;
  if (cp.soft) {
    softDroppedMultipliers(cp, y, true);
    if (cp.nfree > 0) y.segment(r, nb - r).noalias() += cp.Ud.middleCols(cp.nelim, cp.nfree) * t;
  } else {
    y.segment(r, cp.nfree) += t;
  }
  applyQ(cp, y);
  y.array() *= cp.E.array();
}

/// What the kept rows' δμ of a compression is made of in its least-squares
/// system: themselves (a compression followed by another), the handed-up
/// rows' δν (δμ = U₂ δν, the last compression of a body whose parent takes
/// part), or nothing (δμ = 0).
enum class Kept { Mu, Nu, None };

int keptCount(const Node& nd, const Compression& cp, Kept kept) {
  return kept == Kept::Mu ? cp.rank : kept == Kept::Nu ? nd.npass : 0;
}

/// The columns of the hard rows' least-squares system (D = 0, Z = the
/// dropped coordinates): G = W E Q, Q applied from the right to the rows of
/// the block-diagonal W E. Its dropped columns are the t columns, its kept
/// columns G₁ the δμ ones (G₁ U₂ the δν ones).
void hardColumns(const TreeWorkspace& ws, const Node& nd, int e, const Compression& cp, Kept kept, LsSystem& F) {
  const int r = cp.rank, z = cp.nfree, nb = cp.nrows, nk = keptCount(nd, cp, kept);
  double G[12][12];
  int at = 0;
  for (int s = 0; s < cp.nseg; ++s) {
    const Segment& g = cp.seg[s];
    const SmallMat* W = segmentWeight(ws, nd, e, g);
    for (int a = 0; a < g.rows; ++a) {
      double* row = G[at + a];
      for (int b = 0; b < nb; ++b) row[b] = 0;
      if (!W) {
        row[at + a] = cp.E[at + a];
        continue;
      }
      for (int b = a; b < g.rows; ++b) row[at + b] = (*W)(a, b) * cp.E[at + b];
    }
    at += g.rows;
  }
  for (int k = 0; k < cp.f.rank; ++k) {  // G ← G H_k, H_k = 1 − τ v vᵀ, v = [0…0, 1, essential]
    const double tau = cp.f.tau[k];
    const int pk = cp.f.perm[k];
    double v[12];
    for (int b = k + 1; b < nb; ++b) v[b] = cp.f.a[b][pk];
    for (int a = 0; a < nb; ++a) {
      double* row = G[a];
      double d = row[k];
      for (int b = k + 1; b < nb; ++b) d += row[b] * v[b];
      if (d == 0) continue;
      d *= tau;
      row[k] -= d;
      for (int b = k + 1; b < nb; ++b) row[b] -= d * v[b];
    }
  }
  for (int a = 0; a < nb; ++a)
    for (int c = 0; c < z; ++c) F.col[c][a] = G[a][r + c];
  if (kept == Kept::Mu) {
    for (int a = 0; a < nb; ++a)
      for (int c = 0; c < r; ++c) F.col[z + c][a] = G[a][c];
  } else if (kept == Kept::Nu) {
    switch (nd.u2form) {
      case U2Form::Identity:
        for (int a = 0; a < nb; ++a)
          for (int c = 0; c < nk; ++c) F.col[z + c][a] = G[a][c];
        break;
      case U2Form::Reflector:  // U₂ = columns 1… of 1 − β u uᵀ
        for (int a = 0; a < nb; ++a) {
          double gu = 0;
          for (int c = 0; c < r; ++c) gu += G[a][c] * nd.hu[c];
          gu *= nd.hbeta;
          for (int c = 0; c < nk; ++c) F.col[z + c][a] = G[a][c + 1] - gu * nd.hu[c + 1];
        }
        break;
      case U2Form::Explicit:
        for (int a = 0; a < nb; ++a)
          for (int c = 0; c < nk; ++c) {
            double v = 0;
            for (int b = 0; b < r; ++b) v += G[a][b] * nd.U2(b, c);
            F.col[z + c][a] = v;
          }
        break;
    }
  }
}

/// The columns of compliant rows: the stacked multipliers of each unit
/// unknown, weighted segment by segment.
void softColumns(const TreeWorkspace& ws, const Node& nd, int e, const Compression& cp, Kept kept, LsSystem& F) {
  const int r = cp.rank, z = cp.nfree, nk = keptCount(nd, cp, kept);
  BufVec y;
  KVec dmu(r), unit(nk);
  BufVec t(z);
  for (int c = 0; c < z + nk; ++c) {
    dmu.setZero();
    t.setZero();
    if (c < z) {
      t[c] = 1;
    } else if (kept == Kept::Mu) {
      dmu[c - z] = 1;
    } else {
      unit.setZero();
      unit[c - z] = 1;
      addU2(nd, unit, dmu);
    }
    stacked(cp, dmu, t, y);
    int at = 0;
    for (int s = 0; s < cp.nseg; ++s) {
      const Segment& g = cp.seg[s];
      const SmallMat* W = segmentWeight(ws, nd, e, g);
      for (int a = 0; a < g.rows; ++a) {
        double v = W ? 0.0 : y[at + a];
        if (W)
          for (int b = a; b < g.rows; ++b) v += (*W)(a, b) * y[at + b];
        F.col[c][at + a] = v;
      }
      at += g.rows;
    }
  }
}

/// A locked joint's rows (tree_solver/locked.cpp) as one more row of the
/// system: their force ℓ moves with the kept multipliers, δℓ = −(K s)ᵀ δμ,
/// δμ = U₂ δν, and their λ = c ℓ / Σc² costs (ℓ + δℓ)² / Σc².
void lockedJointRow(const Node& nd, int z, int nk, const VecX& lambda, LsSystem& F) {
  const int nb = F.rows, nvar = z + nk;
  const double w = 1.0 / std::sqrt(nd.c2);
  for (int c = 0; c < z; ++c) F.col[c][nb] = 0;
  KVec unit(nk), dmu(nd.nK);
  for (int c = 0; c < nk; ++c) {
    unit.setZero();
    unit[c] = 1;
    dmu.setZero();
    addU2(nd, unit, dmu);
    F.col[z + c][nb] = -w * nd.gl.dot(dmu);
  }
  double ell = 0;
  for (const JointRow& jr : nd.jrows)
    if (jr.active) ell += jr.c * lambda[jr.global];
  F.col[nvar][nb] = w * ell;
  F.rows = nb + 1;
}

/// Leaves to root at compression e of body i: the least-squares system of
/// its stack in [t; kept unknowns] — the stacked multipliers E Q [δμ; D δμ +
/// Z t], each segment weighted by its cost-to-go, against the right side ρ —
/// triangularised; keeps the rows fixing t and the cost-to-go of the kept
/// unknowns (in the compression for Kept::Mu, in the body for Kept::Nu).
void costOfCompression(TreeWorkspace& ws, int i, int e, Kept kept, const VecX& lambda) {
  Node& nd = ws.nodes[i];
  Compression& cp = nd.comp[e];
  const int z = cp.nfree, nk = keptCount(nd, cp, kept);
  const int nvar = z + nk;
  LsSystem& F = ws.mnF;
  F.rows = cp.nrows;
  F.cols = nvar + 1;
  if (!cp.soft)
    hardColumns(ws, nd, e, cp, kept, F);
  else
    softColumns(ws, nd, e, cp, kept, F);
  // The right side: the current λ of own rows, the children's and the previous ρ.
  int at = 0;
  for (int s = 0; s < cp.nseg; ++s) {
    const Segment& g = cp.seg[s];
    const double* in = g.kind == Segment::Block   ? lambda.data() + ws.blocks[g.id].global
                       : g.kind == Segment::Child ? ws.nodes[g.id].mnRho.data()
                                                  : nd.comp[e - 1].mnRho.data();
    for (int k = 0; k < g.rows; ++k) F.col[nvar][at + k] = in[k];
    at += g.rows;
  }
  if (nd.locked && e == nd.ncomp - 1 && kept == Kept::Nu) lockedJointRow(nd, z, nk, lambda, F);
  triangularize(F, nvar);
  cp.mnTop.resize(z, nvar + 1);
  for (int c = 0; c <= nvar; ++c)
    for (int a = 0; a < z; ++a) cp.mnTop(a, c) = F.col[c][a];
  if (kept == Kept::None) return;
  SmallMat& R = kept == Kept::Mu ? cp.mnR : nd.mnR;
  KVec& rho = kept == Kept::Mu ? cp.mnRho : nd.mnRho;
  R.resize(nk, nk);
  rho.resize(nk);
  for (int a = 0; a < nk; ++a) {
    for (int c = 0; c < nk; ++c) R(a, c) = F.col[z + c][z + a];
    rho[a] = F.col[nvar][z + a];
  }
}

/// Whether body i's handed-up rows take part: their δν is free (a root's
/// rows to the world) or set by a parent that takes part.
bool handsUp(const Model& model, const TreeWorkspace& ws, int i) {
  const int p = model.parent[i];
  return ws.nodes[i].npass > 0 && (p < 0 || ws.nodes[p].mn_active);
}

/// Root to leaves at body i: δν, then each compression's optimal t and its
/// stacked δλ — added to own rows' λ, handed to the children and the previous
/// compression.
void replayNode(const Model& model, TreeWorkspace& ws, int i, VecX& lambda) {
  Node& nd = ws.nodes[i];
  if (nd.ncomp == 0) return;
  const bool up = handsUp(model, ws, i);
  KVec dnu(up ? nd.npass : 0);
  if (up && model.parent[i] < 0) {  // rows handed to the world: δν = −R⁻¹ρ
    for (int r = nd.npass - 1; r >= 0; --r) {
      double s = nd.mnRho[r];
      for (int c = r + 1; c < nd.npass; ++c) s += nd.mnR(r, c) * dnu[c];
      dnu[r] = nd.mnR(r, r) != 0 ? -s / nd.mnR(r, r) : 0.0;
    }
  } else if (up) {
    dnu = nd.dnu;
  }
  KVec& top = nd.comp[nd.ncomp - 1].dmu;
  top.setZero(nd.nK);
  if (up) addU2(nd, dnu, top);
  if (up && nd.locked) {  // the locked joint's rows follow: δℓ = −(K s)ᵀ δμ
    const double dl = -nd.gl.dot(top);
    for (const JointRow& jr : nd.jrows)
      if (jr.active) lambda[jr.global] += jr.c * dl / nd.c2;
  }
  for (int e = nd.ncomp - 1; e >= 0; --e) {
    Compression& cp = nd.comp[e];
    BufVec t(cp.nfree), y;
    backSolve(cp.mnTop, cp.nfree, e == nd.ncomp - 1 ? dnu : cp.dmu, t);
    stacked(cp, cp.dmu, t, y);
    const double* in = y.data();
    for (int s = 0; s < cp.nseg; ++s) {
      const Segment& g = cp.seg[s];
      if (g.kind == Segment::Block) {
        double* out = lambda.data() + ws.blocks[g.id].global;
        for (int k = 0; k < g.rows; ++k) out[k] += in[k];
      } else {
        KVec& d = g.kind == Segment::Child ? ws.nodes[g.id].dnu : nd.comp[e - 1].dmu;
        d = Eigen::Map<const KVec>(in, g.rows);
      }
      in += g.rows;
    }
  }
}

/// The bodies whose λ the free multipliers move: each free body and, below
/// it, the chains of handed-up rows. Parents come first (each search starts
/// from a body with a smaller index than anything it reaches).
void findRegion(const Model& model, TreeWorkspace& ws) {
  ws.nregion = 0;
  for (int s = ws.nseeds - 1; s >= 0; --s) {  // seeds were recorded leaves first
    const int seed = ws.seeds[s];
    if (ws.nodes[seed].mn_active) continue;
    int head = ws.nregion;
    ws.nodes[seed].mn_active = true;
    ws.region[ws.nregion++] = seed;
    while (head < ws.nregion) {
      const int i = ws.region[head++];
      for (int c : model.children[i]) {
        Node& cn = ws.nodes[c];
        if (cn.npass == 0 || cn.mn_active) continue;
        cn.mn_active = true;
        ws.region[ws.nregion++] = c;
      }
    }
  }
}

/// x ← x minus its projection on the tree rows' free directions.
void projectTree(const Model& model, TreeWorkspace& ws, VecX& x) {
  for (int k = ws.nregion - 1; k >= 0; --k) {
    const int i = ws.region[k];
    const Node& nd = ws.nodes[i];
    const bool up = handsUp(model, ws, i);
    for (int e = 0; e < nd.ncomp; ++e)
      costOfCompression(ws, i, e, e < nd.ncomp - 1 ? Kept::Mu : up ? Kept::Nu : Kept::None, x);
  }
  for (int k = 0; k < ws.nregion; ++k) replayNode(model, ws, ws.region[k], x);
}

}  // namespace

void minimumNorm(const Model& model, TreeWorkspace& ws, VecX& lambda) {
  if (ws.nseeds > 0) {
    findRegion(model, ws);
    projectTree(model, ws, lambda);
  }
  const int k = static_cast<int>(ws.loops.size()), dl = k - ws.loop_rank;
  if (dl > 0) {
    // Loop directions: v = scale ⊙ V₂ (unscaled loop multipliers) with the
    // tree multipliers L v that absorb their force; made orthogonal to the
    // tree directions, then orthonormalised (modified Gram–Schmidt, twice).
    const auto& V = ws.z_svd.matrixV();
    for (int j = 0; j < dl; ++j) {
      auto n = ws.loop_null.col(j);
      ws.loop_tmp = ws.loop_scale.cwiseProduct(V.col(ws.loop_rank + j));
      n.noalias() = ws.L * ws.loop_tmp;
      for (int l = 0; l < k; ++l) n[ws.loops[l].global] = ws.loop_tmp[l];
      if (ws.nseeds > 0) {
        ws.lambda0 = n;  // free after the loop closure
        projectTree(model, ws, ws.lambda0);
        n = ws.lambda0;
      }
    }
    for (int pass = 0; pass < 2; ++pass)
      for (int j = 0; j < dl; ++j) {
        auto n = ws.loop_null.col(j);
        for (int i = 0; i < j; ++i) n -= ws.loop_null.col(i).dot(n) * ws.loop_null.col(i);
        const double nn = n.norm();
        if (nn > 0) n /= nn;
      }
    for (int j = 0; j < dl; ++j) lambda -= ws.loop_null.col(j).dot(lambda) * ws.loop_null.col(j);
  }
  for (int k2 = 0; k2 < ws.nregion; ++k2) ws.nodes[ws.region[k2]].mn_active = false;
  ws.nregion = 0;
}

}  // namespace appell::detail
