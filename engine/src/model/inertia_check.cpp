// Judging and repairing mass distributions as robot descriptions publish them.
//
// The dynamics ask one thing of the inertias: a positive definite mass matrix
// M(q). The articulated-body algorithm factorises M joint by joint
// (Featherstone 2008, "Rigid Body Dynamics Algorithms", §7.3): M is positive
// definite exactly when every joint's articulated inertia along its motion,
// D = Sᵀ Iᴬ S, is. A rigid group (a moving body and the bodies fixed to it)
// whose spatial inertia is positive definite makes its own D positive definite
// (Iᴬ ⪰ I); only groups whose inertia is singular — massless, a point mass, a
// tensor with a zero principal moment — need D computed, and they may well be
// carried: a near-massless floating base whose legs carry the mass.
//
// Loaded with one note per group (the dynamics run):
//   - principal moments I₁ ≤ I₂ ≤ I₃ with I₁ + I₂ < I₃ (CAD exports round
//     them; no mass distribution has them, but the tensor is positive definite);
//   - a singular group whose joint's D is positive definite.
// Refused, naming the body, its joint and what to write instead:
//   - a tensor that is not symmetric, or has a negative principal moment
//     beyond round-off (the kinetic energy would not be positive);
//   - a joint whose D is singular at the neutral or at one of two random
//     configurations (a massless leaf on a revolute joint, a massless frame
//     carrying a wheel on a coaxial joint: the bodies can move at no cost).
#include "model/inertia_check.hpp"

#include <appell/configuration.hpp>
#include <appell/data.hpp>
#include <appell/kinematics.hpp>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <sstream>

