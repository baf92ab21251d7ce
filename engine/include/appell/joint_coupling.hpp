// A linear coupling of two one-degree-of-freedom joints (URDF <mimic>).
//
// The follower f is held at
//     q_f = m · q_l + o          (m: multiplier, o: offset; l: the leader)
// as one holonomic, bilateral joint-space row
//     g = q_f − m q_l − o = 0,     ġ = v_f − m v_l,     g̈ = v̇_f − m v̇_l
// (no velocity-product term: the row is constant in q). Its multiplier λ is
// the generalized force the coupling applies to the follower — a torque for a
// revolute joint, a force for a prismatic one — and −m λ on the leader: the
// gear or linkage that a mimic joint stands for, doing no work (λ ġ = 0).
// The tree solver takes the row as it takes every joint-space row (a closed
// loop: tree_solver.hpp); ROS tools mean the same by <mimic> (the ROS URDF
// specification: value = multiplier · other_joint_value + offset).
#pragma once

#include <appell/constraint.hpp>

namespace appell {

class JointCoupling : public Constraint {
 public:
  /// Throws std::invalid_argument (naming the joints) unless both joints are
  /// revolute, continuous or prismatic and distinct, and m, o are finite.
  JointCoupling(const Model& model, int follower, int leader, double multiplier, double offset);

  /// "<follower>_mimic"; its row is "coupling" (CSV lambda:<follower>_mimic.coupling).
  const std::string& name() const override { return name_; }
  int rows() const override { return 1; }
  int bodyA() const override { return follower_; }
  RowKind rowKind(int) const override { return RowKind::Custom; }
  std::string rowLabel(int) const override { return "coupling"; }
  bool holonomic(int) const override { return true; }
  bool jointSpace() const override { return true; }
  /// The follower's and the leader's velocities (columns 0 and 1 of A_joint).
  std::vector<int> jointColumns(const Model&) const override { return {fv_, lv_}; }
  void reserve(const Model& model, RowBlock& block) const override;
  void evaluate(const Model& model, const Data& data, double t, const VecX& q, const VecX& v,
                RowBlock& out) const override;

  int follower() const { return follower_; }
  int leader() const { return leader_; }
  double multiplier() const { return multiplier_; }
  double offset() const { return offset_; }

 private:
  int follower_, leader_;
  int fq_, fv_, lq_, lv_;
  double multiplier_, offset_;
  std::string name_;
};

}  // namespace appell
