// Velocity and acceleration terms of contact rows.
//
// For r = tᵀ(v_O + ω × x) − tᵀ(v_SO + Ω × x) with x(t), t(t) moving:
//   d/dt tᵀ(v_O + ω × x) = ṫᵀV_B(x) + tᵀ(a_O + α × x) + tᵀ(ω × ẋ)
//                         = ṫᵀV_B(x) + W·a + tᵀ(ω × ẋ)          (a = [α; a_O] = dV/dt)
//   d/dt tᵀV_S(x(t), t)   = ṫᵀV_S(x) + tᵀ(A_lin + A_ang × x + Ω × ẋ)
// so ṙ = W·a + κ with κ as below (docs/contacts.md §2).
#include "contact_rows.hpp"

namespace appell::detail {

RowTerms pointVelocityRow(const Vec3& t, const Vec3& tdot, const Vec3& x, const Vec3& xdot,
                          const Vec6& body_velocity, const SupportState& S) {
  const Vec3 w = body_velocity.head<3>(), vO = body_velocity.tail<3>();
  const Vec3 W = S.V.head<3>(), vS = S.V.tail<3>();
  const Vec3 Aang = S.A.head<3>(), Alin = S.A.tail<3>();
  const Vec3 vb = vO + w.cross(x);
  const Vec3 vs = vS + W.cross(x);
  RowTerms r;
  r.w << x.cross(t), t;
  r.b = -t.dot(vs);
  r.kappa = tdot.dot(vb - vs) + t.dot(w.cross(xdot)) - t.dot(Alin + Aang.cross(x) + W.cross(xdot));
  return r;
}

RowTerms spinRow(const Vec3& n, const Vec3& ndot, const Vec6& body_velocity,
                 const SupportState& S) {
  RowTerms r;
  r.w << n, Vec3::Zero();
  r.b = -n.dot(S.V.head<3>());
  r.kappa = ndot.dot(body_velocity.head<3>() - S.V.head<3>()) - n.dot(S.A.head<3>());
  return r;
}

}  // namespace appell::detail
