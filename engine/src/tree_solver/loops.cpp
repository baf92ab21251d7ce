// Tree solver, loop closure: rows between two moving bodies and rows given
// over v are auxiliary unknowns λ_L (Baraff 1996's "few auxiliary rows").
// The tree-constrained response is affine in the loop forces:
//     v̇(λ_L) = v̇₀ + W λ_L,   W = [response to B_lᵀ],  one bias+forward
// replay per loop row (the factorization is shared): O(k n). λ_L solves
//     S λ_L = β − B v̇₀,   S = B W = B C Bᵀ   (C: the tree-constrained M⁻¹).
//
// S is never formed. With homogeneous tree rows (A_T W = 0),
//     S = Wᵀ M W = Zᵀ Z,   Z = [R_i a_i(W)]  (6n × k),  I_i = R_iᵀ R_i,
// the kinetic-energy metric of the responses, summed over bodies. Z is to S
// what A M^{-½} is to A M⁻¹ Aᵀ in the dense solvers: λ_L taken from the SVD
// of Z loses eps·cond(Z), where solving with S itself would lose
// eps·cond(Z)² — the squaring that once needed iterative refinement. The rank
// rule is the dense solvers' (relative to the largest singular value of the
// equilibrated Z); redundant loop directions get λ = 0 here (tree_solver/
// min_norm.cpp then removes them from λ globally), inconsistent ones are named.
#include "tree_solver/workspace.hpp"

#include <algorithm>
#include <cmath>

