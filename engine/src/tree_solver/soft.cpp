// Tree solver, compliant rows: rows a joint can barely move are not resolved
// there but handed up with their compliance — delayed pivoting, as sparse
// direct solvers delay a small pivot to the parent front (Duff & Reid 1983);
// the Popov–Vereshchagin recursion carries all rows this way (Featherstone,
// "Rigid Body Dynamics Algorithms", 2008).
//
// Why: resolving a row at a joint with a small singular value σ of K S hands
// the parent a stiffness ~1/σ² (Pᵀ Ia P with |P| ~ 1/σ), and the parent's
// eliminations then lose about eps/σ⁴ — 10⁻⁵ at σ ≈ 10⁻³ where the dense
// solvers lose nothing. Instead, such a joint is eliminated exactly as in ABA
// with its rows carried (the saddle form of the subtree's problem):
//     D q̈ = u − Uᵀ ā − Gᵀ λ,   K a − Φ λ = k,   a = ā + S q̈,
// which leaves, in ā and λ only,
//     K' ā − Φ' λ = k',  K' = K − G D⁻¹ Uᵀ,  Φ' = Φ + G D⁻¹ Gᵀ,  k' = k − G D⁻¹ u,
// and the force IA' ā + pA' + K'ᵀ λ on the parent (IA', pA' as in ABA). D is
// an inertia, so nothing is divided by σ. Directions of Φ' = V Λ Vᵀ with Λ
// large are resolved here — λ₁ = Λ₁⁻¹(K'₁ ā − k'₁), a bounded stiffness
// K'₁ᵀ Λ₁⁻¹ K'₁ for the parent — and the others go up as rows with compliance
// Λ₂ until a joint that moves them well, or the root, resolves them. Only the
// nodes on such a row's path pay for it.
//
// Φ is kept as a square-root factor F (Φ = F Fᵀ, F' = [F, G L⁻ᵀ] with
// D = L Lᵀ) and split by the SVD of F, never formed: a compliance σ² ≈ 10⁻¹⁰
// next to one of order 1 keeps its relative accuracy (the eigenvalues of Φ
// itself would carry an absolute error eps‖Φ‖), and the rank tolerances apply
// to √Φ in the same units as to the rows.
#include "tree_solver/workspace.hpp"

#include <algorithm>
#include <cmath>

