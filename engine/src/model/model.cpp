#include <appell/model.hpp>

#include <appell/configuration.hpp>
#include <appell/data.hpp>
#include <appell/dynamics.hpp>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include <cmath>
#include <sstream>
#include <string_view>
#include <unordered_set>

namespace appell {

const char* toString(JointType type) {
  switch (type) {
    case JointType::Fixed: return "fixed";
    case JointType::Revolute: return "revolute";
    case JointType::Continuous: return "continuous";
    case JointType::Prismatic: return "prismatic";
    case JointType::Planar: return "planar";
    case JointType::Floating: return "floating";
    case JointType::Ball: return "ball";
  }
  return "?";
}

int jointNq(JointType type) {
  switch (type) {
    case JointType::Fixed: return 0;
    case JointType::Revolute: case JointType::Continuous: case JointType::Prismatic: return 1;
    case JointType::Planar: return 3;
    case JointType::Floating: return 7;
    case JointType::Ball: return 4;
  }
  return 0;
}

int jointNv(JointType type) {
  switch (type) {
    case JointType::Floating: return 6;
    case JointType::Ball: case JointType::Planar: return 3;
    default: return jointNq(type);
  }
}

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

// Rotational inertia about the centre of mass must be symmetric positive
// definite and its principal moments must satisfy the triangle inequality
// (I₁ + I₂ ≥ I₃): otherwise no mass distribution has it.
void checkInertia(const std::string& body, const Inertia& I, bool may_be_massless) {
  if (!std::isfinite(I.mass) || !finite(I.com) || !finite(I.inertia_com))
    fail(body, "inertia has a non-finite value");
  if (I.mass < 0) fail(body, "negative mass " + std::to_string(I.mass));
  if (I.mass == 0) {
    if (!may_be_massless) fail(body, "zero mass on a moving body with no massive descendants");
    if (I.inertia_com.norm() != 0) fail(body, "zero mass but non-zero rotational inertia");
    return;
  }
  const Mat3& J = I.inertia_com;
  if ((J - J.transpose()).norm() > 1e-9 * (1 + J.norm())) fail(body, "inertia tensor is not symmetric");
  Eigen::SelfAdjointEigenSolver<Mat3> eig(J);
  const Vec3 d = eig.eigenvalues();
  const double tol = 1e-12 * std::max(1.0, d.cwiseAbs().maxCoeff());
  if (d.minCoeff() <= 0) {
    std::ostringstream s;
    s << "inertia tensor is not positive definite (principal moments " << d.transpose() << ")";
    fail(body, s.str());
  }
  if (d(0) + d(1) < d(2) - tol) {
    std::ostringstream s;
    s << "principal moments " << d.transpose() << " violate the triangle inequality";
    fail(body, s.str());
  }
}

// A massless moving body is harmless only when the bodies it carries give every
// direction of its joint some inertia. Otherwise M is singular — e.g. a
// massless floating frame carrying a wheel on a revolute joint: frame and wheel
// can counter-rotate at no cost — and ABA would return huge numbers instead of
// an error. The joint-space articulated inertia D = Sᵀ Iᴬ S (Featherstone 2008,
// §7.3) of each such body must be positive definite; it is read off one ABA
// pass at the neutral and at two random configurations.
void checkMasslessJoints(const Model& m) {
  bool any = false;
  for (int i = 0; i < m.nbodies; ++i) any |= m.joints[i].nv > 0 && m.inertias[i].mass == 0;
  if (!any) return;
  Data data(m);
  std::mt19937 rng(12345);
  const VecX zero = VecX::Zero(m.nv);
  for (int trial = 0; trial < 3; ++trial) {
    const VecX q = trial == 0 ? neutralConfiguration(m) : randomConfiguration(m, rng);
    aba(m, data, q, zero, zero);
    for (int i = 0; i < m.nbodies; ++i) {
      const Joint& j = m.joints[i];
      if (j.nv == 0 || m.inertias[i].mass != 0) continue;
      const MatX D = j.S.transpose() * data.IA[i] * j.S;
      const Eigen::SelfAdjointEigenSolver<MatX> eig(D);
      const double scale = std::max(1e-300, data.IA[i].norm());
      if (eig.eigenvalues().minCoeff() <= 1e-12 * scale)
        fail(m.body_names[i],
             "massless body on a moving joint whose motion meets no inertia (the bodies it "
             "carries can move so as to cancel it): the mass matrix would be singular");
    }
  }
}

}  // namespace

