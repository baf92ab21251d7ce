// All declared constraints of a system, evaluated together into the dense
// Pfaffian form the reference solvers use:
//     A(q, t) v + b(q, t) = 0,      A v̇ + abias = 0,   abias = Ȧ v + ḃ,
// while keeping each constraint's body-local block for the tree kernel.
#pragma once

#include <appell/constraint.hpp>

#include <memory>
#include <vector>

namespace appell {

using ConstraintList = std::vector<std::shared_ptr<const Constraint>>;

struct ConstraintData {
  ConstraintData(const Model& model, const ConstraintList& constraints);

  int m = 0;                       ///< total rows
  std::vector<int> offset;         ///< first row of each constraint
  std::vector<RowBlock> blocks;    ///< per constraint, as evaluated
  MatX A;                          ///< m × nv
  VecX b, abias;                   ///< m
  VecX gap;                        ///< m, holonomic gaps (0 for other rows)
  std::vector<char> holonomic;     ///< m, row is ġ of a gap
  std::vector<int> row_constraint; ///< m, owning constraint
  bool singular = false;           ///< some constraint reported singular geometry
  std::string singular_reason;     ///< "<constraint>: <reason>" of the first one
  MatX J;                          ///< 6 × nv scratch
};

/// Evaluates every constraint at (q, v, t) into `cdata` (blocks, A, b, abias, gaps).
/// Leaves `data` holding forwardKinematics(q, v, 0): data.a are the bias accelerations J̇v.
void evaluateConstraints(const Model& model, Data& data, const ConstraintList& constraints,
                         ConstraintData& cdata, double t, const VecX& q, const VecX& v);

/// ‖A v + b‖∞ and max |gap| of the last evaluation.
double velocityResidual(const ConstraintData& cdata, const VecX& v);
double gapResidual(const ConstraintData& cdata);

}  // namespace appell
