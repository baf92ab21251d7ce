// The kinematic tree's small queries, and ModelBuilder: the structure checked body by
// body; the inertias judged and repaired per rigid group in inertia_check.cpp.
#include <appell/joint_types.hpp>
#include <appell/model.hpp>

#include "model/inertia_check.hpp"

#include <cmath>
#include <string_view>
#include <unordered_set>

namespace appell {

// The joint type table's facts (a value outside the enum: "?", no coordinates).
const char* toString(JointType type) {
  return jointTypeIndex(type) < kJointTypes.size() ? jointTypeInfo(type).name : "?";
}
int jointNq(JointType type) { return jointTypeIndex(type) < kJointTypes.size() ? jointTypeInfo(type).nq : 0; }
int jointNv(JointType type) { return jointTypeIndex(type) < kJointTypes.size() ? jointTypeInfo(type).nv : 0; }

int Model::bodyIndex(const std::string& name) const {
  for (int i = 0; i < nbodies; ++i)
    if (body_names[i] == name) return i;
  return -1;
}

int Model::jointIndex(const std::string& name) const {
  for (int i = 0; i < nbodies; ++i)
    if (joint_names[i] == name) return i;
  return -1;
}

bool Model::isAncestor(int ancestor, int body) const {
  for (int i = body; i >= 0; i = parent[i])
    if (i == ancestor) return true;
  return false;
}

double Model::totalMass() const {
  double m = 0;
  for (const auto& I : inertias) m += I.mass;
  return m;
}

int ModelBuilder::addBody(const std::string& name, int parent, const SE3& placement,
                          JointType type, const Vec3& axis, const Inertia& inertia,
                          const std::string& joint_name, const JointLimits& limits) {
  entries_.push_back({name, joint_name.empty() ? name + "_joint" : joint_name, parent, placement,
                      type, axis, inertia, limits});
  return static_cast<int>(entries_.size()) - 1;
}

namespace {

[[noreturn]] void fail(const std::string& body, const std::string& why) {
  throw ModelError("body '" + body + "': " + why);
}

template <typename Derived>
bool finite(const Eigen::MatrixBase<Derived>& m) {
  return m.allFinite();
}

/// A joint of the given type at coordinate offsets (idx_q, idx_v), its motion
/// subspace S in the joint frame.
Joint makeJoint(const std::string& name, JointType type, const Vec3& axis, const JointLimits& limits,
                int idx_q, int idx_v) {
  Joint j;
  j.type = type;
  j.nq = jointNq(type);
  j.nv = jointNv(type);
  j.idx_q = idx_q;
  j.idx_v = idx_v;
  j.limits = limits;
  if (jointTypeInfo(type).has_axis) {
    if (!finite(axis) || axis.norm() < 1e-12) fail(name, "joint axis is zero or not finite");
    j.axis = axis.normalized();
  }
  j.S = Mat6X::Zero(6, j.nv);
  switch (type) {
    case JointType::Fixed: break;
    case JointType::Revolute: case JointType::Continuous: j.S.col(0).head<3>() = j.axis; break;
    case JointType::Prismatic: j.S.col(0).tail<3>() = j.axis; break;
    case JointType::Planar: {
      // A pair a user can guess (docs/engine.md): t₁ = the first of the
      // joint frame's x, y axes not within 45° of the normal, projected
      // into the plane; t₂ = axis × t₁. Axis z: (x, y); axis x: (y, z);
      // axis y: (x, −z).
      const Vec3 first = std::abs(j.axis.x()) < std::sqrt(0.5) ? Vec3::UnitX() : Vec3::UnitY();
      j.t1 = (first - first.dot(j.axis) * j.axis).normalized();
      j.t2 = j.axis.cross(j.t1);
      j.S.col(0).tail<3>() = j.t1;
      j.S.col(1).tail<3>() = j.t2;
      j.S.col(2).head<3>() = j.axis;
      break;
    }
    case JointType::Floating: j.S = Mat6::Identity(); break;
    case JointType::Ball: j.S.topRows<3>() = Mat3::Identity(); break;
  }
  return j;
}

}  // namespace

Model ModelBuilder::build(std::vector<std::string>* notes) const {
  Model m;
  const int n = static_cast<int>(entries_.size());
  m.nbodies = n;
  m.gravity = gravity_;
  if (!gravity_.allFinite()) throw ModelError("gravity is not finite");
  m.children.resize(n);
  // Every body's own numbers first: a rigid group's or a subtree's sums would
  // otherwise turn one body's negative or NaN mass into a misleading error
  // about another body.
  for (const Entry& e : entries_) {
    if (!std::isfinite(e.inertia.mass) || !finite(e.inertia.com) || !finite(e.inertia.inertia_com))
      fail(e.name, "inertia has a non-finite value");
    if (e.inertia.mass < 0)
      fail(e.name, "negative mass " + std::to_string(e.inertia.mass) +
                       ": write a mass ≥ 0 (0 for a frame that carries none)");
  }
  std::unordered_set<std::string_view> body_names;  // one pass, not every pair
  body_names.reserve(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const Entry& e = entries_[i];
    if (e.parent >= i || e.parent < -1)
      fail(e.name, "parent index " + std::to_string(e.parent) + " is not an earlier body");
    if (!body_names.insert(e.name).second) fail(e.name, "two bodies share this name");
    if (!finite(e.placement.R) || !finite(e.placement.p)) fail(e.name, "joint placement is not finite");
    if ((e.placement.R.transpose() * e.placement.R - Mat3::Identity()).norm() > 1e-9)
      fail(e.name, "joint placement rotation is not orthonormal");

    const Joint j = makeJoint(e.name, e.type, e.axis, e.limits, m.nq, m.nv);
    m.nq += j.nq;
    m.nv += j.nv;
    m.parent.push_back(e.parent);
    m.placement.push_back(e.placement);
    m.joints.push_back(j);
    m.inertias.push_back(e.inertia);
    m.spatial_inertia.emplace_back();
    m.spatial_inertia_factor.emplace_back();
    detail::cacheSpatialInertia(m, i);
    m.body_names.push_back(e.name);
    m.joint_names.push_back(e.joint_name);
    if (e.parent >= 0) m.children[e.parent].push_back(i);
    for (int k = 0; k < j.nv; ++k) m.body_of_v.push_back(i);
  }
  // One pass with a hash set: O(n), not a comparison of every pair (a 10⁵-link
  // chain would take minutes).
  std::unordered_set<std::string_view> joint_names;
  joint_names.reserve(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i)
    if (!joint_names.insert(m.joint_names[i]).second)
      fail(m.body_names[i], "joint name '" + m.joint_names[i] + "' is used twice");
  // The mass distribution is judged per rigid group (a moving body with the
  // bodies fixed to it), as the dynamics see it, after the repairs the caller
  // asked for (inertia_check.cpp).
  std::vector<std::string> per_body(static_cast<std::size_t>(n));
  detail::repairInertias(m, repairs_, per_body);
  detail::checkInertias(m, per_body);
  if (notes)
    for (int i = 0; i < n; ++i)
      if (!per_body[i].empty()) notes->push_back("body '" + m.body_names[i] + "': " + per_body[i]);
  return m;
}

std::vector<RigidGroup> rigidGroups(const Model& model) {
  std::vector<RigidGroup> groups;
  std::vector<int> group_of(model.nbodies, -1);
  std::vector<SE3> in_group(model.nbodies);  // body frame in its group's moving body
  for (int i = 0; i < model.nbodies; ++i) {
    const int p = model.parent[i];
    if (model.joints[i].type != JointType::Fixed) {
      group_of[i] = static_cast<int>(groups.size());
      groups.push_back({i, {}, model.inertias[i]});
      in_group[i] = SE3::Identity();
    } else if (p >= 0 && group_of[p] >= 0) {  // parents come first
      RigidGroup& g = groups[group_of[i] = group_of[p]];
      in_group[i] = in_group[p] * model.placement[i];
      g.fixed.push_back(i);
      g.inertia = g.inertia + model.inertias[i].transformed(in_group[i]);
    }
  }
  return groups;
}

}  // namespace appell
