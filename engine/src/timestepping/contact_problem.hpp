// The per-step contact problem of the Moreau–Jean scheme and its Delassus
// operator (moreau_jean.hpp).
//
// Problem. Impulses P over contact blocks [n, f₁…f_nf, e₁…e_ne] with
//     u = u_free + W P
// and per block: the normal row u_n ≥ t_n ⊥ P_n ≥ 0 (t_n = −e u⁻ₙ, Newton's
// restitution); the friction rows in Coulomb's cone |P_f| ≤ μ P_n with the
// maximal-dissipation law, in De Saxcé's form
//     K* ∋ (u_n − t_n + μ|u_f|, u_f) ⊥ P ∈ K = {|P_f| ≤ μ P_n}
// (De Saxcé & Feng, "New inequality and functional for contact with
// friction", Mech. Struct. Mach. 19, 1991); equality rows u_e = 0 while the
// block pushes (P_n > 0), P = 0 otherwise. Solved by non-smooth block
// Gauss–Seidel (Jean 1999; Acary & Brogliato 2008 §13.7): each block exactly
// given the others — its normal row and its friction disk alternated to their
// fixed point (the disk's minimizer in W's metric, friction_onset.cpp), its
// equality rows by one LDLᵀ — until the natural-map residual
//     ‖P − Π_K(P − ρ ũ)‖ / ρ,   ρ = block size / trace(W_bb)
// (a velocity, zero exactly at a solution) is below the tolerance.
#pragma once

#include <appell/constraint_set.hpp>
#include <appell/constrained_dynamics.hpp>

#include <string>
#include <vector>

namespace appell::timestepping {

struct ProblemBlock {
  int first = 0;   ///< its normal row; friction rows follow, then equality rows
  int nf = 0, ne = 0;
  double mu = 0;
  int rows() const { return 1 + nf + ne; }
};

struct ContactProblem {
  MatX W;              ///< n × n (symmetric positive semidefinite)
  VecX u_free, target, P, u;
  std::vector<ProblemBlock> blocks;
  int n = 0;
  int sweeps = 0;
  double residual = 0;
  bool converged = true;

  /// Sizes everything for at most `rows` rows in `contacts` blocks.
  void reserve(int rows, int contacts);
  void clear() {
    blocks.clear();  // (keeps its capacity)
    n = 0;
  }
  /// Appends a block; returns its first row.
  int add(int nf, int ne, double mu);
  /// Non-smooth Gauss–Seidel from the P given (a warm start) until the
  /// residual is ≤ tol or max_sweeps sweeps; sets sweeps, residual, converged, u.
  void solve(double tol, int max_sweeps);
  /// The block's natural-map residual at the current P and u (m/s).
  double blockResidual(const ProblemBlock& b) const;

 private:
  void solveBlock(const ProblemBlock& b);
};

/// The candidates' rows as a dense J over v (O(rows · nv)), and the
/// Delassus operator W = J R, R = P_G M⁻¹ Jᵀ, of the rows of a problem.
struct Delassus {
  MatX J;          ///< max rows × nv: every unilateral row the scheme uses
  VecX b;          ///< their velocity offsets (u = J v + b)
  MatX R;          ///< nv × max rows: responses of the problem's rows
  MatX A;          ///< 6 × nv: one constraint's rows (scratch)
  MatX body_J;     ///< 6 × nv scratch
  VecX abias, tau;

  void reserve(int nv, int rows);
  /// Writes `count` rows `rows` of constraint `c` (as evaluated in `cdata`)
  /// to J and b from row `at`. `data` as evaluateConstraintRows leaves it.
  void assemble(const Model& model, const Data& data, const ConstraintList& constraints,
                const ConstraintData& cdata, int c, const int* rows, int count, int at);
  /// R's columns for the problem rows `map` (indices into J) and W = J R:
  /// one solve of `solver` per row at τ + s Jᵢᵀ, less the free one (v̇₀),
  /// over s (the map is affine in τ). false with `error` when a solve fails.
  bool respond(const Model& model, Data& data, const ConstraintList& constraints,
               ConstraintData& cdata, ConstrainedSolver& solver, const VecX& q, const VecX& v,
               const VecX& tau, const VecX& vdot0, const std::vector<int>& map, int n,
               ConstrainedResult& res, MatX& W, std::string& error);
};

}  // namespace appell::timestepping