namespace appell::detail {

namespace {

/// B_l applied to the main pass (body accelerations ws.a0, velocities ws.vdot0).
double applyRow(const ConstraintData& cdata, const Data& data, const TreeWorkspace& ws,
                const LoopRow& lr) {
  const RowBlock& blk = cdata.blocks[lr.constraint];
  if (lr.joint_space) return jointRowDot(blk, lr.row, ws.vdot0);
  const Vec6 aA = data.oMi[lr.bodyA].act(ws.a0[lr.bodyA]);
  const Vec6 aB = data.oMi[lr.bodyB].act(ws.a0[lr.bodyB]);
  return blk.Wa.row(lr.row).dot(aA) - blk.Wb.row(lr.row).dot(aB);
}

/// Of the generalized force f = B_lᵀ of loop row l, the share the tree rows
/// leave free: ‖M v̇_l‖ / ‖f‖ with M v̇_l = f + A_Tᵀ λ_T (0 when the tree rows
/// absorb all of it: the row is immobile, and its response W_l is round-off).
/// Both forces in one leaves-to-root sweep, as in RNEA: M v̇ = Σ J_iᵀ I_i a_i.
/// Sets ‖f‖ in `fnorm`.
double freeShare(const Model& model, const Data& data, const ConstraintData& cdata,
                 TreeWorkspace& ws, const LoopRow& lr, double& fnorm) {
  const RowBlock& blk = cdata.blocks[lr.constraint];
  for (int i = 0; i < model.nbodies; ++i) {
    ws.fsub[i].noalias() = model.spatial_inertia[i] * ws.nodes[i].a;
    ws.floop[i].setZero();
  }
  if (!lr.joint_space) {
    ws.floop[lr.bodyA] += data.oMi[lr.bodyA].actInvForce(blk.Wa.row(lr.row).transpose());
    ws.floop[lr.bodyB] -= data.oMi[lr.bodyB].actInvForce(blk.Wb.row(lr.row).transpose());
  }
  double mv2 = 0, f2 = 0;
  if (lr.joint_space) {  // B_lᵀ over v: ‖f‖² straight from its columns
    for (size_t k = 0; k < blk.joint_cols.size(); ++k) { const double a = blk.A_joint(lr.row, k); f2 += a * a; }
  }
  for (int i = model.nbodies - 1; i >= 0; --i) {
    const Joint& j = model.joints[i];
    for (int c = 0; c < j.nv; ++c) {
      const double m = j.S.col(c).dot(ws.fsub[i]);
      mv2 += m * m;
      if (lr.joint_space) continue;
      const double f = j.S.col(c).dot(ws.floop[i]);
      f2 += f * f;
    }
    const int p = model.parent[i];
    if (p < 0) continue;
    ws.fsub[p] += data.liMi[i].actForce(ws.fsub[i]);
    ws.floop[p] += data.liMi[i].actForce(ws.floop[i]);
  }
  fnorm = std::sqrt(f2);
  return f2 > 0 ? std::sqrt(mv2 / f2) : 0.0;
}

/// The loop closure's part that depends on the factor and the loop rows
/// only: each loop row's unit response (W, L, Z), Z equilibrated, and Z's
/// SVD with its rank. Kept while the factor record holds (FactorRecord).
void formLoopClosure(const Model& model, const Data& data, const ConstraintData& cdata,
                     TreeWorkspace& ws) {
  const int k = static_cast<int>(ws.loops.size());
  const SolverOptions& o = ws.options;
  // Unit solves: the response to each loop row's generalized force B_lᵀ,
  // with no velocity terms, no gravity and homogeneous tree rows — so the
  // body accelerations are J_i v̇ and Z's column is their M-metric root.
  const bool use_c = ws.use_c, multipliers = ws.multipliers;
  const Vec6 a_world = ws.a_world;
  ws.use_c = false;
  ws.multipliers = true;  // L, the responses' multipliers, is kept with the closure
  ws.a_world.setZero();
  for (auto& nd : ws.nodes) nd.bias0.setZero();
  for (auto& tb : ws.blocks) tb.rhs.setZero();
  for (int b : ws.jrow_nodes)
    for (auto& jr : ws.nodes[b].jrows) jr.rhs = 0;
  for (int l = 0; l < k; ++l) {
    const LoopRow& lr = ws.loops[l];
    const RowBlock& blk = cdata.blocks[lr.constraint];
    ws.tau.setZero();
    if (lr.joint_space) {
      addJointRow(blk, lr.row, 1.0, ws.tau);
    } else {
      // bias0 is minus the external force, body frame.
      ws.nodes[lr.bodyA].bias0 -= data.oMi[lr.bodyA].actInvForce(blk.Wa.row(lr.row).transpose());
      ws.nodes[lr.bodyB].bias0 += data.oMi[lr.bodyB].actInvForce(blk.Wb.row(lr.row).transpose());
    }
    biasPass(model, data, ws, false);
    forwardPass(model, data, ws, false);
    ws.W.col(l) = ws.vdot;
    ws.L.col(l) = ws.lambda;
    for (int i = 0; i < model.nbodies; ++i)
      ws.Z.col(l).segment<6>(6 * i).noalias() = ws.inertia_root[i] * ws.nodes[i].a;
    ws.loop_share[l] = freeShare(model, data, cdata, ws, lr, ws.loop_fnorm[l]);
    if (!lr.joint_space) {
      ws.nodes[lr.bodyA].bias0.setZero();
      ws.nodes[lr.bodyB].bias0.setZero();
    }
  }
  ws.use_c = use_c;
  ws.multipliers = multipliers;
  ws.a_world = a_world;

  // Equilibrate the columns (S's diagonal to 1). A row whose force the tree
  // rows absorb (free share at the rank tolerance) is immobile: its column
  // is round-off and is zeroed, it gets λ = 0, and its right side, scaled by
  // its own norm, must vanish.
  for (int l = 0; l < k; ++l) {
    const double d = ws.Z.col(l).norm();
    const bool mobile = ws.loop_share[l] > o.rank_rel_tol && d > 0;
    ws.loop_scale[l] = mobile ? 1.0 / d : ws.loop_fnorm[l] > 0 ? 1.0 / ws.loop_fnorm[l] : 1.0;
    ws.Z.col(l) *= mobile ? ws.loop_scale[l] : 0.0;
  }
  // Z = U Σ Vᵀ, so S = V Σ² Vᵀ: λ = V₁ Σ₁⁻² V₁ᵀ r, and the part of r along V₂
  // (directions no loop force moves) is the inconsistency.
  ws.z_svd.compute(ws.Z, Eigen::ComputeThinV);
  const auto& s = ws.z_svd.singularValues();
  const double thr = std::max(o.rank_abs_tol, o.rank_rel_tol * s(0));  // s(0) ≤ √k
  int rank = 0;
  while (rank < k && s(rank) > thr) ++rank;
  ws.loop_rank = rank;
}

}  // namespace

void loopTargets(const Model& model, const Data& data, const ConstraintData& cdata,
                 TreeWorkspace& ws, const VecX& v, bool impulse) {
  for (size_t l = 0; l < ws.loops.size(); ++l) {
    const LoopRow& lr = ws.loops[l];
    const RowBlock& blk = cdata.blocks[lr.constraint];
    double t;
    if (lr.joint_space) {
      t = impulse ? -(jointRowDot(blk, lr.row, v) + blk.b_joint[lr.row])
                  : -blk.abias_joint[lr.row];
    } else if (impulse) {
      const Vec6 VA = data.oMi[lr.bodyA].act(data.v[lr.bodyA]);
      const Vec6 VB = data.oMi[lr.bodyB].act(data.v[lr.bodyB]);
      t = -(blk.Wa.row(lr.row).dot(VA) - blk.Wb.row(lr.row).dot(VB) + blk.b[lr.row]);
    } else {
      // On gravity-shifted accelerations a' = a − g (both bodies see the same g).
      t = -blk.kappa[lr.row] -
          (blk.Wa.row(lr.row).tail<3>() - blk.Wb.row(lr.row).tail<3>()).dot(model.gravity);
    }
    ws.loop_target[l] = t;
  }
}

bool solveLoops(const Model& model, const Data& data, const ConstraintData& cdata,
                TreeWorkspace& ws) {
  const int k = static_cast<int>(ws.loops.size());
  if (k == 0) return true;
  const SolverOptions& o = ws.options;

  // Main pass: keep it, and the loop rows' residuals on it.
  ws.vdot0 = ws.vdot;
  ws.lambda0 = ws.lambda;
  for (int i = 0; i < model.nbodies; ++i) ws.a0[i] = ws.nodes[i].a;
  for (int l = 0; l < k; ++l) ws.loop_rhs[l] = ws.loop_target[l] - applyRow(cdata, data, ws, ws.loops[l]);

  if (!ws.loop_closure_valid) {
    formLoopClosure(model, data, cdata, ws);
    ws.loop_closure_valid = true;
  }
  ws.loop_res = ws.loop_scale.cwiseProduct(ws.loop_rhs);

  // Z = U Σ Vᵀ (formLoopClosure), so S = V Σ² Vᵀ: λ = V₁ Σ₁⁻² V₁ᵀ r, and
  // the part of r along V₂ (directions no loop force moves) is the inconsistency.
  const auto& s = ws.z_svd.singularValues();
  const auto& V = ws.z_svd.matrixV();
  const int rank = ws.loop_rank;
  ws.loop_tmp.noalias() = V.transpose() * ws.loop_res;
  ws.loop_tmp.head(rank).array() /= s.head(rank).array().square();
  ws.loop_lambda.noalias() = V.leftCols(rank) * ws.loop_tmp.head(rank);

  // Consistency: V₂ V₂ᵀ r must vanish.
  ws.loop_resid.noalias() = V.rightCols(k - rank) * ws.loop_tmp.tail(k - rank);
  const double res = ws.loop_resid.lpNorm<Eigen::Infinity>();
  if (res > o.consistency_tol * std::max(1.0, ws.loop_res.lpNorm<Eigen::Infinity>())) {
    std::string names;
    for (int l = 0; l < k; ++l) {
      if (std::abs(ws.loop_resid[l]) <= 0.01 * res) continue;
      const std::string& n = ws.names[ws.loops[l].constraint];
      if (names.find("'" + n + "'") != std::string::npos) continue;
      if (!names.empty()) names += ", ";
      names += "'" + n + "'";
    }
    ws.last_error = "inconsistent loop-closing constraints " + names +
                    ": no acceleration satisfies them together with the tree rows";
    ws.failure = {true, -1, -2, res};
    return false;
  }
  ws.loop_lambda.array() *= ws.loop_scale.array();

  ws.vdot = ws.vdot0;
  ws.vdot.noalias() += ws.W * ws.loop_lambda;
  ws.lambda = ws.lambda0;
  ws.lambda.noalias() += ws.L * ws.loop_lambda;
  for (int l = 0; l < k; ++l) ws.lambda[ws.loops[l].global] = ws.loop_lambda[l];
  return true;
}

}  // namespace appell::detail
