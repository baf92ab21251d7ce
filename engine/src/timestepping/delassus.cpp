// The Delassus operator of the Moreau–Jean step from the scene's own solver.
//
// With only the bilateral rows G closed, a solve's v̇ is affine in the joint
// forces: v̇(τ + s Jᵢᵀ) − v̇(τ) = s (M⁻¹ − M⁻¹Gᵀ(GM⁻¹Gᵀ)⁺GM⁻¹) Jᵢᵀ, the response
// Rᵢ of the velocity to a unit impulse along contact row i that the
// bilateral constraints transmit. So R costs one O(n) solve per row (the
// tree solver's; the dense ones as they are) and W = J R is the contact
// rows' mutual response, the Delassus operator (Moreau 1988; Acary &
// Brogliato 2008 §10.1) — no mass matrix is formed.
#include "timestepping/contact_problem.hpp"

#include <appell/kinematics.hpp>

#include <algorithm>

namespace appell::timestepping {

void Delassus::reserve(int nv, int rows) {
  J = MatX::Zero(std::max(rows, 1), nv);
  b = VecX::Zero(std::max(rows, 1));
  R = MatX::Zero(nv, std::max(rows, 1));
  A = MatX::Zero(6, nv);
  body_J = MatX::Zero(6, nv);
  abias = VecX::Zero(6);
  tau = VecX::Zero(nv);
}

void Delassus::assemble(const Model& model, const Data& data, const ConstraintList& constraints,
                        const ConstraintData& cdata, int c, const int* rows, int count, int at) {
  const Constraint& con = *constraints[c];
  const RowBlock& blk = cdata.blocks[c];
  const int m = con.rows();
  assembleConstraintRows(model, data, con, blk, body_J, A.topRows(m), abias.head(m));
  for (int k = 0; k < count; ++k) {
    J.row(at + k) = A.row(rows[k]);
    b[at + k] = con.jointSpace() ? blk.b_joint[rows[k]] : blk.b[rows[k]];
  }
}

bool Delassus::respond(const Model& model, Data& data, const ConstraintList& constraints,
                       ConstraintData& cdata, ConstrainedSolver& solver, const VecX& q,
                       const VecX& v, const VecX& tau0, const VecX& vdot0,
                       const std::vector<int>& map, int n, ConstrainedResult& res, MatX& W,
                       std::string& error, bool with_W) {
  // At the scale of the forces (any scale is exact up to round-off relative
  // to τ; the weight and τ set that round-off).
  const double s = std::max({1.0, tau0.lpNorm<Eigen::Infinity>(),
                             model.totalMass() * model.gravity.norm()});
  for (int i = 0; i < n; ++i) {
    tau = tau0;
    tau.noalias() += s * J.row(map[i]).transpose();
    solver.solve(model, data, constraints, cdata, q, v, tau, res, SolveOutputs::Accelerations);
    if (!res.ok) {
      error = "the Delassus operator's solve failed: " + res.error;
      return false;
    }
    R.col(i) = (res.vdot - vdot0) / s;
  }
  if (!with_W) return true;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) W(i, j) = J.row(map[i]).dot(R.col(j));
  // Symmetric in exact arithmetic: remove the round-off's skew part.
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < i; ++j) W(i, j) = W(j, i) = 0.5 * (W(i, j) + W(j, i));
  return true;
}

}  // namespace appell::timestepping
