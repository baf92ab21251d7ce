// Tree solver, backward passes (leaves → root). See docs/tree-solver.md.
//
// factorPass: everything that depends on the pose and the rows but not on the
// right sides — row compression, the split of each joint by K S (a norm and a
// reflector for one DoF, the compression's triangular factor for a free
// joint, an SVD otherwise), and the articulated inertias with the
// particular/free coupling kept.
// biasPass: the right sides — articulated bias forces and the right sides of
// the compressed and handed-up rows; it can be replayed cheaply for the unit
// solves of the loop closure and for the impulse solve.
#include "tree_solver/ldlt.hpp"
#include "tree_solver/workspace.hpp"

#include <algorithm>
#include <cmath>

namespace appell::detail {

namespace {

/// Writes `rows` (r × 6) into rows at..at+r of the QR's stack.
void stackRows(PivotedQR& qr, int at, const KRows& rows) {
  for (int r = 0; r < rows.rows(); ++r) Eigen::Map<Vec6>(qr.a[at + r]) = rows.row(r).transpose();
}

/// Below this, λ_min of the equilibrated Gram matrix is not trusted to certify
/// independent rows (its round-off is ~1e-15; σ_min ≥ 1e-4 is far from it).
constexpr double kIndependentFloor = 1e-8;

/// Whether a pivoted QR of the nb ≤ 6 equilibrated rows in qr.a would keep
/// every row, certified without it: with unit rows, the next pivot norm of
/// step k is at least σ_min/√6 (each row of the unreduced block keeps
/// ‖yᵀ R₂₂‖ ≥ σ_min), and the rank threshold is at most
/// thr = max(abs_tol, rel_tol √nb) (|R₀₀| ≤ ‖E B‖_F = √nb), so
/// λ_min > 6 thr² suffices, and λ_min ≥ 1/tr(G⁻¹) for the Gram matrix
/// G = E B Bᵀ E (LDLᵀ, ldlt.hpp). Costs nb(nb+1)/2 dot products and an
/// nb × nb LDLᵀ, with no square root and no serial pivot search.
bool independentRows(const SolverOptions& o, const PivotedQR& qr, int nb) {
  Mat6 G;
  for (int r = 0; r < nb; ++r) {
    const Eigen::Map<const Vec6> x(qr.a[r]);
    for (int c = 0; c <= r; ++c) G(r, c) = x.dot(Eigen::Map<const Vec6>(qr.a[c]));
  }
  double inv_d[6];
  if (!ldlt(G, nb, inv_d)) return false;
  constexpr double ones[6] = {1, 1, 1, 1, 1, 1};  // the rows are unit already
  const double thr2 = std::max(o.rank_abs_tol * o.rank_abs_tol,
                               o.rank_rel_tol * o.rank_rel_tol * nb);
  return equilibratedInverseTrace(G, inv_d, ones, nb) * std::max(6 * thr2, kIndependentFloor) < 1;
}

/// Rank-revealing compression of the `nb` rows stacked in cp.f:
/// equilibrate each row (rows already below the absolute tolerance are left
/// alone, so round-off residue of a redundant row is never blown up into a
/// fake constraint), then Householder QR with column pivoting, Qᵀ E B Π = R,
/// stopped at the numerical rank (pivoted_qr.hpp). Sets out = Q₁ᵀ E B = R₁ Πᵀ
/// — read off R, no product with Q.
///
/// With `whole` (the stack is the body's only one and one segment, it
/// carries no compliance and its K need not be triangular: not a free joint,
/// whose split reads R₁₁) and rows certified independent (independentRows), the QR is skipped:
/// Q = 1, no reflector (cp.f.rank = 0), out = E B. The QR would have kept
/// every row, and any basis of the same row space serves the split.
void compress(const SolverOptions& o, Compression& cp, int nb, KRows& out, bool whole,
              int& certified) {
  PivotedQR& qr = cp.f;
  cp.nrows = nb;
  cp.E.resize(nb);
  bool all_unit = true;
  for (int r = 0; r < nb; ++r) {
    Eigen::Map<Vec6> row(qr.a[r]);
    const double n = row.norm();
    const bool scaled = n > o.rank_abs_tol;
    all_unit = all_unit && scaled;
    const double e = scaled ? 1.0 / n : 1.0;
    cp.E[r] = e;
    row *= e;
  }
  if (whole && all_unit && nb <= 6 && independentRows(o, qr, nb)) {
    ++certified;
    qr.rank = 0;
    cp.rank = nb;
    out.resize(nb, 6);
    for (int r = 0; r < nb; ++r) out.row(r) = Eigen::Map<const Vec6>(qr.a[r]).transpose();
    return;
  }
  qr.factor(nb, o.rank_abs_tol, o.rank_rel_tol);
  const int rank = qr.rank;
  cp.rank = rank;
  out.setZero(rank, 6);
  for (int c = 0; c < 6; ++c)
    for (int r = 0; r <= std::min(c, rank - 1); ++r) out(r, qr.perm[c]) = qr(r, c);
}

/// A child's handed-up rows (its frame) mapped to this body's frame by the
/// force transform and stacked at row `at` of the QR.
void stackChildRows(const SE3& liMi, const KRows& rows, PivotedQR& qr, int at) {
  for (int r = 0; r < rows.rows(); ++r) {
    Eigen::Map<Vec6>(qr.a[at + r]) = liMi.actForce(rows.row(r).transpose());
  }
}

/// Body rows of a constraint block, world covectors → body frame (adjoint of
/// the motion transform: w_body = ᵒX_iᵀ w), stacked at row `at` of the QR.
void stackBodyRows(const Data& data, const ConstraintData& cdata, const TreeBlock& tb,
                   PivotedQR& qr, int at) {
  const RowBlock& blk = cdata.blocks[tb.constraint];
  const RowMatrix6& W = tb.sign > 0 ? blk.Wa : blk.Wb;
  const SE3& oMi = data.oMi[tb.body];
  for (int r = 0; r < tb.rows; ++r) {
    Eigen::Map<Vec6>(qr.a[at + r]) = oMi.actInvForce(tb.sign * W.row(r).transpose());
  }
}

/// Split of a free joint (S = 1, so G = K) without an SVD. The last
/// compression left K = [R₁₁ R₁₂] Πᵀ with R₁₁ upper triangular and
/// nonsingular (its pivots passed the rank test), so
///   G⁺ = Π [R₁₁⁻¹; 0]  (a right inverse: K G⁺ = 1),
///   V₂ = Π [−R₁₁⁻¹ R₁₂; 1]  (a basis of null K),
/// and no row is handed up. Neither need be orthogonal: the free part is
/// minimised over all of null K, so v̇ is the constrained minimiser, and
/// μ = G⁺ᵀ(Sᵀf − τ) is exact because the force balance along V₂ puts Sᵀf − τ
/// in the range of Gᵀ. σ_min(K) ≥ σ_min(R₁₁) ≥ 1/‖R₁₁⁻¹‖_F: when that bound is
/// above kWeakPivot the SVD would resolve every row too; otherwise returns
/// false and the caller takes the SVD.
bool freeSplit(Node& nd) {
  const int n = nd.nK;
  const int* perm = nd.comp[nd.ncomp - 1].f.perm;
  double R[6][6], Ri[6][6] = {};
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < 6; ++c) R[r][c] = nd.K(r, perm[c]);
  double fro = 0;
  for (int c = 0; c < n; ++c)  // back substitution, R₁₁ X = 1, column by column
    for (int r = c; r >= 0; --r) {
      double x = r == c ? 1.0 : 0.0;
      for (int k = r + 1; k <= c; ++k) x -= R[r][k] * Ri[k][c];
      Ri[r][c] = x / R[r][r];
      fro += Ri[r][c] * Ri[r][c];
    }
  const double lb = 1.0 / std::sqrt(fro);
  if (!(lb > kWeakPivot)) return false;
  nd.Gpinv.setZero(6, n);
  nd.V2.setZero(6, 6 - n);
  for (int r = 0; r < n; ++r) {
    for (int c = 0; c < n; ++c) nd.Gpinv(perm[r], c) = Ri[r][c];
    for (int f = 0; f < 6 - n; ++f) {
      double x = 0;
      for (int k = r; k < n; ++k) x -= Ri[r][k] * R[k][n + f];
      nd.V2(perm[r], f) = x;
    }
  }
  for (int f = 0; f < 6 - n; ++f) nd.V2(perm[n + f], f) = 1;
  nd.u2form = U2Form::Identity;
  nd.npass = 0;
  return true;
}

/// One-DoF joint (revolute, prismatic, continuous: most bodies). The SVD of
/// the column g = K s is its norm σ and a Householder reflector H = 1 − β u uᵀ
/// with H g = ∓σ e₁, whose other columns span U₂ — kept as (u, β), never
/// formed. With the row resolved (ρ = 1) nothing is free and
///   H = Pᵀ IA P = IA − (gk zᵀ + z gkᵀ),  P = 1 − s gkᵀ, gk = Kᵀ g / σ²,
///   z = IA s − ½ (sᵀ IA s) gk,
/// a symmetric rank-2 update; otherwise it is ABA's 1-DoF elimination.
/// Returns false, leaving the split to splitSoft, when 0 < σ < kWeakPivot.
bool splitOneDof(const SolverOptions& o, const Joint& j, bool root, Node& nd, Mat6& H) {
  // Rows of K (row-major, nK × 6) as fixed-size 6-vectors: the products below
  // are a handful of 6-wide dots and axpys, not Eigen's dynamic-size kernels.
  const int nK = nd.nK;
  auto row = [&](int r) { return Eigen::Map<const Vec6>(nd.K.data() + 6 * r); };
  const Vec6 s = j.S.col(0);
  double g[6], sigma2 = 0;
  for (int r = 0; r < nK; ++r) {
    g[r] = row(r).dot(s);
    sigma2 += g[r] * g[r];
  }
  const double sigma = std::sqrt(sigma2);
  if (sigma > o.rank_abs_tol && sigma < kWeakPivot) return false;  // compliant rows
  if (sigma > o.rank_abs_tol) {
    nd.rankG = 1;
    nd.npass = nK - 1;
    nd.nf = 0;
    nd.gp.resize(nK);  // G⁺ᵀ = g/σ²; nothing free: V2, S2 unused
    for (int r = 0; r < nK; ++r) nd.gp[r] = g[r] / sigma2;
    if (nK > 1) {
      nd.u2form = U2Form::Reflector;
      nd.hu.resize(nK);
      for (int r = 0; r < nK; ++r) nd.hu[r] = g[r] / sigma;
      nd.hu[0] += nd.hu[0] >= 0 ? 1.0 : -1.0;
      nd.hbeta = 2.0 / nd.hu.squaredNorm();
      // Kpass = U₂ᵀ K = rows 1… of H K = K − β u (uᵀ K).
      Vec6 uK = Vec6::Zero();
      for (int r = 0; r < nK; ++r) uK += nd.hu[r] * row(r);
      nd.Kpass.resize(nK - 1, 6);
      for (int r = 1; r < nK; ++r)
        Eigen::Map<Vec6>(nd.Kpass.data() + 6 * (r - 1)) = row(r) - (nd.hbeta * nd.hu[r]) * uK;
    } else {
      nd.u2form = U2Form::Identity;  // no rows left: U₂ is empty
      nd.Kpass.resize(0, 6);
    }
    if (root) return true;  // H, gk and ias only serve the parent
    Vec6& gk = nd.gk;
    gk.setZero();
    for (int r = 0; r < nK; ++r) gk += nd.gp[r] * row(r);
    const Vec6& w = nd.ias = nd.IA * s;  // nothing free: Ia = IA
    const Vec6 z = w - (0.5 * s.dot(w)) * gk;
    H = nd.IA;
    H.noalias() -= gk * z.transpose();
    H.noalias() -= z * gk.transpose();
  } else {
    nd.rankG = 0;
    nd.npass = nK;
    nd.nf = 1;
    nd.u2form = U2Form::Identity;
    nd.Kpass = nd.K;
    nd.V2.setIdentity(1, 1);
    nd.S2 = j.S;
    const Vec6 U = nd.IA * s;
    const double Dinv = 1.0 / s.dot(U);
    nd.U = U;
    nd.Dinv.setConstant(1, 1, Dinv);
    H = nd.IA;
    H.noalias() -= (Dinv * U) * U.transpose();
  }
  return true;
}

/// Any other joint: a free joint's split from the compression's R₁₁ when well
/// conditioned, otherwise the SVD of G = K S; then the free part eliminated
/// as in ABA and H = Pᵀ Ia P. Returns false, leaving the split to splitSoft,
/// when a kept singular value is below kWeakPivot.
bool splitGeneral(TreeWorkspace& ws, const Joint& j, bool root, Node& nd, Mat6& H) {
  const SolverOptions& o = ws.options;
  const int nv = j.nv, nK = nd.nK;
  int rho = 0;
  nd.u2form = U2Form::Explicit;
  if (nK > 0 && j.type == JointType::Floating && freeSplit(nd)) {
    rho = nK;
  } else if (nK > 0 && nv > 0) {
    const SmallMat G = nd.K * j.S;
    ws.svd.compute(G, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const auto& sv = ws.svd.singularValues();
    const double thr = std::max(o.rank_abs_tol, o.rank_rel_tol * sv(0));
    while (rho < sv.size() && sv(rho) > thr) ++rho;
    if (rho > 0 && sv(rho - 1) < kWeakPivot) return false;  // compliant rows
    const auto& Um = ws.svd.matrixU();
    const auto& Vm = ws.svd.matrixV();
    if (rho > 0)
      nd.Gpinv.noalias() = Vm.leftCols(rho) * sv.head(rho).cwiseInverse().asDiagonal() *
                           Um.leftCols(rho).transpose();
    nd.U2 = Um.rightCols(nK - rho);
    nd.V2 = Vm.rightCols(nv - rho);
  } else {
    nd.u2form = U2Form::Identity;
    nd.V2.setIdentity(nv, nv);
  }
  nd.rankG = rho;
  nd.npass = nK - rho;
  nd.nf = nv - rho;
  if (nd.u2form == U2Form::Identity)
    nd.Kpass = nd.K;
  else if (nd.npass > 0)
    nd.Kpass.noalias() = nd.U2.transpose() * nd.K;
  else
    nd.Kpass.resize(0, 6);

  // GK = G⁺ K (nv × 6): P = 1 − S GK is a low-rank update of the identity,
  // never formed when nv ≤ 2 (applied as x − GKᵀ(Sᵀx) / x − S(GK x)).
  auto& GK = nd.GK;
  if (rho > 0) {
    if (!root) GK.noalias() = nd.Gpinv * nd.K;
    nd.S2.noalias() = j.S * nd.V2;
  } else {
    nd.S2 = j.S;
  }
  if (nd.nf > 0) {
    nd.U.noalias() = nd.IA * nd.S2;
    const SmallMat D = nd.S2.transpose() * nd.U;
    if (root) {  // H, GK and IaS only serve the parent; D⁻¹ only the forward pass
      nd.Dinv = D.llt().matrixL();
      nd.dinv_factor = true;
      return true;
    }
    nd.Dinv = D.llt().solve(SmallMat::Identity(nd.nf, nd.nf));
  }
  if (root) return true;  // H, GK and IaS only serve the parent
  Mat6 Ia = nd.IA;
  if (nd.nf > 0) Ia.noalias() -= nd.U * nd.Dinv * nd.U.transpose();
  if (rho > 0) {
    // Pᵀ Ia P = Ia P − GKᵀ (Sᵀ Ia P), Ia P = Ia − (Ia S) GK: O(36 nv) per
    // factor instead of two dense 6 × 6 products.
    nd.IaS.noalias() = Ia * j.S;
    Mat6 IaP = Ia;
    IaP.noalias() -= nd.IaS * GK;
    Eigen::Matrix<double, Eigen::Dynamic, 6, 0, 6, 6> SIaP(nv, 6);
    SIaP.noalias() = j.S.transpose() * IaP;
    H = IaP;
    H.noalias() -= GK.transpose() * SIaP;
  } else {
    H = Ia;
  }
  return true;
}

/// Step 1 of the factor pass at body i: stack its own rows and the
/// children's unresolved rows, compressing whenever the stack would exceed
/// 12 rows and once at the end.
void stackAndCompress(const Data& data, const ConstraintData& cdata, TreeWorkspace& ws, int i,
                      const Joint& j) {
  const SolverOptions& o = ws.options;
  Node& nd = ws.nodes[i];
  nd.ncomp = 0;
  nd.nK = 0;
  nd.nfree = 0;
  nd.K.resize(0, 6);
  int nb = 0;
  Compression* cur = &nd.comp[0];
  cur->nseg = 0;
  auto compressStack = [&](bool last) {
    bool soft = false;
    for (int s = 0; s < cur->nseg; ++s) soft |= softSegment(ws, nd, nd.ncomp, cur->seg[s]);
    // One segment: a constraint's own rows, or one child's handed-up rows
    // (independent as handed up) — where redundancy is rare and the
    // certificate pays. Several segments meeting is where it arises (an
    // axle's normal row and its trailer's, both on the ground): straight to
    // the QR, with no certificate attempted.
    const bool whole = o.certify_independent_stacks && last && nd.ncomp == 0 &&
                       cur->nseg == 1 && !soft && j.type != JointType::Floating;
    compress(o, *cur, nb, nd.K, whole, ws.certified_stacks);
    nd.nK = cur->rank;
    cur->soft = false;
    // Dropped rows with no compliance: redundant, their multipliers free.
    cur->nfree = soft ? softCompress(ws, i, nd.ncomp) : nb - cur->rank;
    nd.nfree += cur->nfree;
    // The next stack, if any group is left to start one (the constructor
    // sized comp for the most compressions the groups can cause).
    ++nd.ncomp;
    cur = nd.ncomp < static_cast<int>(nd.comp.size()) ? &nd.comp[nd.ncomp] : nullptr;
    if (cur) cur->nseg = 0;
  };
  for (const Segment& g : nd.groups) {
    const int r = g.kind == Segment::Block ? ws.blocks[g.id].rows : ws.nodes[g.id].npass;
    if (r == 0) continue;
    if (nb + r > 12) {  // compress, and carry the kept rows on
      compressStack(false);
      nb = nd.nK;
      if (nb > 0) {
        stackRows(cur->f, 0, nd.K);
        cur->seg[cur->nseg++] = {Segment::Previous, -1, nb};
      }
    }
    if (g.kind == Segment::Block)
      stackBodyRows(data, cdata, ws.blocks[g.id], cur->f, nb);
    else
      stackChildRows(data.liMi[g.id], ws.nodes[g.id].Kpass, cur->f, nb);
    cur->seg[cur->nseg++] = {g.kind, g.id, r};
    nb += r;
  }
  if (cur && cur->nseg > 0) compressStack(true);
}

/// Closed joint-space rows on body i's joint lock it (tree_solver/locked.cpp);
/// one row fixes q̈, the others are redundant, split by min norm.
void lockByJointRows(const ConstraintData& cdata, TreeWorkspace& ws, Node& nd) {
  nd.locked = false;
  if (nd.jrows.empty()) return;
  nd.c2 = 0;
  int closed = 0;
  for (JointRow& r : nd.jrows) {
    r.active = cdata.isActive(r.constraint);
    r.c = r.active ? cdata.blocks[r.constraint].A_joint(r.row, 0) : 0.0;
    r.active = r.active && r.c != 0;  // a zero row locks nothing (λ = 0)
    nd.c2 += r.c * r.c;
    closed += r.active ? 1 : 0;
  }
  nd.locked = closed > 0;
  if (closed > 1) ws.redundant += closed - 1;
}

}  // namespace

void factorPass(const Model& model, const Data& data, const ConstraintData& cdata,
                TreeWorkspace& ws) {
  for (int i = 0; i < model.nbodies; ++i) ws.nodes[i].IA = model.spatial_inertia[i];
  ws.redundant = 0;
  ws.nseeds = 0;
  ws.any_soft = false;
  ws.certified_stacks = 0;

  for (int i = model.nbodies - 1; i >= 0; --i) {
    Node& nd = ws.nodes[i];
    const Joint& j = model.joints[i];
    const int p = model.parent[i];
    stackAndCompress(data, cdata, ws, i, j);

    // 2. Split the joint: G = K S = U Σ Vᵀ; rows along U₁ fix V₁ᵀ q̈, rows
    //    along U₂ do not involve q̈ and go to the parent; V₂ spans the free part.
    // 3. Articulated inertia: a = P ā + d + S₂ z with P = 1 − S G⁺ K; the free
    //    part z is eliminated as in ABA, and the parent sees H = Pᵀ Ia P — the
    //    particular/free coupling the constrained-LQR equations drop.
    Mat6& H = nd.H;
    nd.soft = false;
    nd.softpass = false;
    lockByJointRows(cdata, ws, nd);
    const bool soft_rows = nd.ncomp > 0 && nd.comp[nd.ncomp - 1].soft;
    nd.dinv_factor = false;
    if (nd.locked)
      splitLocked(ws, j, p < 0, nd, H);
    else if (soft_rows || !(j.nv == 1 ? splitOneDof(ws.options, j, p < 0, nd, H) : splitGeneral(ws, j, p < 0, nd, H)))
      splitSoft(ws, j, p < 0, nd, H);
    if (p < 0) nd.nfree += nd.npass;  // rows no joint can move: their combinations are zero rows of A
    if (nd.nfree > 0) {  // tree_solver/min_norm.cpp starts from these bodies
      ws.redundant += nd.nfree;
      ws.seeds[ws.nseeds++] = i;
    }
    if (p >= 0) addTransformedInertia(data.liMi[i], H, ws.nodes[p].IA);
    ws.any_soft = ws.any_soft || nd.soft;
  }
}

void velocityCouplings(const Model& model, TreeWorkspace& ws) {
  for (int i = 0; i < model.nbodies; ++i) {
    Node& nd = ws.nodes[i];
    if (nd.npass > 0) nd.kpc.noalias() = nd.Kpass * nd.c;
    if (model.parent[i] >= 0) nd.Hc.noalias() = nd.H * nd.c;
  }
}

namespace {

/// Body i's right sides through its recorded compressions, Qᵀ E r, into each
/// compression's rhs and the body's k. With check, false (and ws.failure
/// set) when a dropped row's right side is not the combination of the kept
/// ones its row is: no acceleration satisfies them.
bool compressedRhs(TreeWorkspace& ws, int i, bool check) {
  Node& nd = ws.nodes[i];
  for (int e = 0; e < nd.ncomp; ++e) {
    Compression& cp = nd.comp[e];
    BufVec r;
    gatherRhs(ws, i, e, r);
    double rmax = 0;  // ‖E r‖∞, the scale of the consistency test
    for (int k = 0; k < cp.nrows; ++k) {
      r[k] *= cp.E[k];
      rmax = std::max(rmax, std::abs(r[k]));
    }
    applyQt(cp, r);
    const double tol = ws.options.consistency_tol * std::max(1.0, rmax);
    double res = 0;
    if (cp.soft) {
      if (!softCompressionRhs(cp, r, tol, res) && check) {
        ws.failure = {true, i, e, res};
        return false;
      }
      continue;
    }
    cp.rhs.resize(cp.rank);
    for (int k = 0; k < cp.rank; ++k) cp.rhs[k] = r[k];
    if (!check) continue;
    for (int k = cp.rank; k < cp.nrows; ++k) res = std::max(res, std::abs(r[k]));
    if (res > tol) {
      ws.failure = {true, i, e, res};
      return false;
    }
  }
  if (nd.ncomp > 0)
    nd.k = nd.comp[nd.ncomp - 1].rhs;
  else
    nd.k.resize(0);
  return true;
}

/// The bias force a rigid joint's body hands its parent — the gradient of
/// the child's cost-to-go in ā = X a_p + c:
///   H ā + Pᵀ(Ia d + pa) + Kᵀ G⁺ᵀ τ,   d = S G⁺ k,
/// with Pᵀ x = x − GKᵀ(Sᵀ x) and Kᵀ G⁺ᵀ = GKᵀ:  H ā + x − GKᵀ(Sᵀx − τ).
Vec6 parentBias(const TreeWorkspace& ws, const Node& nd, const Joint& j) {
  const auto tau = ws.tau.segment(j.idx_v, j.nv);
  Vec6 pa = nd.pA;
  if (nd.nf > 0) pa.noalias() += nd.U * (nd.Dinv * nd.u);
  Vec6 g = ws.use_c ? nd.Hc : Vec6::Zero();
  if (nd.rankG > 0 && j.nv == 1) {
    pa += nd.gp.dot(nd.k) * nd.ias;
    g -= (j.S.col(0).dot(pa) - tau[0]) * nd.gk;
  } else if (nd.rankG > 0) {
    KVec y(j.nv);
    y.noalias() = nd.Gpinv * nd.k;
    pa.noalias() += nd.IaS * y;
    KVec sx(j.nv);
    sx.noalias() = j.S.transpose() * pa;
    sx -= tau;
    g.noalias() -= nd.GK.transpose() * sx;
  }
  g += pa;
  if (nd.locked) g += nd.rho * nd.Hs;  // a = ā + s ρ: ρ enters as c does
  return g;
}

/// A body with compliant rows (tree_solver/soft.cpp): its bias to the parent
/// and the right sides it hands up.
void softBodyBias(const Data& data, TreeWorkspace& ws, int i, const Joint& j, int p) {
  Node& nd = ws.nodes[i];
  Vec6 pa;
  softBias(nd.locked ? lockedJoint() : j, nd, ws.tau, pa);
  if (p >= 0) {
    if (ws.use_c) pa += nd.Hc;
    if (nd.locked) pa += nd.rho * nd.Hs;  // a = ā + s ρ: ρ enters as c does
    ws.nodes[p].pA += data.liMi[i].actForce(pa);
  }
  nd.kpass = nd.kv.head(nd.npass);
  if (ws.use_c && nd.npass > 0) nd.kpass -= nd.kpc;
  if (nd.locked && nd.npass > 0) nd.kpass -= nd.rho * nd.kps;
}

}  // namespace

bool biasPass(const Model& model, const Data& data, TreeWorkspace& ws, bool check) {
  for (int i = 0; i < model.nbodies; ++i) ws.nodes[i].pA = ws.nodes[i].bias0;
  ws.failure = {};

  for (int i = model.nbodies - 1; i >= 0; --i) {
    Node& nd = ws.nodes[i];
    const Joint& j = model.joints[i];
    const int p = model.parent[i];
    if (nd.locked && !lockedRhs(ws, i, check) && check) return false;
    if (!compressedRhs(ws, i, check)) return false;
    if (nd.soft) {
      softBodyBias(data, ws, i, j, p);
      continue;
    }
    if (nd.nf > 0) {
      const auto tau = ws.tau.segment(j.idx_v, j.nv);
      if (nd.rankG > 0)
        nd.u.noalias() = nd.V2.transpose() * tau;
      else
        nd.u = tau;
      nd.u.noalias() -= nd.S2.transpose() * nd.pA;
    }
    if (p >= 0) ws.nodes[p].pA += data.liMi[i].actForce(parentBias(ws, nd, j));
    if (nd.npass > 0) {
      applyU2t(nd, nd.k, nd.kpass);
      if (ws.use_c) nd.kpass -= nd.kpc;
      if (nd.locked) nd.kpass -= nd.rho * nd.kps;
    } else {
      nd.kpass.resize(0);
    }
  }
  return true;
}

}  // namespace appell::detail
