// Constrained forward dynamics: the interface every formulation implements.
//
//   M v̇ + h = τ + Aᵀλ,      A v̇ + abias = 0          (Neimark & Fufaev 1967)
//
// Three formulations give the same v̇ and the same reaction Aᵀλ:
//   Multipliers  dense KKT (reference)                       kkt.hpp
//   Appell       dense null-space / Maggi equations          appell_maggi.hpp
//   Tree         Gauss' principle by dynamic programming on
//                the kinematic tree, O(n + m) (the default)  tree_solver.hpp
// The λ contract (the one statement of it; docs and solvers refer here):
// with redundant rows λ is not unique, and every formulation returns the same
// one, the minimum-norm solution of Aᵀλ = M v̇ + h − τ (equivalently the
// unique solution in range(A)), so reported reactions never depend on the
// formulation. The impulse of projectVelocity() is the minimum-norm one too.
// `redundant` = m − rank(A), the rank decided with SolverOptions' tolerances
// on equilibrated rows. Inconsistent rows (no v̇ satisfies them) are an error,
// reported in the result — never a silently wrong v̇.
#pragma once

#include <appell/constraint_set.hpp>
#include <appell/name_table.hpp>

#include <memory>
#include <string>

namespace appell {

enum class Formulation { Tree, Multipliers, Appell };
/// Every formulation with its names ("tree", "kkt"/"multipliers",
/// "appell"/"maggi"): the one list that parsing, error messages, the scene
/// format and the command-line help read.
std::span<const NamedValue<Formulation>> formulationTable();
const char* toString(Formulation f);  ///< the canonical name
/// Parses any name or alias of formulationTable(); throws std::invalid_argument
/// listing them all otherwise.
Formulation formulationFromString(const std::string& name);

struct SolverOptions {
  double rank_abs_tol = 1e-10;   ///< absolute rank tolerance on equilibrated rows
  double rank_rel_tol = 1e-10;   ///< relative rank tolerance
  double consistency_tol = 1e-8; ///< residual above which redundant rows are inconsistent
  /// Tree solver: a model of one body on a floating joint, its rows resolved
  /// whole, is solved in closed form (tree_solver/free_body.cpp); false runs
  /// the general passes there too (the tests compare the two).
  bool free_body_closed_form = true;
  /// Tree solver: a body's one stack of rows (one constraint's, or one
  /// child's handed-up rows) certified independent skips the compression's
  /// QR (tree_solver/backward.cpp); false factors every stack (the tests
  /// compare the two).
  bool certify_independent_stacks = true;
};

/// What a solve must produce. Integrator stages need only v̇; reports need λ.
/// The minimum-norm λ costs the tree solver an extra sweep when rows are
/// redundant across bodies (docs/tree-solver.md), so stages skip it.
enum class SolveOutputs {
  All,            ///< v̇, the minimum-norm λ, Aᵀλ, rank
  Accelerations,  ///< v̇ and rank only; λ and Aᵀλ are left unspecified
};

struct ConstrainedResult {
  VecX vdot;                 ///< nv
  VecX lambda;               ///< m, one multiplier per row (minimum norm: see above)
  VecX reaction;             ///< nv, Aᵀλ
  int rank = 0;              ///< rank of A
  int redundant = 0;         ///< m − rank
  bool ok = true;
  std::string error;         ///< why !ok (inconsistent rows, singular geometry, …)
};

class ConstrainedSolver {
 public:
  virtual ~ConstrainedSolver() = default;
  virtual Formulation formulation() const = 0;
  /// Whether solve() and projectVelocity() assemble the dense A (m × nv): then
  /// the ConstraintData they are given needs DenseRows::Sized storage. The tree
  /// solver reads only the rows.
  virtual bool usesDenseRows() const = 0;
  /// Accelerations and reactions at (t, q, v) under joint forces τ (gravity from
  /// the model). `cdata` must hold the rows at (t, q, v) (evaluateConstraintRows;
  /// a dense solver assembles A and abias itself); `data` is workspace.
  /// `outputs`: everything, or v̇ alone (what an integrator stage needs).
  virtual void solve(const Model& model, Data& data, const ConstraintList& constraints,
                     ConstraintData& cdata, const VecX& q, const VecX& v, const VecX& tau,
                     ConstrainedResult& out, SolveOutputs outputs = SolveOutputs::All) = 0;
  /// Impulse solve for drift control: v ← argmin ‖v⁺ − v‖_M subject to A v⁺ + b = 0,
  /// with the rows in `cdata` evaluated at q. Writes the impulses (m) to `impulse`.
  /// Returns false (v untouched, lastError() says why) when the rows are inconsistent.
  virtual bool projectVelocity(const Model& model, Data& data, const ConstraintList& constraints,
                               ConstraintData& cdata, const VecX& q, VecX& v, VecX& impulse) = 0;
  /// Why the last solve() or projectVelocity() failed (empty after a success).
  virtual const std::string& lastError() const = 0;
  /// How often the solver re-chose which velocities are dependent (only the
  /// Appell solver's coordinate partition does; 0 for the others).
  virtual int partitionChanges() const { return 0; }
};

/// Builds the solver for a formulation, with its workspace sized for this system.
std::unique_ptr<ConstrainedSolver> makeSolver(Formulation f, const Model& model,
                                              const ConstraintList& constraints,
                                              const SolverOptions& options = {});

}  // namespace appell
