// --set and --sweep (overrides.hpp).
#include "overrides.hpp"

#include <appell/constraint_set.hpp>
#include <appell/output.hpp>

#include <Eigen/QR>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace appell::cli {

namespace {

std::vector<double> numbersOf(const std::string& name, const std::string& text) {
  std::vector<double> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    std::size_t used = 0;
    double x = 0;
    try {
      x = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() || !std::isfinite(x))
      throw UsageError("--set " + name + ": '" + item + "' is not a finite number");
    out.push_back(x);
  }
  if (out.empty()) throw UsageError("--set " + name + ": no value");
  return out;
}

double oneNumber(const std::string& name, const std::string& text) {
  const std::vector<double> x = numbersOf(name, text);
  if (x.size() != 1) throw UsageError("--set " + name + ": takes one number, got " + std::to_string(x.size()));
  return x[0];
}

}  // namespace

void completeVelocities(Scene& scene, const std::vector<int>& kept) {
  const Model& m = scene.model;
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
  MatX A(rows.size(), free.size());
  VecX rhs(rows.size());
  for (std::size_t k = 0; k < rows.size(); ++k) {
    rhs[k] = -cd.b[rows[k]];
    for (int j : kept) rhs[k] -= cd.A(rows[k], j) * scene.v0[j];
    for (std::size_t c = 0; c < free.size(); ++c) A(k, c) = cd.A(rows[k], free[c]);
  }
  const VecX x = Eigen::CompleteOrthogonalDecomposition<MatX>(A).solve(rhs);
  for (std::size_t c = 0; c < free.size(); ++c) scene.v0[free[c]] = x[c];
  const double residual = rows.empty() ? 0.0 : (A * x - rhs).lpNorm<Eigen::Infinity>();
  if (residual > 1e-9 * std::max(1.0, scene.v0.lpNorm<Eigen::Infinity>())) {
    const std::vector<std::string> names = coordinateNames(m, true);
    std::string set;
    for (int j : kept) set += (set.empty() ? "" : ", ") + names[j];
    throw UsageError("--set: the constraints do not allow " + set + " as set (residual " +
                     std::to_string(residual) + ")");
  }
}

void applyOverride(Scene& scene, const std::string& name, const std::string& value, std::vector<int>& kept) {
  Model& m = scene.model;
  if (name == "gravity") {
    const std::vector<double> g = numbersOf(name, value);
    if (g.size() != 3) throw UsageError("--set gravity: needs gx,gy,gz");
    m.gravity = Vec3(g[0], g[1], g[2]);
    return;
  }
  if (name == "speed") {
    if (m.nbodies == 0 || m.joints[0].type != JointType::Floating)
      throw UsageError("--set speed: the scene's root is not a floating base (set a velocity by name instead)");
    const int vx = m.joints[0].idx_v + 3;  // the root's link-frame vx
    scene.v0[vx] = oneNumber(name, value);
    kept.push_back(vx);
    return;
  }
  for (const char* part : {".position", ".velocity"}) {
    const std::string suffix = part;
    if (name.size() <= suffix.size() || name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
      continue;
    const int j = m.jointIndex(name.substr(0, name.size() - suffix.size()));
    if (j < 0) break;
    const Joint& joint = m.joints[j];
    const std::vector<double> x = numbersOf(name, value);
    const bool pos = suffix == ".position";
    const int n = pos ? joint.nq : joint.nv;
    if (static_cast<int>(x.size()) != n)
      throw UsageError("--set " + name + ": needs " + std::to_string(n) + " numbers, got " +
                       std::to_string(x.size()));
    for (int k = 0; k < n; ++k) (pos ? scene.q0[joint.idx_q + k] : scene.v0[joint.idx_v + k]) = x[k];
    if (!pos)
      for (int k = 0; k < n; ++k) kept.push_back(joint.idx_v + k);
    return;
  }
  const std::vector<std::string> q = coordinateNames(m, false), v = coordinateNames(m, true);
  if (auto it = std::find(q.begin(), q.end(), name); it != q.end()) {
    scene.q0[it - q.begin()] = oneNumber(name, value);
    return;
  }
  if (auto it = std::find(v.begin(), v.end(), name); it != v.end()) {
    scene.v0[it - v.begin()] = oneNumber(name, value);
    kept.push_back(static_cast<int>(it - v.begin()));
    return;
  }
  throw UsageError("--set " + name + ": not gravity, speed, <joint>.position, <joint>.velocity or a "
                   "coordinate's name as the CSV's q: and v: columns give it");
}

std::vector<int> applyOverrides(Scene& scene, const Args& args) {
  std::vector<int> kept;
  for (const std::string& s : args.all("set")) {
    const auto eq = s.find('=');
    if (eq == std::string::npos || eq == 0) throw UsageError("--set expects NAME=VALUE, got '" + s + "'");
    applyOverride(scene, s.substr(0, eq), s.substr(eq + 1), kept);
  }
  completeVelocities(scene, kept);
  return kept;
}

Sweep parseSweep(const std::string& spec) {
  const auto eq = spec.find('=');
  if (eq == std::string::npos || eq == 0)
    throw UsageError("--sweep expects NAME=START:STOP:COUNT, got '" + spec + "'");
  Sweep s;
  s.name = spec.substr(0, eq);
  std::vector<std::string> parts;
  std::stringstream in(spec.substr(eq + 1));
  for (std::string p; std::getline(in, p, ':');) parts.push_back(p);
  if (parts.size() != 3) throw UsageError("--sweep " + s.name + ": expects START:STOP:COUNT");
  const double a = oneNumber(s.name, parts[0]), b = oneNumber(s.name, parts[1]);
  const double c = oneNumber(s.name, parts[2]);
  if (!(c >= 1) || c != std::floor(c) || c > 100000)
    throw UsageError("--sweep " + s.name + ": COUNT must be a whole number from 1 to 100000");
  const int n = static_cast<int>(c);
  for (int k = 0; k < n; ++k) s.values.push_back(n == 1 ? a : a + (b - a) * k / (n - 1));
  return s;
}

}  // namespace appell::cli
