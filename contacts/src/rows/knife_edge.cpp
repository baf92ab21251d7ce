// Knife edge (skate, sleigh runner, trailer axle): the contact point may not
// move across the blade within the tangent plane.
//   point blade, direction b (body):  lateral ℓ = normalize(n × R b)
//   disk/torus wheel, axle a (body):  ℓ = normalize((1 − n nᵀ) R a)
// (for a wheel the blade direction is the rolling direction a × n, and
//  n × (a × n) = (1 − n nᵀ) a, so both are "perpendicular to the blade").
// With u the unnormalised direction, ℓ̇ = (1 − ℓℓᵀ) u̇ / |u|, and a body-fixed
// vector turns as ω × (R b). |u| → 0 (blade along the normal) is singular.
#include "contact_kinds.hpp"
#include "contact_rows.hpp"

namespace appell::detail {

const char* writeKnifeEdgeRows(const ContactGeometry& g, const SE3& pose, const Vec6& V,
                               const SupportState& S, const Vec3& blade_body, bool wheel_axis,
                               double tol, RowBlock& out) {
  const Vec3& n = g.normal;
  const Vec3& nd = g.normal_rate;
  const Vec3 w = V.head<3>();
  const Vec3 bw = pose.R * blade_body;
  const Vec3 bwd = w.cross(bw);
  Vec3 u, ud;
  if (wheel_axis) {
    u = bw - n * n.dot(bw);
    ud = bwd - nd * n.dot(bw) - n * (nd.dot(bw) + n.dot(bwd));
  } else {
    u = n.cross(bw);
    ud = nd.cross(bw) + n.cross(bwd);
  }
  const double len = u.norm();
  const char* reason = nullptr;
  Vec3 l, ld;
  if (len <= tol) {
    reason = wheel_axis ? "knife-edge wheel lying flat: its axle is parallel to the normal"
                        : "knife edge parallel to the contact normal: no lateral direction";
    l = g.t1;
    ld.setZero();
  } else {
    l = u / len;
    ld = (ud - l * l.dot(ud)) / len;
  }
  const RowTerms rl = pointVelocityRow(l, ld, g.point, g.point_rate, V, S);
  const RowTerms rn = pointVelocityRow(n, nd, g.point, g.point_rate, V, S);
  putRow(out, 0, rl.w, rl.b, rl.kappa, 0);
  putRow(out, 1, rn.w, rn.b, rn.kappa, g.gap);
  return reason;
}

}  // namespace appell::detail
