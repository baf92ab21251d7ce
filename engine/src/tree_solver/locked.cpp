// Tree solver, locked joints: joint-space rows on the one velocity of a
// one-DoF joint (joint limits, JointRow in workspace.hpp) are taken inside
// the passes instead of as loop rows. While such a row is closed it fixes
// the joint's acceleration, q̈ = ρ, so for this solve the joint has no free
// direction and nothing to resolve: the body moves with its parent plus the
// known relative acceleration s ρ,
//     a = ā + s ρ,   ā = ᵢXₚ aₚ + c,
// its rows K a = k go up as rows on ā with right side k − (K s) ρ, the
// parent sees the articulated inertia unchanged (H = IA, or splitSoft's H
// with no joint when the rows carry compliance) and the bias H s ρ, and the
// rows' force ℓ on q̈ is what the joint's force balance leaves over:
//     sᵀ(IA a + pA) = τ + (K s)ᵀ μ + ℓ.
// Cost O(1) per row: a chain with a limit on every joint stays O(n), where
// the loop closure would take one tree solve per row and a 6n × k factor.
// The minimum-norm λ (tree_solver/min_norm.cpp) sees ℓ as one more own row
// of the node's last compression: δℓ = −(K s)ᵀ δμ.
#include "tree_solver/workspace.hpp"

#include <algorithm>
#include <cmath>

namespace appell::detail {

const Joint& lockedJoint() {
  static const Joint joint = [] {
    Joint j;
    j.type = JointType::Fixed;
    j.nv = j.nq = 0;
    j.S = Mat6X(6, 0);
    return j;
  }();
  return joint;
}

void splitLocked(TreeWorkspace& ws, const Joint& j, bool root, Node& nd, Mat6& H) {
  const Vec6 s = j.S.col(0);
  const int nK = nd.nK;
  nd.gl.resize(nK);
  for (int r = 0; r < nK; ++r) nd.gl[r] = Eigen::Map<const Vec6>(nd.K.data() + 6 * r).dot(s);
  nd.ias = nd.IA * s;
  if (nd.ncomp > 0 && nd.comp[nd.ncomp - 1].soft) {
    splitSoft(ws, lockedJoint(), root, nd, H);
  } else {
    nd.soft = false;
    nd.rankG = 0;
    nd.nf = 0;
    nd.npass = nK;
    nd.u2form = U2Form::Identity;
    nd.Kpass = nd.K;
    H = nd.IA;
  }
  nd.kps.resize(nd.npass);
  if (nd.npass > 0) nd.kps.noalias() = nd.Kpass * s;
  if (!root) nd.Hs.noalias() = H * s;
}

bool lockedRhs(TreeWorkspace& ws, int body, bool check) {
  Node& nd = ws.nodes[body];
  double num = 0, rmax = 0;
  for (const JointRow& r : nd.jrows) {
    if (!r.active) continue;
    num += r.c * r.rhs;
    rmax = std::max(rmax, std::abs(r.rhs));
  }
  nd.rho = num / nd.c2;
  if (!check) return true;
  double res = 0;
  for (const JointRow& r : nd.jrows)
    if (r.active) res = std::max(res, std::abs(r.rhs - r.c * nd.rho));
  if (res <= ws.options.consistency_tol * std::max(1.0, rmax)) return true;
  std::string names;
  for (const JointRow& r : nd.jrows) {
    if (!r.active) continue;
    if (!names.empty()) names += ", ";
    names += "'" + ws.names[r.constraint] + "'";
  }
  ws.last_error = "inconsistent joint-space constraints " + names +
                  " on one joint: no acceleration of the joint satisfies them all";
  ws.failure = {true, -1, -3, res};
  return false;
}

void lockedForce(const Joint& j, Node& nd, double tau, VecX& lambda) {
  double ell = nd.ias.dot(nd.a) + j.S.col(0).dot(nd.pA) - tau;
  if (nd.ncomp > 0) ell -= nd.gl.dot(nd.comp[nd.ncomp - 1].mu);
  nd.ell = ell;
  for (const JointRow& r : nd.jrows) lambda[r.global] = r.active ? r.c * ell / nd.c2 : 0.0;
}

void lockedCertificate(Node& nd, VecX& cert) {
  const double ell = nd.ncomp > 0 ? -nd.gl.dot(nd.comp[nd.ncomp - 1].mu) : 0.0;
  for (const JointRow& r : nd.jrows)
    if (r.active) cert[r.global] = r.c * ell / nd.c2;
}

}  // namespace appell::detail
