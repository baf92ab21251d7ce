// A smooth shape on a plane of any orientation, fixed or moving.
//
// The normal is the plane's: n = R_S n_S, ṅ = Ω × n. The body-frame normal of
// the body at contact is m = −Rᵀn, so ṁ = −(Ṙᵀ n + Rᵀ ṅ) = Rᵀ((ω − Ω) × n)
// (Ṙ = ω̂ R with ω the world angular velocity). The gap is nᵀ(x − p₀) with p₀ on
// the plane; since x is the extreme point along −n, ġ = nᵀ(V_B(x) − V_S(x)).
#include "geometry_internal.hpp"

#include <cmath>
#include <limits>

namespace appell::detail {

void planeGeometry(const Shape& shape, const Plane& plane, const SupportState& S, const SE3& pose,
                   const Vec6& V, ContactGeometry& out, const GeometryOptions& opt) {
  const Twist body(V), sup(S.V);
  // ShapeContact stores the normal unit; normalise only what arrives otherwise.
  const double nn = plane.normal.squaredNorm();
  const Vec3 nS = std::abs(nn - 1.0) <= 8 * std::numeric_limits<double>::epsilon() ? plane.normal : Vec3(plane.normal / std::sqrt(nn));
  const Vec3 n = S.pose.R * nS;
  const Vec3 p0 = S.pose.apply(plane.point);
  const Vec3 m = -(pose.R.transpose() * n);
  const GaussPoint g = inverseGaussMap(shape, m, opt.singular_tol);

  out.normal = n;
  out.normal_rate = sup.w.cross(n);
  out.gap = n.dot(pose.apply(g.y) - p0);
  const Vec3 mdot = pose.R.transpose() * (body.w - sup.w).cross(n);
  finishPoint(pose, body, g, mdot, out);

  // The support's transported frame at n (fixed in the support frame here,
  // so ṫ = Ω × t): a terrain's faces, edges and vertices take the same
  // function of n, so a ball crossing them keeps a continuous frame.
  transportedFrame(S.pose.R, sup.w, out);
  if (g.singular) markSingular(out, g.reason);
}

}  // namespace appell::detail
