// Tree solver, right sides of the loop rows and iterative refinement.
//
// The tree recursion itself needs no refinement: rows a joint can barely move
// are handed up with their compliance (tree_solver_soft.cpp) instead of being
// resolved by a small pivot. Loop rows are different: their Schur complement
// B M_c⁻¹ Bᵀ is formed from unit solves and squares the conditioning of the
// loop rows, so when it is ill conditioned (cond > 10⁴, tree_solver_loops.cpp)
// one step of iterative refinement on the KKT residual (Wilkinson; Higham,
// "Accuracy and Stability of Numerical Algorithms", ch. 12) restores the dense
// solvers' accuracy. It reuses the factorization — one RNEA, O(n + m) row
// residuals and one replay with the k unit responses — and runs only then.
#include <appell/dynamics.hpp>
#include <appell/kinematics.hpp>

#include "tree_solver_workspace.hpp"

namespace appell::detail {

void loopTargets(const Model& model, const Data& data, const ConstraintData& cdata,
                 TreeWorkspace& ws, const VecX& v, bool impulse) {
  for (size_t l = 0; l < ws.loops.size(); ++l) {
    const LoopRow& lr = ws.loops[l];
    const RowBlock& blk = cdata.blocks[lr.constraint];
    double t;
    if (lr.joint_space) {
      t = impulse ? -(blk.A_joint.row(lr.row).dot(v) + blk.b_joint[lr.row])
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

void refine(const Model& model, Data& data, const ConstraintData& cdata, TreeWorkspace& ws,
            const VecX& q, const VecX& v, const VecX& tau, bool impulse) {
  ws.vdot_acc = ws.vdot;
  ws.lambda_acc = ws.lambda;

  // Force residual r_f = τ − (M v̇ + h) + Aᵀλ   (impulse: −M Δ + Aᵀλ).
  if (impulse) {
    ws.tau.setZero();
    ws.resid_f = rnea(model, data, q, ws.tau, ws.tau);      // g(q)
    ws.resid_f -= rnea(model, data, q, ws.tau, ws.vdot_acc);  // −M Δ
  } else {
    ws.resid_f = tau;
    ws.resid_f -= rnea(model, data, q, v, ws.vdot_acc);
  }
  reactionForces(model, data, cdata, ws, ws.lambda_acc, ws.tau);
  ws.resid_f += ws.tau;

  // Row residuals r_c = −(A x + rhs) at the current solution.
  if (impulse) {
    ws.tau = v + ws.vdot_acc;
    forwardKinematics(model, data, q, ws.tau);
  } else {
    forwardKinematics(model, data, q, v, ws.vdot_acc);
  }
  for (auto& tb : ws.blocks) {
    const RowBlock& blk = cdata.blocks[tb.constraint];
    const RowMatrix6& W = tb.sign > 0 ? blk.Wa : blk.Wb;
    const Vec6 x = data.oMi[tb.body].act(impulse ? data.v[tb.body] : data.a[tb.body]);
    for (int r = 0; r < tb.rows; ++r)
      tb.rhs[r] = -(tb.sign * W.row(r).dot(x) + (impulse ? blk.b[r] : blk.kappa[r]));
  }
  for (size_t l = 0; l < ws.loops.size(); ++l) {
    const LoopRow& lr = ws.loops[l];
    const RowBlock& blk = cdata.blocks[lr.constraint];
    if (lr.joint_space) {
      ws.loop_target[l] =
          impulse ? -(blk.A_joint.row(lr.row).dot(ws.tau) + blk.b_joint[lr.row])
                  : -(blk.A_joint.row(lr.row).dot(ws.vdot_acc) + blk.abias_joint[lr.row]);
    } else {
      const auto& x = impulse ? data.v : data.a;
      const Vec6 xA = data.oMi[lr.bodyA].act(x[lr.bodyA]);
      const Vec6 xB = data.oMi[lr.bodyB].act(x[lr.bodyB]);
      ws.loop_target[l] = -(blk.Wa.row(lr.row).dot(xA) - blk.Wb.row(lr.row).dot(xB) +
                            (impulse ? blk.b[lr.row] : blk.kappa[lr.row]));
    }
  }

  // The correction solves the same KKT system with these right sides.
  for (auto& nd : ws.nodes) nd.bias0.setZero();
  ws.tau = ws.resid_f;
  ws.a_world.setZero();
  ws.use_c = false;
  biasPass(model, data, ws, false);
  forwardPass(model, data, ws, false);
  const bool loops_ok = solveLoops(model, data, cdata, ws);
  if (loops_ok) {
    ws.vdot += ws.vdot_acc;
    ws.lambda += ws.lambda_acc;
  } else {
    ws.vdot = ws.vdot_acc;
    ws.lambda = ws.lambda_acc;
  }
  // Leave data as the callers expect it: kinematics at (q, v).
  forwardKinematics(model, data, q, v);
}

}  // namespace appell::detail
