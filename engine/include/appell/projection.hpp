// Drift control: keep the state on the constraint manifold.
//
// An integrator keeps A v + b = 0 and g(q, t) = 0 only up to its truncation
// error. After every step (docs/solvers.md, "Drift control"):
//  1. positions — Newton on the holonomic gaps g(q, t) = 0 (rows flagged
//     holonomic, gaps from ConstraintData::gap; A_hol assembled from those rows
//     only, A_hol = Wₐ Jₐ − W_b J_b). Each iteration takes the
//     step δ of least M-norm in velocity space with A_hol δ = −g (rank-aware:
//     redundant gap rows are fine, contradictory ones an error) and moves
//     q ← retract(q, localRate(q, 0, δ)), so quaternions stay unit by
//     construction. Using the M metric makes the correction the one that
//     disturbs the kinetic energy least; it is the same matrix as the
//     velocity projection.
//  2. velocities — the impulse solve of the chosen ConstrainedSolver
//     (projectVelocity): v⁺ = v − M⁻¹Aᵀμ with A v⁺ + b = 0, minimum-norm μ.
// Baumgarte stabilisation (Baumgarte 1972) is offered as an option only: it
// changes the dynamics (adds 2α(Av + b) + β²g to the acceleration-level
// right-hand side) instead of removing the drift after the fact.
#pragma once

#include <appell/constrained_dynamics.hpp>

#include <memory>
#include <string>
#include <vector>

namespace appell {

class TreeSolver;

struct ProjectionOptions {
  double gap_tol = 1e-12;   ///< stop when max |g| ≤ gap_tol (holonomic rows)
  /// Newton stalls at round-off on large coordinates: accept a residual below
  /// this once an iteration no longer halves it.
  double stall_tol = 1e-9;
  int max_iterations = 20;
  SolverOptions rank;       ///< rank and consistency tolerances of each step
};

struct PositionProjectionResult {
  bool ok = true;
  int iterations = 0;           ///< Newton steps taken
  double initial_residual = 0;  ///< max |g| before
  double residual = 0;          ///< max |g| after
  int rank = 0;                 ///< rank of the holonomic rows at the last step
  std::string error;            ///< why !ok
};

/// Workspace for the position projection of one system (sized at construction,
/// project() does not allocate).
class PositionProjector {
 public:
  /// Each Newton step is a tree solver's velocity projection (O(n)): its
  /// own, or `shared` — a TreeSolver built for the same model and
  /// constraints (the simulator's), which saves a second workspace.
  PositionProjector(const Model& model, const ConstraintList& constraints,
                    const ProjectionOptions& options = {}, TreeSolver* shared = nullptr);
  ~PositionProjector();
  PositionProjector(PositionProjector&&) noexcept;
  PositionProjector& operator=(PositionProjector&&) noexcept;

  /// Drives the holonomic gaps at time t to zero by moving q. On return `cdata`
  /// holds the rows evaluateConstraintRows(t, q, 0) at the final q (their
  /// covectors and b are what the velocity projection needs; κ is not). Only the
  /// holonomic rows are assembled over v, into the projector's own workspace:
  /// `cdata` needs no dense storage. On failure q is left unchanged.
  /// `rows_current`: `cdata` and `data` already hold evaluateConstraintRows at
  /// (t, q) and some v — the covectors, b and gaps do not depend on v — so the
  /// first evaluation is skipped (the simulator's feature-switch check has
  /// just made it; when the gaps are within tolerance that was the whole cost).
  PositionProjectionResult project(const Model& model, Data& data,
                                   const ConstraintList& constraints, ConstraintData& cdata,
                                   double t, VecX& q, bool rows_current = false);
  int holonomicRows() const;
  const ProjectionOptions& options() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// One-shot form (allocates its workspace).
PositionProjectionResult projectPositions(const Model& model, Data& data,
                                          const ConstraintList& constraints,
                                          ConstraintData& cdata, double t, VecX& q,
                                          const ProjectionOptions& options = {});

struct StateProjectionResult {
  bool ok = true;
  PositionProjectionResult position;
  double velocity_residual = 0;  ///< ‖A v + b‖∞ after (from the rows)
  double gap_residual = 0;       ///< max |g| after
  std::string error;
};

/// Positions (Newton, M metric) then velocities (solver.projectVelocity) at
/// time t; `impulse` receives μ. On failure q and v are left unchanged.
StateProjectionResult projectState(const Model& model, Data& data,
                                   const ConstraintList& constraints, ConstraintData& cdata,
                                   ConstrainedSolver& solver, PositionProjector& projector,
                                   double t, VecX& q, VecX& v, VecX& impulse);

/// Baumgarte stabilisation (option only): abias ← abias + 2α(A v + b) + β² g,
/// so the constraints obey ë + 2αė + β²e = 0 instead of ë = 0. Applied to the
/// rows (κ, or Ȧv + ḃ of joint-space rows), so every formulation sees it; also
/// to the dense abias when `cdata` has dense storage. `data` must hold
/// forwardKinematics(q, v) of the rows' evaluation (as evaluateConstraintRows
/// leaves it).
struct BaumgarteOptions {
  bool enabled = false;
  double alpha = 0;
  double beta = 0;
};
void applyBaumgarte(const Data& data, const ConstraintList& constraints, ConstraintData& cdata,
                    const VecX& v, double alpha, double beta);

}  // namespace appell
