// Joint position limits as unilateral constraints.
//
// A revolute or prismatic joint with a limit on side s keeps the gap
//     lower side:  g = q − q_lower ≥ 0,     row  +q̇ (λ > 0 pushes q up),
//     upper side:  g = q_upper − q ≥ 0,     row  −q̇ (λ > 0 pushes q down),
// as a one-row joint-space constraint that is unilateral (constraint.hpp):
// open while the joint is inside its range, closed when it reaches the
// limit (a touchdown: an impact with Newton's restitution e on q̇ — e = 0
// stops the joint there, e = 1 reverses it at the same speed), and open
// again when its multiplier would pull (the joint torque or force turns away
// from the limit). λ is the limit's torque (revolute) or force (prismatic).
// The events are the simulator's (contact_events.hpp); nothing here is
// specific to limits beyond the row.
#pragma once

#include <appell/constraint.hpp>

namespace appell {

enum class LimitSide { Lower, Upper };

class JointLimit : public Constraint {
 public:
  /// Throws std::invalid_argument (naming the joint) for a joint that is not
  /// revolute or prismatic, an infinite or NaN bound, or e outside [0, 1].
  JointLimit(const Model& model, int joint, LimitSide side, double restitution = 0);

  const std::string& name() const override { return name_; }
  int rows() const override { return 1; }
  int bodyA() const override { return joint_; }
  RowKind rowKind(int) const override { return RowKind::Normal; }
  /// "limit": CSV column lambda:<joint>_lower_limit.limit.
  std::string rowLabel(int) const override { return "limit"; }
  bool holonomic(int) const override { return true; }
  bool jointSpace() const override { return true; }
  /// The limited joint's one velocity: the tree solver takes the row inside
  /// its factor pass (a closed limit locks the joint), O(1) per limit.
  std::vector<int> jointColumns(const Model&) const override { return {iv_}; }
  int unilateralRow() const override { return 0; }
  void reserve(const Model& model, RowBlock& block) const override;
  void evaluate(const Model& model, const Data& data, double t, const VecX& q, const VecX& v,
                RowBlock& out) const override;

  int joint() const { return joint_; }
  LimitSide side() const { return side_; }
  double bound() const { return bound_; }

 private:
  int joint_, iq_, iv_;
  LimitSide side_;
  double bound_, sign_;
  std::string name_;
};

}  // namespace appell
