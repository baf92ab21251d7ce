// The Delassus operator of the Moreau–Jean step from the scene's own solver.
//
// With only the bilateral rows G closed, a solve's v̇ is affine in the joint
// forces: v̇(τ + s Jᵢᵀ) − v̇(τ) = s (M⁻¹ − M⁻¹Gᵀ(GM⁻¹Gᵀ)⁺GM⁻¹) Jᵢᵀ, the response
// Rᵢ of the velocity to a unit impulse along contact row i that the
// bilateral constraints transmit. So R costs one O(n) solve per row (the
// tree solver's; the dense ones as they are) and W = J R is the contact
// rows' mutual response, the Delassus operator (Moreau 1988; Acary &
// Brogliato 2008 §10.1). Where no row is closed — a vehicle or a legged
// robot whose only constraints are its contacts, all released for the step —
// that projection is the identity and R = M⁻¹Jᵀ: one mass matrix by the
// composite-rigid-body algorithm (Featherstone 2008, §6.2), one Cholesky
// factor and n triangular solves of size nv, instead of n solves of the
// scene's solver — the same operator up to round-off (on cad_car 14 % of an
// `auto` run went to the n solves).
#include "timestepping/contact_problem.hpp"

#include <appell/dynamics.hpp>
#include <appell/kinematics.hpp>

#include <algorithm>

namespace appell::timestepping {

void Delassus::reserve(const Model& model, int rows) {
  const int nv = model.nv;
  mass_data = std::make_unique<Data>(model, MassMatrix::Sized);
  mass_llt = Eigen::LLT<MatX>(nv);
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
  if (cdata.m_active == 0) {
    mass_llt.compute(crba(model, *mass_data, q));
    if (mass_llt.info() != Eigen::Success) {
      error = "the Delassus operator's mass matrix is not positive definite";
      return false;
    }
    for (int i = 0; i < n; ++i) R.col(i) = J.row(map[i]).transpose();
    mass_llt.solveInPlace(R.leftCols(n));
  } else if (!solvedResponses(model, data, constraints, cdata, solver, q, v, tau0, vdot0, map, n, res, error)) {
    return false;
  }
  if (!with_W) return true;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) W(i, j) = J.row(map[i]).dot(R.col(j));
  // Symmetric in exact arithmetic: remove the round-off's skew part.
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < i; ++j) W(i, j) = W(j, i) = 0.5 * (W(i, j) + W(j, i));
  return true;
}

// R's columns by the scene's solver, one solve per row.
bool Delassus::solvedResponses(const Model& model, Data& data, const ConstraintList& constraints,
                               ConstraintData& cdata, ConstrainedSolver& solver, const VecX& q,
                               const VecX& v, const VecX& tau0, const VecX& vdot0,
                               const std::vector<int>& map, int n, ConstrainedResult& res,
                               std::string& error) {
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
  return true;
}

}  // namespace appell::timestepping
