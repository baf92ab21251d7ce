// Tree solver, loop closure: rows between two moving bodies and rows given
// over v are auxiliary unknowns λ_L (Baraff 1996's "few auxiliary rows").
// The tree-constrained response is affine in the loop forces:
//     v̇(λ_L) = v̇₀ + W λ_L,   W = [response to B_jᵀ],  one bias+forward
// replay per loop row (the factorization is shared): O(k n). Then
//     (B W) λ_L = β − B v̇₀,
// B W = B M^{-½} Π M^{-½} Bᵀ is symmetric positive semidefinite; it is
// equilibrated and solved by SVD for the minimum-norm λ_L, redundant loop rows
// dropping out at the rank tolerance, inconsistent ones reported.
#include "tree_solver_workspace.hpp"

#include <algorithm>
#include <cmath>

namespace appell::detail {

namespace {

/// B_l applied to the current pass (body accelerations in ws.nodes, ws.vdot).
double applyRow(const ConstraintData& cdata, const Data& data, const TreeWorkspace& ws,
                const LoopRow& lr, const VecX& vdot, const std::vector<Vec6>* acc) {
  const RowBlock& blk = cdata.blocks[lr.constraint];
  if (lr.joint_space) return blk.A_joint.row(lr.row).dot(vdot);
  const Vec6 aA = data.oMi[lr.bodyA].act(acc ? (*acc)[lr.bodyA] : ws.nodes[lr.bodyA].a);
  const Vec6 aB = data.oMi[lr.bodyB].act(acc ? (*acc)[lr.bodyB] : ws.nodes[lr.bodyB].a);
  return blk.Wa.row(lr.row).dot(aA) - blk.Wb.row(lr.row).dot(aB);
}

}  // namespace

bool solveLoops(const Model& model, const Data& data, const ConstraintData& cdata,
                TreeWorkspace& ws) {
  const int k = static_cast<int>(ws.loops.size());
  ws.loop_refinement = 0;
  if (k == 0) return true;
  const SolverOptions& o = ws.options;

  // Main pass: keep it, and the loop rows' residuals on it.
  ws.vdot0 = ws.vdot;
  ws.lambda0 = ws.lambda;
  for (int i = 0; i < model.nbodies; ++i) ws.a0[i] = ws.nodes[i].a;
  for (int l = 0; l < k; ++l)
    ws.loop_rhs[l] = ws.loop_target[l] - applyRow(cdata, data, ws, ws.loops[l], ws.vdot0, &ws.a0);

  // Unit solves: the response to each loop row's generalized force B_lᵀ,
  // with no velocity terms, no gravity and homogeneous tree rows.
  const bool use_c = ws.use_c;
  const Vec6 a_world = ws.a_world;
  ws.use_c = false;
  ws.a_world.setZero();
  for (auto& nd : ws.nodes) nd.bias0.setZero();
  for (auto& tb : ws.blocks) tb.rhs.setZero();
  for (int l = 0; l < k; ++l) {
    const LoopRow& lr = ws.loops[l];
    const RowBlock& blk = cdata.blocks[lr.constraint];
    ws.tau.setZero();
    if (lr.joint_space) {
      ws.tau = blk.A_joint.row(lr.row).transpose();
    } else {
      // bias0 is minus the external force, body frame.
      ws.nodes[lr.bodyA].bias0 -= data.oMi[lr.bodyA].actInvForce(blk.Wa.row(lr.row).transpose());
      ws.nodes[lr.bodyB].bias0 += data.oMi[lr.bodyB].actInvForce(blk.Wb.row(lr.row).transpose());
    }
    biasPass(model, data, ws, false);
    forwardPass(model, data, ws, false);
    ws.W.col(l) = ws.vdot;
    ws.L.col(l) = ws.lambda;
    for (int r = 0; r < k; ++r)
      ws.schur(r, l) = applyRow(cdata, data, ws, ws.loops[r], ws.vdot, nullptr);
    if (!lr.joint_space) {
      ws.nodes[lr.bodyA].bias0.setZero();
      ws.nodes[lr.bodyB].bias0.setZero();
    }
  }
  ws.use_c = use_c;
  ws.a_world = a_world;

  // Symmetric, equilibrated Schur complement; rows the tree leaves immobile
  // (diagonal at round-off level) are not scaled up.
  for (int r = 0; r < k; ++r)
    for (int l = 0; l < r; ++l) ws.schur(r, l) = ws.schur(l, r) = 0.5 * (ws.schur(r, l) + ws.schur(l, r));
  const double dmax = ws.schur.diagonal().maxCoeff();
  for (int l = 0; l < k; ++l) {
    const double d = ws.schur(l, l);
    ws.loop_scale[l] = d > o.rank_rel_tol * dmax && d > 0 ? 1.0 / std::sqrt(d)
                       : dmax > 0                          ? 1.0 / std::sqrt(dmax)
                                                           : 1.0;
  }
  for (int r = 0; r < k; ++r)
    for (int l = 0; l < k; ++l) ws.schur(r, l) *= ws.loop_scale[r] * ws.loop_scale[l];
  ws.loop_res = ws.loop_scale.cwiseProduct(ws.loop_rhs);
  ws.schur_svd.compute(ws.schur, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const auto& s = ws.schur_svd.singularValues();
  const double thr = std::max(o.rank_abs_tol, o.rank_rel_tol * s(0));
  int rank = 0;
  while (rank < k && s(rank) > thr) ++rank;
  ws.loop_rank = rank;
  // The Schur complement B M_c⁻¹ Bᵀ squares the conditioning of the loop rows
  // (the dense solvers factor A M^{-½}, not its square): the solve loses about
  // eps·cond where they lose eps·√cond. Past 10⁴ one refinement step on the
  // full KKT residual restores the dense accuracy (two past 10¹⁰).
  const double cond = rank > 0 ? s(0) / s(rank - 1) : 1.0;
  ws.loop_refinement = cond > 1e10 ? 2 : cond > 1e4 ? 1 : 0;
  ws.loop_tmp.noalias() = ws.schur_svd.matrixU().transpose() * ws.loop_res;
  for (int l = 0; l < k; ++l) ws.loop_tmp[l] = l < rank ? ws.loop_tmp[l] / s(l) : 0.0;
  ws.loop_lambda.noalias() = ws.schur_svd.matrixV() * ws.loop_tmp;

  // Consistency: the equilibrated residual must vanish.
  ws.loop_tmp.noalias() = ws.schur * ws.loop_lambda;
  ws.loop_tmp -= ws.loop_res;
  const double res = ws.loop_tmp.lpNorm<Eigen::Infinity>();
  if (res > o.consistency_tol * std::max(1.0, ws.loop_res.lpNorm<Eigen::Infinity>())) {
    std::string names;
    for (int l = 0; l < k; ++l) {
      if (std::abs(ws.loop_tmp[l]) <= 0.01 * res) continue;
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
