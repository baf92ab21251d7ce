// Built-in scenes: a model, its constraints and a consistent initial state.
//
// Header-only builders (one header per scene) used by tests, benchmarks and
// the example programs until the URDF versions exist. Every builder returns a
// BuiltScene whose (q0, v0) satisfies the constraints to round-off: gaps are
// zero by construction and v0 lies in the null space of A (for a moving support,
// on the affine set A v + b = 0).
//
// Helpers here are deliberately small and generic: closing the gaps by Newton
// in local coordinates, completing a velocity from its independent components,
// and drawing random admissible states for the cross-formulation tests.
#pragma once

#include <appell/configuration.hpp>
#include <appell/constraint_set.hpp>
#include <appell/dynamics.hpp>
#include <appell/kinematics.hpp>
#include <appell/model.hpp>

#include <Eigen/QR>

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace appell::scenes {

struct BuiltScene {
  std::string name;
  Model model;
  ConstraintList constraints;
  VecX q0, v0;
  double duration = 1.0;  ///< a sensible length for a demonstration run (s)
};

/// Inertia with principal moments `diag` (body axes) about the centre of mass `com`.
inline Inertia principalInertia(double mass, const Vec3& diag, const Vec3& com = Vec3::Zero()) {
  return {mass, com, diag.asDiagonal()};
}

/// Writes a floating joint's (p, quaternion xyzw) into q at index iq.
inline void setFloatingPose(VecX& q, int iq, const Vec3& p, const Mat3& R) {
  const Quat r(R);
  q.segment<3>(iq) = p;
  q[iq + 3] = r.x();
  q[iq + 4] = r.y();
  q[iq + 5] = r.z();
  q[iq + 6] = r.w();
}

/// Rotation matrix of a floating joint's quaternion at q[iq + 3 … iq + 6].
inline Mat3 floatingRotation(const VecX& q, int iq) {
  return Quat(q[iq + 6], q[iq + 3], q[iq + 4], q[iq + 5]).normalized().toRotationMatrix();
}

/// Body-frame floating velocity v = (ω_body, v_body) from the world angular
/// velocity ω and the world velocity of the body origin.
inline Vec6 floatingVelocity(const Mat3& R, const Vec3& omega_world, const Vec3& origin_velocity) {
  Vec6 v;
  v << R.transpose() * omega_world, R.transpose() * origin_velocity;
  return v;
}

/// Kinetic + potential energy.
inline double totalEnergy(const Model& model, Data& data, const VecX& q, const VecX& v) {
  return kineticEnergy(model, data, q, v) + potentialEnergy(model, data, q);
}

/// Holonomic gaps of the holonomic rows only (size = number of holonomic rows).
inline VecX holonomicGaps(const Model& model, Data& data, const ConstraintList& constraints,
                          ConstraintData& cd, const VecX& q, double t) {
  evaluateConstraints(model, data, constraints, cd, t, q, VecX::Zero(model.nv));
  int nh = 0;
  for (char h : cd.holonomic) nh += h ? 1 : 0;
  VecX g(nh);
  for (int r = 0, k = 0; r < cd.m; ++r)
    if (cd.holonomic[r]) g[k++] = cd.gap[r];
  return g;
}

/// Closes the holonomic gaps by Gauss–Newton in local coordinates with
/// minimum-norm steps (the gaps do not fix every coordinate). The Jacobian is
/// a central difference in θ. Throws std::runtime_error if the gaps do not close.
inline void closeGaps(const Model& model, const ConstraintList& constraints, VecX& q,
                      double t = 0, double tol = 1e-13) {
  Data data(model);
  ConstraintData cd(model, constraints);
  VecX g = holonomicGaps(model, data, constraints, cd, q, t);
  if (g.size() == 0) return;
  const int nv = model.nv;
  VecX th = VecX::Zero(nv), qp(model.nq), qm(model.nq);
  MatX J(g.size(), nv);
  for (int it = 0; it < 50 && g.lpNorm<Eigen::Infinity>() > tol; ++it) {
    const double h = 1e-6;
    for (int k = 0; k < nv; ++k) {
      th.setZero();
      th[k] = h;
      retract(model, q, th, qp);
      th[k] = -h;
      retract(model, q, th, qm);
      J.col(k) = (holonomicGaps(model, data, constraints, cd, qp, t) -
                  holonomicGaps(model, data, constraints, cd, qm, t)) / (2 * h);
    }
    const VecX step = Eigen::CompleteOrthogonalDecomposition<MatX>(J).solve(-g);
    retract(model, q, step, qp);
    q = qp;
    g = holonomicGaps(model, data, constraints, cd, q, t);
  }
  if (!(g.lpNorm<Eigen::Infinity>() <= 1e3 * tol))
    throw std::runtime_error("closeGaps: the holonomic gaps did not close (|g| = " +
                             std::to_string(g.lpNorm<Eigen::Infinity>()) + ")");
}

/// Completes v so that A v + b = 0 by changing only the velocities listed in
/// `dependent` (least squares; they must be able to absorb the constraints).
inline void completeVelocity(const Model& model, const ConstraintList& constraints,
                             const VecX& q, VecX& v, const std::vector<int>& dependent,
                             double t = 0) {
  Data data(model);
  ConstraintData cd(model, constraints);
  evaluateConstraints(model, data, constraints, cd, t, q, v);
  MatX Ad(cd.m, static_cast<int>(dependent.size()));
  for (size_t k = 0; k < dependent.size(); ++k) Ad.col(static_cast<int>(k)) = cd.A.col(dependent[k]);
  const VecX r = cd.A * v + cd.b;
  const VecX dv = Eigen::CompleteOrthogonalDecomposition<MatX>(Ad).solve(-r);
  for (size_t k = 0; k < dependent.size(); ++k) v[dependent[k]] += dv[static_cast<int>(k)];
  evaluateConstraints(model, data, constraints, cd, t, q, v);
  if (velocityResidual(data, constraints, cd, v) > 1e-10 * (1 + v.norm()))
    throw std::runtime_error("completeVelocity: the chosen dependent velocities cannot satisfy "
                             "the constraints");
}

/// v with A v + b = 0 nearest to v in the Euclidean norm (minimum-norm correction).
inline void projectVelocityEuclidean(const Model& model, const ConstraintList& constraints,
                                     const VecX& q, VecX& v, double t = 0) {
  std::vector<int> all(model.nv);
  for (int k = 0; k < model.nv; ++k) all[k] = k;
  completeVelocity(model, constraints, q, v, all, t);
}

/// A random admissible state near the scene's initial one: q = retract(q0, θ)
/// with θ uniform in ±angle_spread (rotations, revolute angles) and
/// ±position_spread (everything else), gaps closed; v random (each component
/// ±speed) projected onto A v + b = 0.
inline void randomState(const BuiltScene& s, std::mt19937& rng, double angle_spread,
                        double position_spread, double speed, VecX& q, VecX& v, double t = 0) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Model& m = s.model;
  VecX th(m.nv);
  for (const Joint& j : m.joints) {
    for (int k = 0; k < j.nv; ++k) {
      bool rot = false;
      switch (j.type) {
        case JointType::Revolute: case JointType::Continuous: case JointType::Ball: rot = true; break;
        case JointType::Floating: rot = k < 3; break;
        case JointType::Planar: rot = k == 2; break;
        default: break;
      }
      th[j.idx_v + k] = (rot ? angle_spread : position_spread) * u(rng);
    }
  }
  q.resize(m.nq);
  retract(m, s.q0, th, q);
  closeGaps(m, s.constraints, q, t);
  v.resize(m.nv);
  for (int k = 0; k < m.nv; ++k) v[k] = speed * u(rng);
  projectVelocityEuclidean(m, s.constraints, q, v, t);
}

}  // namespace appell::scenes
