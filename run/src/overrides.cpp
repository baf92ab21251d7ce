// Named overrides of a scene (overrides.hpp): the state, gravity, constant
// joint forces and a contact's μ, then the velocities completed by the
// closed constraints with the least change from the scene's own.
#include <appell/overrides.hpp>

#include <appell/constraint_set.hpp>
#include <appell/contacts.hpp>
#include <appell/output.hpp>

#include <Eigen/QR>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace appell {

namespace {

// The shortest text that reads back as the same double (std::to_chars).
std::string full(double x) {
  char buf[32];
  const auto end = std::to_chars(buf, buf + sizeof buf, x).ptr;
  return std::string(buf, end);
}

bool endsWith(const std::string& s, const std::string& tail) {
  return s.size() > tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

void needCount(const std::string& name, const std::vector<double>& x, std::size_t n, const std::string& what) {
  if (x.size() != n)
    throw std::invalid_argument(name + ": " + what + ", got " + std::to_string(x.size()) +
                                (x.size() == 1 ? " number" : " numbers"));
}

// <contact>.mu: the contact rebuilt from its description with the new μ (the
// static and kinetic coefficients alike), in `contacts` and `constraints`.
void setMu(Scene& scene, const std::string& name, const std::string& contact, double mu) {
  const int c = scene.contactIndex(contact);
  if (c < 0) throw std::invalid_argument(name + ": no contact '" + contact + "'");
  for (const VertexGroup& g : scene.vertex_groups)
    if (c >= g.first && c < g.first + g.count)
      throw std::invalid_argument(name + ": '" + contact + "' is one vertex of the contact '" + g.name +
                                  "'; its vertices share one μ, given in the scene");
  ContactSpec spec = scene.contacts[c]->spec();
  if (spec.points > 1)
    throw std::invalid_argument(name + ": '" + contact + "' is one of " + std::to_string(spec.points) +
                                " points sharing one μ, given in the scene");
  if (!(mu >= 0)) throw std::invalid_argument(name + ": μ must be ≥ 0 (∞: no limit), not " + full(mu));
  spec.mu = mu;
  spec.mu_kinetic = std::numeric_limits<double>::quiet_NaN();
  auto rebuilt = makeContact(spec);
  scene.contacts[c] = rebuilt;
  scene.constraints[c] = rebuilt;
}

// <joint>.position / .velocity / .effort; false when `name` is none of them.
bool setJointPart(Scene& scene, const std::string& name, const std::vector<double>& x, OverrideReport& r) {
  const Model& m = scene.model;
  for (const char* part : {".position", ".velocity", ".effort"}) {
    if (!endsWith(name, part)) continue;
    const std::string joint_name = name.substr(0, name.size() - std::string(part).size());
    const int j = m.jointIndex(joint_name);
    if (j < 0) return false;
    const Joint& joint = m.joints[j];
    const std::string which = part;
    const bool pos = which == ".position";
    const int n = pos ? joint.nq : joint.nv;
    needCount(name, x, n, "needs " + std::to_string(n));
    if (which == ".effort" && scene.tau.size() != m.nv) scene.tau = VecX::Zero(m.nv);
    VecX& target = pos ? scene.q0 : which == ".velocity" ? scene.v0 : scene.tau;
    const int first = pos ? joint.idx_q : joint.idx_v;
    for (int k = 0; k < n; ++k) target[first + k] = x[k];
    if (which == ".velocity")
      for (int k = 0; k < n; ++k) r.kept.push_back(first + k);
    r.applied.push_back({name, x, joint_name + (pos ? " position" : which == ".velocity" ? " velocity" : " effort (τ)")});
    return true;
  }
  return false;
}

}  // namespace

void applyOverride(Scene& scene, const std::string& name, const std::vector<double>& x, OverrideReport& r) {
  Model& m = scene.model;
  for (double value : x)
    if (!std::isfinite(value) && !endsWith(name, ".mu"))
      throw std::invalid_argument(name + ": '" + full(value) + "' is not a finite number");
  if (x.empty()) throw std::invalid_argument(name + ": no value");
  if (name == "gravity") {
    needCount(name, x, 3, "needs gx,gy,gz");
    m.gravity = Vec3(x[0], x[1], x[2]);
    r.applied.push_back({name, x, "gravity"});
    return;
  }
  const std::vector<std::string> q = coordinateNames(m, false), v = coordinateNames(m, true);
  if (name == "speed") {
    if (m.nbodies == 0 || m.joints[0].type != JointType::Floating)
      throw std::invalid_argument(name + ": the scene's root is not a floating base (set a velocity by name instead)");
    needCount(name, x, 1, "takes one number");
    const int vx = m.joints[0].idx_v + 3;  // the root's link-frame vx
    scene.v0[vx] = x[0];
    r.kept.push_back(vx);
    r.applied.push_back({name, x, v[vx]});
    return;
  }
  if (endsWith(name, ".mu") && scene.contactIndex(name.substr(0, name.size() - 3)) >= 0) {
    needCount(name, x, 1, "takes one number");
    setMu(scene, name, name.substr(0, name.size() - 3), x[0]);
    r.applied.push_back({name, x, name.substr(0, name.size() - 3) + ": μ"});
    return;
  }
  if (setJointPart(scene, name, x, r)) return;
  if (auto it = std::find(q.begin(), q.end(), name); it != q.end()) {
    needCount(name, x, 1, "takes one number");
    scene.q0[it - q.begin()] = x[0];
    r.applied.push_back({name, x, name});
    return;
  }
  if (auto it = std::find(v.begin(), v.end(), name); it != v.end()) {
    needCount(name, x, 1, "takes one number");
    scene.v0[it - v.begin()] = x[0];
    r.kept.push_back(static_cast<int>(it - v.begin()));
    r.applied.push_back({name, x, name});
    return;
  }
  throw std::invalid_argument(name + ": not gravity, speed, <joint>.position, <joint>.velocity, "
                              "<joint>.effort, <contact>.mu or a coordinate's name as the CSV's q: "
                              "and v: columns give it");
}

void completeVelocities(Scene& scene, OverrideReport& report) {
  const Model& m = scene.model;
  const std::vector<int>& kept = report.kept;
  if (scene.constraints.empty() || kept.empty()) return;
  Data data(m);
  ConstraintData cd(m, scene.constraints);
  evaluateConstraints(m, data, scene.constraints, cd, 0.0, scene.q0, scene.v0);
  std::vector<int> rows, free;
  for (int i = 0; i < cd.m; ++i) {
    const int c = cd.row_constraint[i];
    const Constraint& con = *scene.constraints[c];
    // Contacts with clearance are open: only touching ones constrain.
    if (con.unilateral() && cd.gap[cd.offset[c] + con.unilateralRow()] > 1e-8) continue;
    rows.push_back(i);
  }
  for (int j = 0; j < m.nv; ++j)
    if (std::find(kept.begin(), kept.end(), j) == kept.end()) free.push_back(j);
  // The change δ of the free velocities: A_f δ = −(A v + b), least norm.
  MatX A(rows.size(), free.size());
  VecX rhs(rows.size());
  for (std::size_t k = 0; k < rows.size(); ++k) {
    rhs[k] = -cd.b[rows[k]];
    for (int j = 0; j < m.nv; ++j) rhs[k] -= cd.A(rows[k], j) * scene.v0[j];
    for (std::size_t c = 0; c < free.size(); ++c) A(k, c) = cd.A(rows[k], free[c]);
  }
  const VecX delta = Eigen::CompleteOrthogonalDecomposition<MatX>(A).solve(rhs);
  const double residual = rows.empty() ? 0.0 : (A * delta - rhs).lpNorm<Eigen::Infinity>();
  const double scale = std::max(1.0, scene.v0.lpNorm<Eigen::Infinity>());
  if (residual > 1e-9 * scale) {
    const std::vector<std::string> names = coordinateNames(m, true);
    std::string set;
    for (int j : kept) set += (set.empty() ? "" : ", ") + names[j];
    throw std::invalid_argument("the constraints do not allow " + set + " as set (residual " +
                                full(residual) + ")");
  }
  for (std::size_t c = 0; c < free.size(); ++c) {
    const double before = scene.v0[free[c]];
    scene.v0[free[c]] += delta[c];
    if (std::abs(delta[c]) > 1e-12 * scale) report.completed.push_back({free[c], before, scene.v0[free[c]]});
  }
}

std::vector<std::string> describe(const Scene& scene, const OverrideReport& report) {
  std::vector<std::string> lines;
  for (const OverrideReport::Applied& a : report.applied) {
    std::string values;
    for (double x : a.values) values += (values.empty() ? "" : ",") + full(x);
    lines.push_back(a.name + " = " + values + (a.target == a.name ? "" : " (" + a.target + ")"));
  }
  const std::vector<std::string> names = coordinateNames(scene.model, true);
  for (const OverrideReport::Completed& c : report.completed)
    lines.push_back("completed by the constraints: " + names[c.index] + " " + full(c.before) + " → " +
                    full(c.after));
  return lines;
}

}  // namespace appell
