// Row builders shared by the contact kinds (constraint.hpp's convention).
#pragma once

#include <appell/contact_geometry.hpp>

namespace appell::detail {

struct RowTerms {
  Vec6 w;        ///< world spatial covector on V = [ω; v_O]
  double b;      ///< velocity offset
  double kappa;  ///< acceleration offset
};

/// tᵀ(V_B(x) − V_S(x, t)) = 0 for the body point x in contact (geometric point
/// moving at ẋ) and direction t(t) with rate ṫ:
///   W = [x × t; t], b = −tᵀV_S(x),
///   κ = ṫᵀ(V_B(x) − V_S(x)) + tᵀ(ω × ẋ) − tᵀ(A_lin + A_ang × x + Ω × ẋ).
RowTerms pointVelocityRow(const Vec3& t, const Vec3& tdot, const Vec3& x, const Vec3& xdot,
                          const Vec6& body_velocity, const SupportState& S);

/// nᵀ(ω − Ω) = 0:  W = [n; 0], b = −nᵀΩ, κ = ṅᵀ(ω − Ω) − nᵀ A_ang.
RowTerms spinRow(const Vec3& n, const Vec3& ndot, const Vec6& body_velocity,
                 const SupportState& S);

}  // namespace appell::detail
