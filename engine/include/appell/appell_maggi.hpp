// Dense Appell / Maggi (null-space) formulation — a reference solver, kept forever.
//
// Independent quasi-velocities e parametrise the admissible velocities,
// v = N e + η₀ with A N = 0 and A η₀ = −b (Levi-Civita & Amaldi,
// Lezioni di meccanica razionale, vol. II part 2, 1927, §56–58).
// At the acceleration level this reads  v̇ = N ė + v̇_p  with A v̇_p = −abias,
// which is the same as N ė + Ṅ e + η̇₀ since abias = Ȧv + ḃ carries every
// velocity product. Appell's equations ∂S/∂ė = Φ (the Maggi equations) are
//     Nᵀ M N ė = Nᵀ (τ − h − M v̇_p).
// The reaction is recovered afterwards as the residual r = M v̇ + h − τ; it lies
// in range(Aᵀ) (checked: ‖Q₂ᵀr‖ is reported), and λ is the minimum-norm
// solution of Aᵀλ = r.
//
// The basis N:
//   Orthonormal (default): Q₂ of a column-pivoted QR of the equilibrated Aᵀ
//     (N spans the null space of A exactly, NᵀN = I), v̇_p = Q₁ z the
//     minimum-norm particular solution. Its conditioning is that of the rows
//     themselves, so it has no coordinate singularity: at the Emelyanova–Fufaev sleigh
//     equilibrium φ = 0 the blade row (sin φ, −cos φ, 0) simply has its
//     null space spanned by (1, 0, 0) and (0, 0, 1), while the fixed partition
//     ẋ = ẏ cot φ divides by sin φ = 0.
//   CoordinatePartition: dependent velocities chosen by column pivoting of the
//     independent rows, N = [−A_d⁻¹A_i; I] (the classical Voronets/Chaplygin
//     choice), v̇_p = [A_d⁻¹c; 0]. The partition is kept while the condition
//     1/σ_min(A_d) of the equilibrated rows stays below partition_cond_max and
//     re-chosen otherwise (or when the rank changes); every re-choice is
//     counted and described (partitionChanges(), partitionMessage()).
// Rank-deficient A: the same rank decision as the KKT solver (solvers/row_basis.hpp).
#pragma once

#include <appell/constrained_dynamics.hpp>

#include <memory>
#include <vector>

namespace appell {

enum class NullSpace { Orthonormal, CoordinatePartition };

struct AppellOptions {
  NullSpace null_space = NullSpace::Orthonormal;
  /// CoordinatePartition: re-choose the dependent velocities when 1/σ_min of
  /// the (row-equilibrated) dependent block exceeds this.
  double partition_cond_max = 1e3;
  /// Relative ‖Q₂ᵀ r‖ / (‖M v̇‖ + ‖τ − h‖) above which the recovered reaction is
  /// declared outside range(Aᵀ) (an error: it means the solve lost accuracy).
  double range_tol = 1e-6;
};

class AppellSolver final : public ConstrainedSolver {
 public:
  AppellSolver(const Model& model, const ConstraintList& constraints,
               const SolverOptions& options = {}, const AppellOptions& appell = {});
  ~AppellSolver() override;

  Formulation formulation() const override { return Formulation::Appell; }
  bool usesDenseRows() const override { return true; }
  void solve(const Model& model, Data& data, const ConstraintList& constraints,
             ConstraintData& cdata, const VecX& q, const VecX& v, const VecX& tau,
             ConstrainedResult& out,
             SolveOutputs outputs = SolveOutputs::All) override;
  /// v⁺ = N e + η₀ minimising ‖v⁺ − v‖_M (NᵀM(v⁺ − v) = 0), with the impulse
  /// μ (minimum norm) such that v⁺ = v − M⁻¹Aᵀμ.
  bool projectVelocity(const Model& model, Data& data, const ConstraintList& constraints,
                       ConstraintData& cdata, const VecX& q, VecX& v, VecX& impulse) override;

  const SolverOptions& options() const { return options_; }

  /// ‖Q₂ᵀ r‖ relative to ‖M v̇‖ + ‖τ − h‖ in the last solve (0 in exact arithmetic).
  double lastRangeResidual() const;
  /// CoordinatePartition: how often the dependent velocities were re-chosen
  /// (the first choice is not counted), whether the last solve re-chose them,
  /// the condition number that triggered it and of the current partition.
  int partitionChanges() const override;
  bool partitionChangedLastSolve() const;
  double partitionCondition() const;
  /// Dependent velocity indices of the current partition (empty for Orthonormal).
  std::vector<int> dependentVelocities() const;
  /// Human-readable account of the last re-choice ("" if none). Allocates.
  std::string partitionMessage() const;
  const std::string& lastError() const override { return last_error_; }

 private:
  struct Impl;
  SolverOptions options_;
  AppellOptions appell_;
  std::unique_ptr<Impl> impl_;
  std::string last_error_;
};

}  // namespace appell
