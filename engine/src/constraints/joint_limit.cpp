#include <appell/joint_limit.hpp>

#include <cmath>
#include <stdexcept>

namespace appell {

JointLimit::JointLimit(const Model& model, int joint, LimitSide side, double restitution)
    : joint_(joint), side_(side) {
  law_.restitution = restitution;
  if (joint < 0 || joint >= model.nbodies)
    throw std::invalid_argument("joint limit: no joint " + std::to_string(joint));
  const Joint& j = model.joints[joint];
  const std::string& jname = model.joint_names[joint];
  name_ = jname + (side == LimitSide::Lower ? "_lower_limit" : "_upper_limit");
  auto fail = [&](const std::string& why) {
    throw std::invalid_argument("joint limit of '" + jname + "': " + why);
  };
  if (j.type != JointType::Revolute && j.type != JointType::Prismatic)
    fail(std::string("a ") + toString(j.type) + " joint has no position limit (revolute and prismatic only)");
  bound_ = side == LimitSide::Lower ? j.limits.lower : j.limits.upper;
  if (!std::isfinite(bound_)) fail("the bound is not finite");
  if (j.limits.lower > j.limits.upper) fail("lower > upper");
  if (!(restitution >= 0 && restitution <= 1)) fail("restitution must lie in [0, 1]");
  sign_ = side == LimitSide::Lower ? 1.0 : -1.0;
  iq_ = j.idx_q;
  iv_ = j.idx_v;
}

void JointLimit::reserve(const Model& model, RowBlock& block) const {
  Constraint::reserve(model, block);
  block.gap = RowVector6::Zero(1);
}

void JointLimit::evaluate(const Model& model, const Data& data, double, const VecX& q, const VecX&,
                          RowBlock& out) const {
  (void)model;
  out.m = 1;
  out.A_joint.setZero();
  out.A_joint(0, 0) = sign_;  // ġ = ±q̇ (column iv_)
  out.b_joint[0] = 0;
  out.abias_joint[0] = 0;
  out.gap[0] = sign_ * (q[iq_] - bound_);
  out.frame.point = data.oMi[joint_].p;  // where the limited joint's body is
  out.frame.gap = out.gap[0];
}

}  // namespace appell
