// The O(n + m) constrained-dynamics kernel: Gauss' principle solved exactly by
// dynamic programming on the kinematic tree (Gauss 1829; Vereshchagin 1974; Sathya, Bruyninckx, Decré and Pipeleers, IEEE T-RO 2024 — docs/tree-solver.md).
//
//   minimise ½ v̇ᵀ M v̇ + v̇ᵀ(h − τ)   subject to  A v̇ + abias = 0
//
// Backward pass (leaves → root), on top of the articulated-body recursion:
// each body stacks its own constraint rows (spatial covectors on its
// acceleration, body frame) with the rows its children could not resolve,
// compresses them with a rank-revealing QR to at most 6, and splits its joint
// acceleration with an SVD of K S into a particular part fixed by the rows the
// joint resolves and a free part minimised as in ABA. Rows the joint cannot
// move are handed to the parent; the coupling of the particular part enters
// the parent's articulated inertia and bias through the projector P = 1 − S G⁺ K.
// Forward pass: accelerations, then multipliers from joint force balance,
// unrolled through the compressions with their adjoints. When rows are
// redundant, one more sweep over the bodies they reach makes λ the global
// minimum-norm one (the contract of constrained_dynamics.hpp).
//
// Rows between two moving bodies and joint-space rows close loops: they are
// auxiliary unknowns, found from a small rank-revealing Schur complement after
// one extra tree solve per row (O(k n)), factored in square-root form (the
// SVD of its kinetic-energy root, never the complement itself).
//
// Exact: no iterations, no regularisation. No heap allocation inside solve()
// or projectVelocity() once `out` has the right sizes (all workspace is sized
// by the constructor).
#pragma once

#include <appell/constrained_dynamics.hpp>

#include <memory>

namespace appell {

namespace detail {
struct TreeWorkspace;
}

class TreeSolver : public ConstrainedSolver {
 public:
  /// Sizes every workspace for this model and constraint list. Throws
  /// std::invalid_argument naming the constraint when one acts on no moving
  /// body, on a body index outside the model, or writes more than 6 body rows.
  TreeSolver(const Model& model, const ConstraintList& constraints,
             const SolverOptions& options = {});
  ~TreeSolver() override;
  TreeSolver(const TreeSolver&) = delete;
  TreeSolver& operator=(const TreeSolver&) = delete;

  Formulation formulation() const override { return Formulation::Tree; }
  /// Reads only the rows (blocks): A is never formed.
  bool usesDenseRows() const override { return false; }

  void solve(const Model& model, Data& data, const ConstraintList& constraints,
             ConstraintData& cdata, const VecX& q, const VecX& v, const VecX& tau,
             ConstrainedResult& out,
             SolveOutputs outputs = SolveOutputs::All) override;

  /// v⁺ = v − M⁻¹Aᵀμ with A v⁺ + b = 0 (the M-orthogonal projection), the
  /// same recursion with no forces, no velocity products and the velocity
  /// residual as right side; μ goes to `impulse`.
  bool projectVelocity(const Model& model, Data& data, const ConstraintList& constraints,
                       ConstraintData& cdata, const VecX& q, VecX& v, VecX& impulse) override;

  /// Number of loop-closing rows (two moving bodies or joint-space rows)
  /// handled by the Schur complement.
  int loopRows() const;
  /// Rows found redundant (or zero) by the last solve or projectVelocity:
  /// the rank of the active rows is m_active minus this.
  int redundantRows() const;
  /// Whether the last solve or projection took the one-free-body closed form
  /// (tree_solver/free_body.cpp) rather than the passes.
  bool lastSolveClosedForm() const;
  /// Whether the last solve or projection reused the factor of an earlier
  /// one at the same configuration and rows (no backward factor pass: a
  /// projection at an integrator stage's pose, the end-of-step solve after
  /// it). The answer is bit for bit the one a fresh factor gives.
  bool lastFactorReused() const;
  /// Stacks of the last factor whose rows were certified independent, so
  /// that no QR compressed them (SolverOptions::certify_independent_stacks).
  int certifiedStacks() const;
  /// Forgets the recorded factor: the next solve or projection forms it
  /// anew. For benchmarks that time whole solves at one state.
  void forgetFactor();
  const std::string& lastError() const override;

 private:
  std::unique_ptr<detail::TreeWorkspace> ws_;
};

/// The tree solver behind the ConstrainedSolver interface.
std::unique_ptr<ConstrainedSolver> makeTreeSolver(const Model& model,
                                                  const ConstraintList& constraints,
                                                  const SolverOptions& options = {});

}  // namespace appell