Model ModelBuilder::build() const {
  Model m;
  const int n = static_cast<int>(entries_.size());
  m.nbodies = n;
  m.gravity = gravity_;
  if (!gravity_.allFinite()) throw ModelError("gravity is not finite");
  m.children.resize(n);
  // Every body's own numbers first: the subtree masses below would otherwise
  // turn one body's negative or NaN mass into a misleading error about another
  // body (a parent whose subtree "carries no mass").
  for (const Entry& e : entries_) {
    if (!std::isfinite(e.inertia.mass) || !finite(e.inertia.com) || !finite(e.inertia.inertia_com))
      fail(e.name, "inertia has a non-finite value");
    if (e.inertia.mass < 0) fail(e.name, "negative mass " + std::to_string(e.inertia.mass));
  }
  // Subtree mass decides whether a massless body is acceptable: a moving joint
  // needs something with inertia beyond it.
  std::vector<double> subtree_mass(n, 0.0);
  for (int i = n - 1; i >= 0; --i) {
    subtree_mass[i] += entries_[i].inertia.mass;
    if (entries_[i].parent >= 0 && entries_[i].parent < i) subtree_mass[entries_[i].parent] += subtree_mass[i];
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
    const bool moving = e.type != JointType::Fixed;
    if (moving && subtree_mass[i] <= 0)
      fail(e.name, "zero mass on a moving body with no massive descendants (its joint carries no mass)");
    if (e.inertia.mass == 0 && e.inertia.inertia_com.norm() != 0)
      fail(e.name, "zero mass but non-zero rotational inertia");

    Joint j;
    j.type = e.type;
    j.nq = jointNq(e.type);
    j.nv = jointNv(e.type);
    j.idx_q = m.nq;
    j.idx_v = m.nv;
    j.limits = e.limits;
    if (e.type == JointType::Revolute || e.type == JointType::Continuous ||
        e.type == JointType::Prismatic || e.type == JointType::Planar) {
      if (!finite(e.axis) || e.axis.norm() < 1e-12) fail(e.name, "joint axis is zero or not finite");
      j.axis = e.axis.normalized();
    }
    j.S = Mat6X::Zero(6, j.nv);
    switch (e.type) {
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
    m.nq += j.nq;
    m.nv += j.nv;
    m.parent.push_back(e.parent);
    m.placement.push_back(e.placement);
    m.joints.push_back(j);
    m.inertias.push_back(e.inertia);
    m.spatial_inertia.push_back(e.inertia.matrix());
    const Eigen::LLT<Mat6> llt(m.spatial_inertia.back());
    m.spatial_inertia_factor.push_back(llt.info() == Eigen::Success ? Mat6(llt.matrixL())
                                                                    : Mat6::Zero());
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
  // bodies fixed to it), as the dynamics see it: a sensor frame or a point
  // mass on a fixed joint is fine when its group is a valid rigid body.
  for (const RigidGroup& g : rigidGroups(m)) {
    std::string name = m.body_names[g.body];
    std::string merged;
    for (int f : g.fixed)
      if (m.inertias[f].mass > 0 || m.inertias[f].inertia_com.norm() > 0)
        merged += (merged.empty() ? "'" : ", '") + m.body_names[f] + "'";
    try {
      checkInertia(name, g.inertia, subtree_mass[g.body] > 0);
    } catch (const ModelError& err) {
      if (merged.empty()) throw;
      const std::string what = err.what(), head = "body '" + name + "': ";
      fail(name, "combined inertia with the fixed " + merged + " (merged as ROS tools do): " +
                     what.substr(what.rfind(head, 0) == 0 ? head.size() : 0));
    }
  }
  checkMasslessJoints(m);
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