namespace appell::detail {

namespace {

/// Singular values of a compliance factor at or below this are zero: rows no
/// joint moves (hard, or redundant) — the solver's rank rule on √Φ.
double zeroTol(const SolverOptions& o, double smax) {
  return std::max(o.rank_abs_tol, o.rank_rel_tol * smax);
}

}  // namespace

bool softSegment(const TreeWorkspace& ws, const Node& nd, int e, const Segment& g) {
  if (g.kind == Segment::Previous) return nd.comp[e - 1].soft;
  if (g.kind == Segment::Child) return ws.nodes[g.id].softpass;
  return false;
}

int softCompress(TreeWorkspace& ws, int body, int e) {
  Node& nd = ws.nodes[body];
  Compression& cp = nd.comp[e];
  const int nb = cp.nrows, r = cp.rank, ndr = nb - r;
  // The stack's compliance factor, block diagonal by segment (own rows are
  // hard), equilibrated like the rows and carried through Q: F_t = Qᵀ E F.
  StackMat F = StackMat::Zero(nb, nb);
  int at = 0;
  for (int s = 0; s < cp.nseg; ++s) {
    const Segment& g = cp.seg[s];
    if (g.kind == Segment::Previous && nd.comp[e - 1].soft)
      F.block(at, at, g.rows, g.rows) = nd.comp[e - 1].F;
    else if (g.kind == Segment::Child && ws.nodes[g.id].softpass)
      F.block(at, at, g.rows, g.rows).diagonal() = ws.nodes[g.id].fpass;
    at += g.rows;
  }
  BufVec x(nb);
  for (int c = 0; c < nb; ++c) {
    x = cp.E.cwiseProduct(F.col(c));
    applyQt(cp, x);
    F.col(c) = x;
  }
  const double tol = zeroTol(ws.options, F.norm());

  // Dropped combinations: Φ_dk μ_k + Φ_dd μ_d = r_d with Φ = F_t F_tᵀ.
  // Directions of F_d = U_d Σ_d W_dᵀ with Σ above the tolerance are
  // eliminated here (μ_d follows from μ_k), the rest are redundant rows.
  cp.soft = true;
  cp.nelim = 0;
  StackMat Fk = F.topRows(r);
  if (ndr > 0) {
    ws.svd12.compute(F.bottomRows(ndr), Eigen::ComputeFullU | Eigen::ComputeThinV);
    const auto& sv = ws.svd12.singularValues();  // descending
    int ne = 0;
    while (ne < sv.size() && sv[ne] > tol) ++ne;
    cp.nelim = ne;
    cp.Ud = ws.svd12.matrixU();
    cp.sInv = sv.head(ne).cwiseInverse();
    const auto We = ws.svd12.matrixV().leftCols(ne);
    cp.FkWe.noalias() = Fk * We;
    Fk.noalias() -= cp.FkWe * We.transpose();  // F_k (1 − W_e W_eᵀ): Schur complement's factor
  }
  // Kept rows' factor, squared up to rank × rank: F = U Σ from the SVD of F_k.
  if (r > 0) {
    ws.svd12.compute(Fk, Eigen::ComputeFullU);
    cp.F = ws.svd12.matrixU() * ws.svd12.singularValues().asDiagonal();
  } else {
    cp.F.resize(0, 0);
  }
  return ndr - cp.nelim;
}

bool softCompressionRhs(Compression& cp, const BufVec& t, double tol, double& res) {
  const int r = cp.rank, ndr = cp.nrows - r, ne = cp.nelim;
  cp.rhs = t.head(r);
  cp.rd = t.tail(ndr);
  res = 0;
  if (ndr == 0) return true;
  BufVec y(ndr);
  y.noalias() = cp.Ud.transpose() * cp.rd;
  for (int k = ne; k < ndr; ++k) res = std::max(res, std::abs(y[k]));
  if (ne > 0) {
    // rhs_k = r_k − Φ_kd Φ_dd⁺ r_d = r_k − F_k W_e Σ_e⁻¹ U_eᵀ r_d.
    const BufVec z = cp.sInv.cwiseProduct(y.head(ne));
    cp.rhs.noalias() -= cp.FkWe * z;
  }
  return res <= tol;
}

void softDroppedMultipliers(const Compression& cp, BufVec& lam, bool homogeneous) {
  const int r = cp.rank, ndr = cp.nrows - r, ne = cp.nelim;
  lam.segment(r, ndr).setZero();
  if (ne == 0) return;
  // μ_d = Φ_dd⁺ (r_d − Φ_dk μ_k) = U_e Σ_e⁻¹ (Σ_e⁻¹ U_eᵀ r_d − W_eᵀ F_kᵀ μ_k);
  // zero along the redundant directions.
  BufVec y(ne);
  if (homogeneous) {
    y.noalias() = -cp.FkWe.transpose() * lam.head(r);
  } else {
    y.noalias() = cp.Ud.leftCols(ne).transpose() * cp.rd;
    y.array() *= cp.sInv.array();
    y.noalias() -= cp.FkWe.transpose() * lam.head(r);
  }
  y.array() *= cp.sInv.array();
  lam.segment(r, ndr).noalias() = cp.Ud.leftCols(ne) * y;
}

void splitSoft(TreeWorkspace& ws, const Joint& j, bool root, Node& nd, Mat6& H) {
  const SolverOptions& o = ws.options;
  const int nv = j.nv, nK = nd.nK;
  nd.soft = true;
  nd.rankG = 0;
  nd.nf = nv;
  nd.S2 = j.S;
  nd.V2.setIdentity(nv, nv);
  // F' = [F, G L⁻ᵀ]: Φ' = Φ + G D⁻¹ Gᵀ.
  const bool soft_in = nd.ncomp > 0 && nd.comp[nd.ncomp - 1].soft;
  StackMat Fp = StackMat::Zero(nK, nK + nv);
  if (soft_in) Fp.leftCols(nK) = nd.comp[nd.ncomp - 1].F;
  KRows Kp = nd.K;
  Mat6 IAp = nd.IA;
  double d = 0;  // the joint's inertia scale: when to resolve a direction here
  if (nv > 0) {
    nd.U.noalias() = nd.IA * j.S;
    SmallMat D(nv, nv);
    D.noalias() = j.S.transpose() * nd.U;
    const Eigen::LLT<SmallMat> llt(D);
    nd.Dinv = llt.solve(SmallMat::Identity(nv, nv));
    d = D.diagonal().maxCoeff();
    SmallMat G(nK, nv);
    G.noalias() = nd.K * j.S;
    nd.GD.noalias() = G * nd.Dinv;
    SmallMat Gt = G.transpose();
    llt.matrixL().solveInPlace(Gt);  // L⁻¹ Gᵀ
    Fp.rightCols(nv) = Gt.transpose();
    Kp.noalias() -= nd.GD * nd.U.transpose();
    IAp.noalias() -= nd.U * nd.Dinv * nd.U.transpose();
  } else {
    nd.GD.resize(nK, 0);
    nd.Dinv.resize(0, 0);
    nd.U.resize(6, 0);
    d = nd.IA.diagonal().maxCoeff();
  }
  ws.svd12.compute(Fp, Eigen::ComputeFullU);
  const auto& sv = ws.svd12.singularValues();  // descending, nK of them
  const double zero = zeroTol(o, nK > 0 ? sv[0] : 0.0);
  // Resolve Σ²·d ≥ kWeakPivot² (for one DoF and hard rows, σ ≥ kWeakPivot with
  // Σ² = σ²/D); the root resolves every direction with compliance.
  const double resolve = root ? zero : std::max(zero, kWeakPivot / std::sqrt(d));
  int n1 = 0;
  while (n1 < nK && sv[n1] > resolve) ++n1;
  const int n2 = nK - n1;
  // Vphi = [handed up | resolved]: the order the passes index by.
  const auto& Uf = ws.svd12.matrixU();
  nd.Vphi.resize(nK, nK);
  nd.Vphi.leftCols(n2) = Uf.rightCols(n2);
  nd.Vphi.rightCols(n1) = Uf.leftCols(n1);
  nd.npass = n2;
  nd.fpass.resize(n2);
  nd.softpass = false;
  for (int k = 0; k < n2; ++k) {
    const double f = sv[n1 + k];
    nd.fpass[k] = f > zero ? f : 0.0;
    nd.softpass |= nd.fpass[k] > 0;
  }
  nd.u2form = U2Form::Explicit;
  nd.U2 = nd.Vphi.leftCols(n2);
  nd.Kpass.noalias() = nd.U2.transpose() * Kp;
  nd.Kel.noalias() = nd.Vphi.rightCols(n1).transpose() * Kp;
  nd.lamInv = sv.head(n1).array().square().inverse().matrix();
  if (root) return;
  H = IAp;
  for (int k = 0; k < n1; ++k) {
    const Vec6 w = Eigen::Map<const Vec6>(nd.Kel.data() + 6 * k);
    H.noalias() += (nd.lamInv[k] * w) * w.transpose();
  }
  H = 0.5 * (H + H.transpose()).eval();
}

void softBias(const Joint& j, Node& nd, const VecX& tau, Vec6& pa) {
  const int nv = j.nv, n2 = nd.npass, n1 = nd.nK - n2;
  KVec kp = nd.k;
  pa = nd.pA;
  if (nv > 0) {
    nd.u = tau.segment(j.idx_v, nv);
    nd.u.noalias() -= j.S.transpose() * nd.pA;
    KVec ud(nv);
    ud.noalias() = nd.Dinv * nd.u;
    pa.noalias() += nd.U * ud;
    kp.noalias() -= nd.GD * nd.u;
  }
  nd.kv.noalias() = nd.Vphi.transpose() * kp;
  if (n1 > 0) {
    const KVec y = nd.lamInv.cwiseProduct(nd.kv.tail(n1));
    pa.noalias() -= nd.Kel.transpose() * y;
  }
}

void softForward(const Joint& j, Node& nd, const Vec6& abar, VecX& vdot) {
  const int nv = j.nv, n2 = nd.npass, n1 = nd.nK - n2;
  // The multipliers μ = −λ (the solver's sign: the rows' force on the body
  // is −Kᵀμ): μ = V₂ ν − V₁ λ₁,  λ₁ = Λ₁⁻¹ (K'₁ ā − k'₁).
  KVec& mu = nd.comp[nd.ncomp - 1].mu;
  mu.setZero(nd.nK);
  if (n1 > 0) {
    KVec l1(n1);
    l1.noalias() = nd.Kel * abar;
    l1 -= nd.kv.tail(n1);
    l1.array() *= nd.lamInv.array();
    mu.noalias() -= nd.Vphi.rightCols(n1) * l1;
  }
  if (n2 > 0) mu.noalias() += nd.U2 * nd.nu;
  // q̈ = D⁻¹(u − Uᵀ ā) − (G D⁻¹)ᵀ λ,  a = ā + S q̈.
  nd.a = abar;
  if (nv == 0) return;
  auto qdd = vdot.segment(j.idx_v, nv);
  KVec z = nd.u;
  z.noalias() -= nd.U.transpose() * abar;
  qdd.noalias() = nd.Dinv * z;
  qdd.noalias() += nd.GD.transpose() * mu;
  nd.a.noalias() += j.S * qdd;
}

}  // namespace appell::detail
