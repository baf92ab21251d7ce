// Unconstrained rigid-body dynamics:  M(q) v̇ + h(q, v) = τ + Σ Jᵢᵀ fᵢ.
// Names as in Featherstone (2008): RNEA (ch. 5.3), CRBA (6.2), ABA (7.3).
// External forces `fext`, when given, are one spatial force per body in the
// body frame (nullptr = none).
#pragma once

#include <appell/data.hpp>

namespace appell {

using BodyForces = std::vector<Vec6>;

/// τ = M(q) a + h(q, v) − (external); result in data.tau.
const VecX& rnea(const Model& model, Data& data, const VecX& q, const VecX& v, const VecX& a,
                 const BodyForces* fext = nullptr);
/// h(q, v) (Coriolis, centrifugal, gravity); result in data.nle.
const VecX& nonLinearEffects(const Model& model, Data& data, const VecX& q, const VecX& v);
/// M(q), full symmetric; result in data.M.
const MatX& crba(const Model& model, Data& data, const VecX& q);
/// v̇ = M⁻¹ (τ − h + external) in O(n); result in data.ddq.
const VecX& aba(const Model& model, Data& data, const VecX& q, const VecX& v, const VecX& tau,
                const BodyForces* fext = nullptr);

double kineticEnergy(const Model& model, Data& data, const VecX& q, const VecX& v);
/// Gravity potential Σ −m gᵀ c (zero at the world origin).
double potentialEnergy(const Model& model, Data& data, const VecX& q);

/// Total linear and angular momentum about the world origin, world frame [L; P].
Vec6 momentum(const Model& model, Data& data, const VecX& q, const VecX& v);

}  // namespace appell