namespace appell::detail {

// Named, so that a unity build batching this file with others keeps its
// helpers apart.
namespace inertia_rules {
namespace {

// Tolerances, relative to the group's largest principal moment d₃:
// asymmetry and negative moments are round-off below 1e-9 (plus 1e-16 kg m²,
// a gram at 0.3 µm, for tensors that are zero); a group is singular when its
// smallest moment is below 1e-12 d₃ + 1e-16 kg m² (a point mass written with
// moments of 1e-20 is a point mass); a triangle defect below 1e-6 d₃ is the
// rounding of six printed digits of a flat plate (I₁ + I₂ = I₃ exactly).
constexpr double kRoundOff = 1e-9;
constexpr double kAbsoluteMoment = 1e-16;
constexpr double kSingular = 1e-12;
constexpr double kTriangle = 1e-6;

// Messages name links and joints in single quotes and use no apostrophes:
// the loader shortens long spans between quotes (xml_util.cpp, clipQuoted).
[[noreturn]] void fail(const std::string& body, const std::string& why) {
  throw ModelError("body '" + body + "': " + why);
}

std::string str(double x) {
  std::ostringstream s;
  s.precision(6);
  s << x;
  return s.str();
}

std::string moments(const Vec3& d) { return str(d(0)) + " " + str(d(1)) + " " + str(d(2)); }

// "combined inertia with the fixed 'a', 'b' (merged as ROS tools do): ", or
// "" when nothing with mass is fixed to the body.
std::string groupHead(const Model& m, const RigidGroup& g) {
  std::string merged;
  for (int f : g.fixed)
    if (m.inertias[f].mass > 0 || m.inertias[f].inertia_com.norm() > 0)
      merged += (merged.empty() ? "'" : ", '") + m.body_names[f] + "'";
  return merged.empty() ? "" : "combined inertia with the fixed " + merged + " (merged as ROS tools do): ";
}

struct Principal {
  Vec3 d;  ///< ascending
  Mat3 R;  ///< columns: the principal axes
};

Principal principal(const Mat3& J) {
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(J);
  return {eig.eigenvalues(), eig.eigenvectors()};
}

// A group to be carried: its body and what is wrong with its inertia.
struct SingularGroup {
  int body;
  std::string what;
};

// D = Sᵀ Iᴬ S of every joint, leaf to root, as ABA forms it; fails at the
// first singular one among the singular groups (a descendant first, so a
// parent's Iᴬ never holds a failed child's inverse).
void checkArticulated(const Model& m, const std::vector<SingularGroup>& groups) {
  std::vector<int> which(m.nbodies, -1);
  for (std::size_t k = 0; k < groups.size(); ++k) which[groups[k].body] = static_cast<int>(k);
  Data data(m);
  std::mt19937 rng(12345);
  for (int trial = 0; trial < 3; ++trial) {
    const VecX q = trial == 0 ? neutralConfiguration(m) : randomConfiguration(m, rng);
    forwardKinematics(m, data, q);
    for (int i = 0; i < m.nbodies; ++i) data.IA[i] = m.spatial_inertia[i];
    for (int i = m.nbodies - 1; i >= 0; --i) {
      const Joint& j = m.joints[i];
      Mat6 Ia = data.IA[i];
      if (j.nv > 0) {
        const Mat6X U = data.IA[i] * j.S;
        const MatX D = j.S.transpose() * U;
        if (which[i] >= 0) {
          const double lo = Eigen::SelfAdjointEigenSolver<MatX>(D, Eigen::EigenvaluesOnly).eigenvalues()(0);
          const double scale = data.IA[i].norm();
          if (!(lo > kSingular * scale))
            fail(m.body_names[i],
                 "joint '" + m.joint_names[i] + "' (" + toString(j.type) + ") moves no inertia: " +
                     groups[which[i]].what + ", and nothing it carries resists the motion of the joint — the "
                     "articulated inertia along it, Sᵀ Iᴬ S, is singular (" +
                     (scale > 0 ? "smallest eigenvalue " + str(lo) + " against |Iᴬ| = " + str(scale)
                                : std::string("Iᴬ = 0")) +
                     ") at " + (trial == 0 ? "the neutral configuration" : "a random configuration") +
                     ", so the mass matrix would be. Give '" + m.body_names[i] +
                     "' a mass and a positive definite tensor (its <inertial>), make '" + m.joint_names[i] +
                     "' a fixed joint, or bound the inertias at load (--bound-mass, --bound-inertia)");
        }
        Ia.noalias() -= U * D.llt().solve(U.transpose());
      }
      if (m.parent[i] >= 0) addTransformedInertia(data.liMi[i], Ia, data.IA[m.parent[i]]);
    }
  }
}

// Mass carried by each body's joint: its own and its descendants'.
std::vector<double> subtreeMass(const Model& m) {
  std::vector<double> mass(m.nbodies, 0.0);
  for (int i = m.nbodies - 1; i >= 0; --i) {
    mass[i] += m.inertias[i].mass;
    if (m.parent[i] >= 0) mass[m.parent[i]] += mass[i];
  }
  return mass;
}

}  // namespace
}  // namespace inertia_rules

void cacheSpatialInertia(Model& m, int i) {
  m.spatial_inertia[i] = m.inertias[i].matrix();
  const Eigen::LLT<Mat6> llt(m.spatial_inertia[i]);
  m.spatial_inertia_factor[i] = llt.info() == Eigen::Success ? Mat6(llt.matrixL()) : Mat6::Zero();
}

void repairInertias(Model& m, const InertiaRepairs& r, std::vector<std::string>& notes) {
  using namespace inertia_rules;
  if (!std::isfinite(r.bound_mass) || r.bound_mass < 0 || !std::isfinite(r.bound_inertia) ||
      r.bound_inertia < 0)
    throw ModelError("inertia repairs: bound_mass and bound_inertia must be finite and ≥ 0 (got " +
                     str(r.bound_mass) + ", " + str(r.bound_inertia) + ")");
  if (!r.any()) return;
  for (const RigidGroup& g : rigidGroups(m)) {
    Inertia I = g.inertia;
    Inertia point;  // mass added at the group's centre of mass, in the body's frame
    std::vector<std::string> changes;
    if (I.mass < r.bound_mass) {
      point = {r.bound_mass - I.mass, I.mass > 0 ? I.com : Vec3::Zero(), Mat3::Zero()};
      changes.push_back("mass " + str(I.mass) + " kg raised to " + str(r.bound_mass) + " (bound mass)");
      I = I + point;
    }
    const Principal p = principal(I.inertia_com);
    Vec3 d = p.d;
    if (r.bound_inertia > 0 && d(0) < r.bound_inertia) {
      changes.push_back("principal moments " + moments(d) + " raised to at least " + str(r.bound_inertia) +
                        " kg m² (bound inertia)");
      d = d.cwiseMax(r.bound_inertia);
    }
    if (r.balance && d(0) + d(1) < d(2)) {
      changes.push_back("smallest principal moment " + str(d(0)) + " raised to " + str(d(2) - d(1)) +
                        " = I₃ − I₂ (balance: the triangle inequality was broken by " +
                        str(100 * (d(2) - d(1) - d(0)) / d(2)) + " %)");
      d(0) = d(2) - d(1);
    }
    if (changes.empty()) continue;
    // A pure rotational inertia adds the same about every point: ΔJ about the
    // group's centre is ΔJ about the body's own.
    Inertia& own = m.inertias[g.body];
    if (point.mass > 0) own = own + point;
    own.inertia_com += p.R * (d - p.d).asDiagonal() * p.R.transpose();
    cacheSpatialInertia(m, g.body);
    std::string& line = notes[g.body];
    line = groupHead(m, g) + "repaired: ";
    for (std::size_t k = 0; k < changes.size(); ++k) line += (k ? "; " : "") + changes[k];
  }
}

void checkInertias(const Model& m, std::vector<std::string>& notes) {
  using namespace inertia_rules;
  const std::vector<double> carried = subtreeMass(m);
  std::vector<SingularGroup> singular;
  struct Pending {
    int body;
    std::string head, text;
  };
  std::vector<Pending> singular_notes;  // kept once the joints pass
  // One line per body: after a repair's, what is still to say.
  auto note = [&](int body, const std::string& head, const std::string& text) {
    std::string& line = notes[body];
    line = line.empty() ? head + text : line + "; then " + text;
  };
  for (const RigidGroup& g : rigidGroups(m)) {
    const std::string& name = m.body_names[g.body];
    const std::string head = groupHead(m, g);
    const Mat3& J = g.inertia.inertia_com;
    if ((J - J.transpose()).norm() > kRoundOff * (1 + J.norm()))
      fail(name, head + "inertia tensor is not symmetric: write each product of inertia once (ixy, ixz, iyz)");
    const Vec3 d = principal(J).d;
    if (d(0) < -(kRoundOff * d.cwiseAbs().maxCoeff() + kAbsoluteMoment))
      fail(name, head + "inertia tensor is not positive semi-definite (principal moments " + moments(d) +
                     "): a negative moment would make the kinetic energy negative. Write the tensor of a "
                     "real body — principal moments ≥ 0, each at most the sum of the other two (a wrong "
                     "sign of ixy, ixz or iyz does this)");
    if (g.inertia.mass <= 0 || d(0) <= kSingular * d(2) + kAbsoluteMoment) {
      const std::string what =
          carried[g.body] <= 0 ? "it and the bodies it carries have zero mass"
          : g.inertia.mass <= 0 ? "its mass is zero"
                                : "its inertia is singular (mass " + str(g.inertia.mass) +
                                      " kg, principal moments " + moments(d) + ")";
      singular.push_back({g.body, head + what});
      singular_notes.push_back(
          {g.body, head, (g.inertia.mass <= 0 ? std::string("massless")
                                        : "singular inertia (mass " + str(g.inertia.mass) +
                                              " kg, principal moments " + moments(d) + ")") +
                       " — loaded: the bodies beyond its joint '" + m.joint_names[g.body] +
                       "' resist its motion in every direction (Sᵀ Iᴬ S positive definite)"});
      continue;
    }
    const double defect = (d(2) - d(0) - d(1)) / d(2);
    if (defect > kTriangle)
      note(g.body, head,
           "principal moments " + moments(d) + " violate the triangle inequality by " + str(100 * defect) +
               " % (I₁ + I₂ = " + str(d(0) + d(1)) + " < I₃): no mass distribution has them, but the "
               "tensor is positive definite and the dynamics run (balancing raises I₁ to " +
               str(d(2) - d(1)) + ")");
  }
  if (singular.empty()) return;
  checkArticulated(m, singular);
  for (const Pending& p : singular_notes) note(p.body, p.head, p.text);
}

}  // namespace appell::detail
