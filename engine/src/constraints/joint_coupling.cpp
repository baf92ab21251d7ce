#include <appell/joint_coupling.hpp>

#include <cmath>
#include <stdexcept>

namespace appell {

JointCoupling::JointCoupling(const Model& model, int follower, int leader, double multiplier,
                             double offset)
    : follower_(follower), leader_(leader), multiplier_(multiplier), offset_(offset) {
  for (int j : {follower, leader})
    if (j < 0 || j >= model.nbodies)
      throw std::invalid_argument("joint coupling: no joint " + std::to_string(j));
  const std::string& fname = model.joint_names[follower];
  const std::string& lname = model.joint_names[leader];
  name_ = fname + "_mimic";
  auto fail = [&](const std::string& why) {
    throw std::invalid_argument("joint '" + fname + "' mimicking '" + lname + "': " + why);
  };
  if (follower == leader) fail("a joint cannot mimic itself");
  for (int j : {follower, leader})
    if (!oneDofJoint(model.joints[j].type))
      fail(std::string("'") + model.joint_names[j] + "' is a " + toString(model.joints[j].type) +
           " joint; only revolute, continuous and prismatic joints can be coupled");
  if (!std::isfinite(multiplier) || !std::isfinite(offset)) fail("multiplier and offset must be finite");
  fq_ = model.joints[follower].idx_q;
  fv_ = model.joints[follower].idx_v;
  lq_ = model.joints[leader].idx_q;
  lv_ = model.joints[leader].idx_v;
}

void JointCoupling::reserve(const Model& model, RowBlock& block) const {
  Constraint::reserve(model, block);
  block.gap = RowVector6::Zero(1);
}

void JointCoupling::evaluate(const Model&, const Data& data, double, const VecX& q, const VecX&,
                             RowBlock& out) const {
  out.m = 1;
  out.A_joint.setZero();
  out.A_joint(0, 0) = 1;              // ġ = v_f − m v_l (columns fv_, lv_)
  out.A_joint(0, 1) = -multiplier_;
  out.b_joint[0] = 0;
  out.abias_joint[0] = 0;
  out.gap[0] = q[fq_] - multiplier_ * q[lq_] - offset_;
  out.frame.point = data.oMi[follower_].p;  // where the follower's body is
  out.frame.gap = out.gap[0];
}

}  // namespace appell
