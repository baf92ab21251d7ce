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
// Gauss–Seidel (Jean 1999; Acary & Brogliato 2008 §13.7): each block given
// the others — sticking by one solve with W_bb's LDLᵀ when that impulse lies
// in the cone, else its normal row, then its friction disk at that normal
// impulse (the disk's minimizer in W's metric from the block's
// eigen-decomposition, Newton on the secular equation), its equality rows
// by the LDLᵀ; both
// factors computed once per problem, not per sweep — until the natural-map
// residual
//     ‖P − Π_K(P − ρ ũ)‖ / ρ,   ρ = block size / trace(W_bb)
// (a velocity, zero exactly at a solution) is below the tolerance.
//
// Active-set finish. On redundant contacts (four tyres, four corners) W is
// singular or nearly so and Gauss–Seidel converges linearly at a rate near
// one: hundreds of sweeps for 1e-10 m/s. Once its sweeps have sorted the
// contacts into open, sticking and sliding (each sliding along −u_f), those
// modes' equalities — u = target on a sticking contact's rows, u_n = target
// and P_f = μ P_n d on a sliding one's — are one linear system A x = r in the
// pushing contacts' unknowns. It is solved for a correction of the
// Gauss–Seidel iterate — with no sliding contact (A symmetric semidefinite)
// by iterated Tikhonov regularization, δ ← δ + (A + εI)⁻¹(r − A δ), which
// leaves A's null directions alone and does not square its condition; with
// sliding ones by the shifted normal equations A Aᵀ y = r − A x, δ = Aᵀ y,
// refined, the sliding directions updated from the new u and solved
// again —, and accepted only when the result is
// cone-feasible and every block's natural-map residual meets the tolerance —
// the same test Gauss–Seidel stops on, so the answer's guarantee does not
// change. (The polishing step of Stellato et al., "OSQP: an operator
// splitting solver for quadratic programs", Math. Prog. Comp. 12, 2020,
// applied to the modes of the Coulomb problem.)
#pragma once

#include <appell/constraint_set.hpp>
#include <appell/constrained_dynamics.hpp>

#include "simulator/friction_problem.hpp"

#include <Eigen/Cholesky>

#include <memory>
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
  VecX start;          ///< the P the last solve started from
  std::vector<ProblemBlock> blocks;
  int n = 0;
  int sweeps = 0;
  double residual = 0;
  bool converged = true;
  bool polished = false;  ///< the active-set finish solved it
  /// Modes (per block: 0 open, 1 pushing, 2 sliding) from which solve() does
  /// not try the active-set finish — an earlier solve's failed finish over
  /// the same blocks, carried by the caller (MoreauJean::solveProblem).
  /// Empty: none.
  std::vector<signed char> skip_modes;

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
  /// After solve(): the modes of its last failed finish (skip_modes when it
  /// tried none but skipped those; empty when none failed), and how many
  /// finishes it tried that failed.
  const std::vector<signed char>& failedModes() const { return failed_modes_; }
  int failedFinishes() const { return failed_finishes_; }

 private:
  using Mat6 = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>;
  void factorBlocks();
  void solveBlock(int j);
  void sweep();
  double maxResidual() const;
  bool polish(double tol);
  bool polishFrom(double tol, bool from_zero);
  bool min_norm_failed_ = false;  // this solve's minimum-norm finish missed the tolerance
  // The modes of this solve's last failed finish (not retried from them), and
  // of the try under way.
  std::vector<signed char> failed_modes_, tried_modes_;
  bool opened_least_ = false;  ///< this finish opened its least loaded block
  int failed_finishes_ = 0;    ///< finishes this solve tried that failed
  bool readModes();
  void activeSet();
  bool solveModes(double tol, bool from_zero);
  bool solveActiveSet(double tol);
  bool solveNormalEquations();
  bool adjustModes(double tol);
  void expand(const VecX& x);
  // Per block, fixed within a problem: the friction disk's factor and the
  // equality rows' LDLᵀ (capacity 6: no heap).
  std::vector<detail::DiskFactor> disk_;
  std::vector<Eigen::LDLT<Mat6>> ldlt_;
  std::vector<char> stick_solve_;  ///< per block: its sticking solve by ldlt_ is well posed
  // The active-set finish's modes per block, its unknowns (a row, or a
  // sliding block's normal row with its friction along dir_; each unknown's
  // row is its equation), and workspace.
  std::vector<int> unknown_row_, unknown_block_;
  std::vector<signed char> mode_;
  std::vector<Vec3> dir_;
  MatX A_, B_;
  VecX x_, r_, y_, P_save_, u_save_, delta_;
  std::vector<int> piv_;
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
  // The mass-matrix path (respond): M and its Cholesky factor, in a Data of
  // their own so that the scene's kinematics caches stay as the solver left them.
  std::unique_ptr<Data> mass_data;
  Eigen::LLT<MatX> mass_llt;

  void reserve(const Model& model, int rows);
  /// Writes `count` rows `rows` of constraint `c` (as evaluated in `cdata`)
  /// to J and b from row `at`. `data` as evaluateConstraintRows leaves it.
  void assemble(const Model& model, const Data& data, const ConstraintList& constraints,
                const ConstraintData& cdata, int c, const int* rows, int count, int at);
  /// R's columns for the problem rows `map` (indices into J) and W = J R:
  /// one solve of `solver` per row at τ + s Jᵢᵀ, less the free one (v̇₀),
  /// over s (the map is affine in τ) — or, when no row is closed (no
  /// bilateral constraint: then R = M⁻¹Jᵀ), from one Cholesky factor of M.
  /// false with `error` when a solve fails. with_W false: R's columns only.
  bool respond(const Model& model, Data& data, const ConstraintList& constraints,
               ConstraintData& cdata, ConstrainedSolver& solver, const VecX& q, const VecX& v,
               const VecX& tau, const VecX& vdot0, const std::vector<int>& map, int n,
               ConstrainedResult& res, MatX& W, std::string& error, bool with_W = true);

 private:
  bool solvedResponses(const Model& model, Data& data, const ConstraintList& constraints,
                       ConstraintData& cdata, ConstrainedSolver& solver, const VecX& q,
                       const VecX& v, const VecX& tau0, const VecX& vdot0,
                       const std::vector<int>& map, int n, ConstrainedResult& res,
                       std::string& error);
};

}  // namespace appell::timestepping
