// Equilibria of constrained systems, including those of the second kind.
//
// A state (q, v = 0) is an equilibrium when the constrained accelerations
// vanish. With joint forces τ and gravity, Q(q) = τ − h(q, 0), that is
//     Q(q) + Aᵀ(q) λ = 0,     g(q) = 0   (the holonomic gaps),
// nv + n_h equations in nv + m unknowns (θ, λ) (local coordinates
// q = retract(q̄, θ)). Emelyanova & Fufaev (1978, docs/equilibria.md) show why the multipliers
// must stay among the unknowns: equilibria "of the second kind" are held by
// nonholonomic reactions alone, and any form that eliminates λ through a
// partition of the velocities (Chaplygin, Voronets, Appell with a fixed
// partition) loses them wherever the partition's coefficients blow up — which
// is exactly at those equilibria (the sleigh's ẋ = ẏ cot φ at φ = 0).
// The solution set is a manifold (dimension ≥ number of nonholonomic rows), so
// the solver takes minimum-norm Gauss–Newton steps, damped à la
// Levenberg–Marquardt when a step does not reduce the residual.
//
// Also needed for a static equilibrium: A·0 + b = b(q, t) = 0 and the
// acceleration offset abias(q, 0, t) = 0 (a moving support cannot hold a body
// at rest unless it moves only tangentially to itself) — checked, reported.
#pragma once

#include <appell/constraint_set.hpp>

#include <string>
#include <vector>

namespace appell {

struct EquilibriumOptions {
  VecX tau;                       ///< joint forces (size nv); empty = none
  double time = 0;                ///< t at which the constraints are evaluated
  /// Converged when ‖Q + Aᵀλ‖∞ ≤ tolerance · force_scale and ‖g‖∞ ≤ tolerance · length_scale.
  double tolerance = 1e-12;
  /// Force scale; ≤ 0: max(‖Q(q_guess)‖∞, total weight), or 1 if both vanish.
  double force_scale = -1;
  double length_scale = 1.0;      ///< metres: weights the gaps against the forces
  int max_iterations = 100;
  double fd_step = 1e-6;          ///< central-difference step in θ for ∂/∂θ
  /// Rank tolerance (relative to the largest singular value) for the local
  /// dimension of the equilibrium manifold.
  double rank_tolerance = 1e-6;
};

struct EquilibriumResult {
  bool converged = false;
  /// Human-readable outcome: "converged …" or "no equilibrium near the guess:
  /// smallest residual … after … iterations (…)".
  std::string message;
  VecX q;                  ///< the equilibrium (or the best point reached)
  VecX lambda;             ///< one multiplier per constraint row (minimum norm)
  VecX reaction;           ///< Aᵀλ (nv)
  VecX generalized_force;  ///< Q(q) = τ − h(q, 0) (nv)
  double residual = 0;     ///< max of the two scaled residuals below
  double force_residual = 0;  ///< ‖Q + Aᵀλ‖∞ (N, N·m)
  double gap_residual = 0;    ///< ‖g‖∞ over holonomic rows (m)
  double motion_residual = 0; ///< ‖b‖∞ + ‖abias(q, 0)‖∞: nonzero means a moving support
  int iterations = 0;
  int rank_A = 0;          ///< rank of A at q
  int redundant_rows = 0;  ///< m − rank A (λ then minimum-norm, not unique)
  /// Local dimension of the equilibrium set in configuration space:
  /// nullity of P ∂(Q + Aᵀλ, g)/∂θ, P removing range([Aᵀ; 0]) (the λ directions).
  int manifold_dimension = 0;
  MatX tangent;            ///< nv × manifold_dimension, orthonormal basis in θ at q
  std::vector<std::string> row_labels;  ///< "<constraint>/<row>" per λ entry
  /// Emelyanova & Fufaev's distinction: an equilibrium of the *second kind*
  /// cannot be held by the holonomic rows' reactions alone (min over λ_h of
  /// ‖Q + A_hᵀ λ_h‖∞, `holonomic_residual`, exceeds the tolerance): some
  /// nonholonomic row (a knife edge's lateral row, a rolling contact's
  /// tangential rows) must push. One of the first kind would stay at rest
  /// with the nonholonomic constraints removed.
  bool second_kind = false;
  double holonomic_residual = 0;  ///< N, N·m
};

/// Newton-type search for an equilibrium from `q_guess`. Never reports a
/// false equilibrium: converged is true only when the scaled residuals are
/// below tolerance; otherwise the result holds the best point reached.
/// Throws std::invalid_argument on sizes that do not match the model.
EquilibriumResult findEquilibrium(const Model& model, const ConstraintList& constraints,
                                  const VecX& q_guess, const EquilibriumOptions& options = {});

struct MultiStartResult {
  std::vector<EquilibriumResult> runs;  ///< one per guess, in order
  std::vector<int> distinct;            ///< indices of converged runs, duplicates removed
  /// Per entry of `distinct`, the equilibrium set it lies on (0, 1, … in
  /// order of first appearance): two equilibria share a set when the path
  /// between them (q = retract(q_a, s·θ_ab), s ∈ (0, 1)) stays on equilibria
  /// — every sampled point converges to an equilibrium within a small
  /// fraction of |θ_ab| of itself — as for a sleigh that can rest anywhere
  /// along a line of the incline.
  std::vector<int> set;
  int sets = 0;
};

/// Runs findEquilibrium from every guess; converged runs whose configurations
/// lie within `same_tol` of an earlier one (‖difference(q_i, q_j)‖∞) are duplicates.
MultiStartResult findEquilibria(const Model& model, const ConstraintList& constraints,
                                const std::vector<VecX>& guesses,
                                const EquilibriumOptions& options = {}, double same_tol = 1e-6);

}  // namespace appell
