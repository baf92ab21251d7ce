// Tree solver, forward pass (root → leaves): accelerations, then each body's
// multipliers from its joint force balance, unrolled into its rows and its
// children's handed-up rows (tree_solver/multipliers.cpp).
#include "tree_solver/workspace.hpp"

#include <algorithm>

namespace appell::detail {

namespace {

/// A root's handed-up rows act on the world's (prescribed) acceleration: no
/// joint moves them, so they must already hold. Their combinations are zero
/// rows of A, whose multipliers are free: zero here, then chosen by
/// tree_solver/min_norm.cpp. False (and ws.failure set) when they do not hold.
bool rootRowsHold(TreeWorkspace& ws, int i, const Vec6& xa, bool check) {
  Node& nd = ws.nodes[i];
  nd.nu.setZero(nd.npass);
  if (!check) return true;
  KVec lhs(nd.npass);
  lhs.noalias() = nd.Kpass * xa;
  const double res = (nd.kpass - lhs).lpNorm<Eigen::Infinity>();
  const double scale = std::max({1.0, nd.kpass.lpNorm<Eigen::Infinity>(), lhs.lpNorm<Eigen::Infinity>()});
  if (res <= ws.options.consistency_tol * scale) return true;
  ws.failure = {true, i, -1, res};
  return false;
}

/// A locked joint: q̈ = ρ fixed by its closed rows (tree_solver/locked.cpp).
void lockedForward(TreeWorkspace& ws, int i, const Joint& j, Vec6 abar) {
  Node& nd = ws.nodes[i];
  abar += nd.rho * j.S.col(0);
  if (nd.soft) {
    softForward(lockedJoint(), nd, abar, ws.vdot);
  } else {
    nd.a = abar;
    if (nd.ncomp > 0) {
      KVec& mu = nd.comp[nd.ncomp - 1].mu;
      mu.setZero(nd.nK);
      if (nd.npass > 0) addU2(nd, nd.nu, mu);
    }
  }
  ws.vdot[j.idx_v] = nd.rho;
  if (!ws.multipliers) return;
  lockedForce(j, nd, ws.tau[j.idx_v], ws.lambda);
  if (nd.ncomp > 0) unrollNode(ws, i, nd.ncomp - 1, ws.lambda);
}

/// The body's acceleration and its joint's q̈:
///     q̈ = G⁺(k − K ā) + V₂ z,   z = D⁻¹(u − Uᵀ w),   w = ā + S G⁺(k − K ā).
Vec6 jointAcceleration(Node& nd, const Joint& j, const Vec6& abar, VecX& vdot) {
  auto qdd = vdot.segment(j.idx_v, j.nv);
  Vec6 w = abar;
  if (nd.rankG > 0 && j.nv == 1) {
    double y = 0;  // G⁺(k − K ā), K's rows as fixed-size 6-vectors
    for (int r = 0; r < nd.nK; ++r)
      y += nd.gp[r] * (nd.k[r] - Eigen::Map<const Vec6>(nd.K.data() + 6 * r).dot(abar));
    w += y * j.S.col(0);
    qdd[0] = y;
  } else if (nd.rankG > 0) {
    KVec r = nd.k;
    r.noalias() -= nd.K * abar;
    KVec y(j.nv);
    y.noalias() = nd.Gpinv * r;
    w.noalias() += j.S * y;
    qdd = y;
  } else {
    qdd.setZero();
  }
  Vec6 a = w;
  if (nd.nf == 0) return a;
  KVec z = nd.u;
  z.noalias() -= nd.U.transpose() * w;
  KVec zz;
  if (nd.dinv_factor) {
    zz = z;
    nd.Dinv.triangularView<Eigen::Lower>().solveInPlace(zz);
    nd.Dinv.transpose().triangularView<Eigen::Upper>().solveInPlace(zz);
  } else {
    zz.noalias() = nd.Dinv * z;
  }
  a.noalias() += nd.S2 * zz;
  if (nd.rankG > 0)
    qdd.noalias() += nd.V2 * zz;
  else
    qdd += zz;
  return a;
}

/// Multipliers of K from the joint's force balance  Gᵀ μ = Sᵀ f − τ with
/// f = IA a + pA (the force the joint transmits, constraint forces of this
/// body's rows excluded); the U₂ part comes from the parent.
void jointMultipliers(TreeWorkspace& ws, int i, const Joint& j, bool at_root) {
  Node& nd = ws.nodes[i];
  const Vec6& a = nd.a;
  const auto tau = ws.tau.segment(j.idx_v, j.nv);
  KVec& mu = nd.comp[nd.ncomp - 1].mu;
  mu.setZero(nd.nK);
  if (nd.rankG > 0 && j.nv == 1) {
    const Vec6 s = j.S.col(0);
    const double sIAa = !at_root ? nd.ias.dot(a) : s.dot(nd.IA * a);  // IA s kept (not at the root)
    mu.noalias() += (sIAa + s.dot(nd.pA) - tau[0]) * nd.gp;
  } else if (nd.rankG > 0) {
    KVec r(j.nv);
    if (nd.nf == 0 && !at_root)  // Ia = IA, so Sᵀ IA a = (Ia S)ᵀ a, kept by the factor pass
      r.noalias() = nd.IaS.transpose() * a;
    else
      r.noalias() = j.S.transpose() * (nd.IA * a);
    r.noalias() += j.S.transpose() * nd.pA;
    r -= tau;
    mu.noalias() += nd.Gpinv.transpose() * r;
  }
  if (nd.npass > 0) addU2(nd, nd.nu, mu);
  unrollNode(ws, i, nd.ncomp - 1, ws.lambda);
}

}  // namespace

bool forwardPass(const Model& model, const Data& data, TreeWorkspace& ws, bool check) {
  for (int i = 0; i < model.nbodies; ++i) {
    Node& nd = ws.nodes[i];
    const Joint& j = model.joints[i];
    const int p = model.parent[i];
    const Vec6 xa = p >= 0 ? data.liMi[i].actInv(ws.nodes[p].a) : data.liMi[i].actInv(ws.a_world);
    Vec6 abar = xa;
    if (ws.use_c) abar += nd.c;
    if (p < 0 && nd.npass > 0 && !rootRowsHold(ws, i, xa, check)) return false;
    if (nd.locked) {
      lockedForward(ws, i, j, abar);
      continue;
    }
    if (nd.soft) {
      softForward(j, nd, abar, ws.vdot);
      if (ws.multipliers) unrollNode(ws, i, nd.ncomp - 1, ws.lambda);
      continue;
    }
    nd.a = jointAcceleration(nd, j, abar, ws.vdot);
    // The accelerations never read the multipliers: skipped when only v̇ is asked for.
    if (nd.ncomp > 0 && ws.multipliers) jointMultipliers(ws, i, j, p < 0);
  }
  return true;
}

}  // namespace appell::detail
