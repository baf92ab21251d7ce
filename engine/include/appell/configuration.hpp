// The configuration manifold: q lives on ℝⁿ × SO(3)ᵏ, v in its tangent space.
//
// Integrators step in local coordinates θ ∈ ℝ^nv around a base point q₀
// (Runge–Kutta–Munthe-Kaas): q = retract(q₀, θ), with θ̇ = localRate(q₀, θ, v).
//   Euclidean coordinates (revolute, prismatic, planar (a, b, φ), the floating
//   base's position) retract by addition; quaternions by q₀ ⊗ exp(θ).
// So a quaternion is never advanced by adding to it: a step is an exact
// rotation, and renormalising is not what keeps it unit.
#pragma once

#include <appell/model.hpp>

#include <random>

namespace appell {

/// The zero configuration (identity quaternions).
VecX neutralConfiguration(const Model& model);

/// q = retract(q0, θ): move from q0 by the local coordinates θ (size nv).
void retract(const Model& model, const VecX& q0, const VecX& theta, VecX& q);

/// retract(q0, θ) into q and localRate(q0, θ, v) into θ̇ together, as an
/// RKMK stage needs them: each rotation's exponential and dexp⁻¹ share one
/// half-angle sine and cosine (three fewer transcendental calls per joint).
void retractWithRate(const Model& model, const VecX& q0, const VecX& theta, const VecX& v,
                     VecX& q, VecX& theta_dot);

/// θ̇ = T(q0, θ) v: rate of the local coordinates for velocity v at q = retract(q0, θ).
void localRate(const Model& model, const VecX& q0, const VecX& theta, const VecX& v,
               VecX& theta_dot);

/// q = q0 ⊕ h v: where the configuration goes when the velocity v (body
/// frame for rotations, as everywhere) is held constant for a time h — the
/// exact flow of q̇ = G(q) v with v frozen (Pinocchio's `integrate`): the
/// exponential of SO(3) and SE(3)/SE(2) twists, addition elsewhere. So
/// integrate(q1, −v, h) undoes integrate(q0, v, h) exactly, which a symmetric
/// method's drift needs (Hairer, Lubich & Wanner, GNI, §IV.8).
void integrate(const Model& model, const VecX& q0, const VecX& v, double h, VecX& q);

/// θ with retract(q0, θ) = q1 (the shortest rotation for quaternions).
void difference(const Model& model, const VecX& q0, const VecX& q1, VecX& theta);

/// q̇ = G(q) v, as an nq-vector (for reports and finite differences).
void configurationRate(const Model& model, const VecX& q, const VecX& v, VecX& qdot);

/// Renormalise every quaternion (after loading user input; not part of stepping).
void normalizeQuaternions(const Model& model, VecX& q);

/// The first joint whose quaternion has no direction (|q|² zero or below the
/// smallest normal double, where q/|q| is undefined), or −1. Quaternions off
/// the unit sphere are otherwise accepted (a rotation is that of q/|q|).
int degenerateQuaternionJoint(const Model& model, const VecX& q);

/// A random configuration: angles in [−π, π], displacements in [−1, 1],
/// uniformly random unit quaternions.
VecX randomConfiguration(const Model& model, std::mt19937& rng);

}  // namespace appell
