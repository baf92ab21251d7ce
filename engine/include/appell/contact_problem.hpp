// The frictional contact problem of one time-stepping step, as data, and
// appell's solver for it as its own type (docs/contacts.md §10).
//
// A Moreau–Jean step (Acary & Brogliato 2008, Numerical Methods for
// Nonsmooth Dynamical Systems, ch. 13) reduces to impulses P over contact
// blocks [n, f₁…f_nf, e₁…e_ne] with
//     u = W P + u_free,    W = J M⁻¹ Jᵀ under the bilateral rows (Delassus),
// and per block, with t the block's targets (zero but on the normal row:
// its gap or Newton's restitution): u_n − t_n ≥ 0 ⊥ P_n ≥ 0; the friction
// rows in Coulomb's cone |P_f| ≤ μ P_n with maximal dissipation (De Saxcé's
// form, on the modified velocity u_n − t_n + μ|u_f|); equality rows u_e = t_e
// while the block pushes. A block of one normal and two friction rows is
// exactly the problem of Siconos' fc3d solvers (Acary, Brémond & Huber,
// "On solving contact problems with Coulomb friction: formulations and
// numerical comparisons", 2018) with q = u_free − t.
//
// Simulator::contactProblem copies the last time-stepping step's problem;
// ContactProblemSolver solves such a problem with the engine's own
// non-smooth block Gauss–Seidel and active-set finish — the same code, so
// re-solving a recorded problem from its warm start reproduces the step's
// impulses bit for bit. Together they let a user check, time or replace the
// engine's solver on the problems their own scene makes.
#pragma once

#include <appell/spatial.hpp>

#include <memory>
#include <vector>

namespace appell {

/// One contact's rows in a ContactProblemData.
struct ContactProblemBlock {
  int constraint = -1;    ///< its index in the simulator's constraint list
  int first = 0;          ///< its normal row; friction rows follow, then equality rows
  int friction_rows = 0;  ///< 0 (frictionless), 1 (a knife edge's) or 2 (a cone)
  int equality_rows = 0;  ///< rows held while it pushes (ideal rolling)
  double mu = 0;          ///< the cone this step uses (kinetic after a slip)
};

/// A contact problem u = W P + u_free (see the top of this file).
struct ContactProblemData {
  double t = 0;                 ///< the step's start
  MatX W;                       ///< n × n, symmetric positive semidefinite
  VecX u_free, target;          ///< n each
  VecX warm_start;              ///< the impulses the solve started from
  /// Per block, the modes (0 open, 1 pushing, 2 sliding) from which the
  /// step did not try the active-set finish: those of an earlier step's
  /// failed finish over the same contacts (docs/contacts.md §10); empty
  /// when it skipped none. ContactProblemSolver skips them too.
  std::vector<int> skipped_finish_modes;
  VecX P;                       ///< the step's impulses (N s)
  std::vector<ContactProblemBlock> blocks;
  int sweeps = 0;               ///< Gauss–Seidel sweeps the step took
  double residual = 0;          ///< its natural-map residual (m/s)
  bool converged = false;
  int rows() const { return static_cast<int>(u_free.size()); }
};

/// The engine's contact-problem solver over one problem (copied in).
class ContactProblemSolver {
 public:
  struct Result {
    int sweeps = 0;
    double residual = 0;     ///< max over blocks of ‖P − Π_K(P − ρ ũ)‖/ρ, ρ = rows/trace W_bb (m/s)
    bool converged = false;  ///< residual ≤ tol · max(1, |u_free|∞)
    bool polished = false;   ///< the active-set finish ended it
  };
  /// Throws std::invalid_argument when the blocks do not tile the rows, a
  /// size disagrees, a number is not finite, or skipped_finish_modes is
  /// neither empty nor one mode in {0, 1, 2} per block.
  explicit ContactProblemSolver(const ContactProblemData& problem);
  ~ContactProblemSolver();
  ContactProblemSolver(ContactProblemSolver&&) noexcept;
  ContactProblemSolver& operator=(ContactProblemSolver&&) noexcept;

  /// Solves from `start` (size n) to `tol` or `max_sweeps`; P and u = W P +
  /// u_free are the answer. Allocates nothing once P and u have n rows.
  /// Throws std::invalid_argument for a start of another size or not finite.
  Result solve(const VecX& start, double tol, int max_sweeps, VecX& P, VecX& u);
  /// The natural-map residual of impulses P (the solver's stopping measure).
  double residual(const VecX& P);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace appell
