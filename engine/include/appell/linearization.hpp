// Linearization of constrained dynamics about an equilibrium or a steady motion.
//
// State x = (θ, v) in local coordinates around the reference q* (q = retract(q*, θ)),
// flow f(x) = (θ̇, v̇) = (localRate(q*, θ, v), v̇ from any ConstrainedSolver).
// The motion stays on the constraint manifold
//     𝓜 = { g(q) = 0 (holonomic gaps),  A(q) v + b(q, t) = 0 },
// so the linearization is taken in independent coordinates on it: an
// orthonormal basis Z of T𝓜 = null ∂(g, A v + b)/∂(θ, v) (from an SVD), and the
// reduced matrix L = Zᵀ (∂f/∂x) Z, whose columns are central differences of f
// along the columns of Z. At an equilibrium f(x*) = 0 and ∂f maps T𝓜 into
// itself, so L is the matrix of the linearized flow on 𝓜.
//
// Steady motions (relative equilibria): the user names cyclic coordinates —
// θ indices the dynamics do not depend on (position, heading and spin of a
// rolling disk built with planar/revolute joints). Their rates may be nonzero
// (the drift); the reduced state drops them: x_r = (θ without the cyclic
// entries, v), f_r = (their θ̇, v̇). The reference must make f_r = 0 (reported
// as steady_residual), and f must not depend on the cyclic entries (reported
// as symmetry_residual) — both are checked numerically, not assumed.
#pragma once

#include <appell/constrained_dynamics.hpp>

#include <Eigen/Eigenvalues>

#include <string>
#include <vector>

namespace appell {

struct LinearizationOptions {
  VecX tau;                 ///< joint forces (size nv, held constant); empty = none
  double time = 0;          ///< t of the (time-independent) constraints
  std::vector<int> cyclic;  ///< θ indices of cyclic coordinates (empty: an equilibrium)
  /// Central-difference step along unit directions of x, scaled by max(1, ‖x*‖∞).
  double fd_step = 1e-5;
  /// Relative singular-value tolerance for the constraint Jacobian's rank.
  double rank_tolerance = 1e-9;
};

struct LinearizationResult {
  int dimension = 0;            ///< k = dim T𝓜 (reduced)
  std::vector<int> retained;    ///< θ indices kept (all but the cyclic ones)
  /// (nθ_r + nv) × k orthonormal basis of T𝓜 in x_r = (θ_retained, v).
  MatX basis;
  MatX matrix;                  ///< k × k reduced linearization L
  Eigen::VectorXcd eigenvalues; ///< of L (Eigen::EigenSolver)
  VecX drift;                   ///< θ̇ at the reference (nv): the cyclic rates of a steady motion
  double steady_residual = 0;   ///< ‖f_r(x*)‖∞: 0 for an equilibrium / relative equilibrium
  double symmetry_residual = 0; ///< max |∂f_r/∂θ_c| over cyclic c (0 when truly cyclic)
  double constraint_residual = 0;  ///< ‖(g, A v + b)‖∞ at the reference
};

/// Linearizes at (q, v) (v = 0 for an equilibrium) with `solver` for v̇.
/// Throws std::invalid_argument on bad sizes or cyclic indices, and
/// std::runtime_error naming the reason when the solver fails at a probe.
LinearizationResult linearize(const Model& model, const ConstraintList& constraints,
                              ConstrainedSolver& solver, const VecX& q, const VecX& v,
                              const LinearizationOptions& options = {});

/// Number of eigenvalues with |μ| ≤ tol (tol absolute).
int countZeroEigenvalues(const LinearizationResult& result, double tol);

}  // namespace appell
