// Dispatch over the support surface, and the pieces every pair shares:
// the contact point from the Gauss map and the tangent frame with its rates.
#include "geometry_internal.hpp"
#include "terrain_index.hpp"

namespace appell {

namespace detail {

void markSingular(ContactGeometry& out, const char* reason) {
  out.singular = true;
  out.reason = reason;
  out.point_rate.setZero();
  out.normal_rate.setZero();
  out.t1_rate.setZero();
  out.t2_rate.setZero();
}

void finishPoint(const SE3& pose, const Twist& body, const GaussPoint& g, const Vec3& mdot,
                 ContactGeometry& out) {
  out.point_body = g.y;
  out.point = pose.apply(g.y);
  out.margin = g.margin;
  // The geometric contact point moves with the body (material velocity) and
  // slides over the body's surface as the normal turns: d/dt σ(m) = Σ ṁ.
  out.point_rate = body.at(out.point) + pose.R * (g.Sigma * mdot);
  out.support_point = out.point - out.gap * out.normal;
}

void tangentFrame(const Vec3& e, const Vec3& edot, ContactGeometry& out) {
  const Vec3& n = out.normal;
  const Vec3& nd = out.normal_rate;
  // u = (1 − n nᵀ) e,  u̇ = ė − ṅ (n·e) − n (ṅ·e + n·ė),  ṫ1 = (1 − t1 t1ᵀ) u̇ / |u|.
  const Vec3 u = e - n * n.dot(e);
  const double inv_len = 1.0 / u.norm();
  out.t1 = u * inv_len;
  const Vec3 ud = edot - nd * n.dot(e) - n * (nd.dot(e) + n.dot(edot));
  out.t1_rate = (ud - out.t1 * out.t1.dot(ud)) * inv_len;
  out.t2 = n.cross(out.t1);
  out.t2_rate = nd.cross(out.t1) + n.cross(out.t1_rate);
}

void transportedFrame(const Mat3& RS, const Vec3& Omega, ContactGeometry& out) {
  const Vec3& n = out.normal;
  const Vec3& nd = out.normal_rate;
  const Vec3 p = RS.col(2);   // the pole
  const Vec3 a = -RS.col(1);  // t1 at the pole
  // 1 + p·n as |p + n|²/2: accurate near the antipode, where 1 + p·n cancels.
  const Vec3 q = p + n;
  const double k = 0.5 * q.squaredNorm();
  if (!(k > kAntipode)) {
    // n = −p to round-off: no limit exists (the hairy-ball point); the
    // support's own axis, projected, keeps the rows finite and usable.
    tangentFrame(a, Omega.cross(a), out);
    return;
  }
  // t1 = R(p → n) a = a − (p + n)(n·a)/(1 + p·n), with ṗ = Ω × p, ȧ = Ω × a.
  const Vec3 pd = Omega.cross(p), ad = Omega.cross(a);
  const double alpha = n.dot(a) / k;
  const double alpha_d = (nd.dot(a) + n.dot(ad)) / k;
  const double k_d = q.dot(pd + nd);
  out.t1 = a - q * alpha;
  out.t1_rate = ad - (pd + nd) * alpha - q * (alpha_d - alpha * k_d / k);
  out.t2 = n.cross(out.t1);
  out.t2_rate = nd.cross(out.t1) + n.cross(out.t1_rate);
}

}  // namespace detail

void contactGeometry(const Shape& shape, const SupportSurface& surface,
                     const SupportState& support, const SE3& body_pose,
                     const Vec6& body_velocity, ContactGeometry& out,
                     const GeometryOptions& options, int latched_feature,
                     std::span<const int> excluded) {
  out.singular = false;
  out.reason = nullptr;
  out.margin = 1;
  out.iterations = 0;
  out.feature = -1;
  if (!isSmoothContactShape(shape)) {
    out = ContactGeometry{};
    detail::markSingular(out, "collision-only shape has no smooth contact point");
    return;
  }
  std::visit(Overloaded{
                 [&](const Plane& p) {
                   detail::planeGeometry(shape, p, support, body_pose, body_velocity, out, options);
                 },
                 [&](const SphereSurface& s) {
                   detail::sphereSurfaceGeometry(shape, s, support, body_pose, body_velocity, out,
                                                 options);
                 },
                 [&](const TerrainMesh& t) {
                   detail::terrainGeometry(shape, t, support, body_pose, body_velocity, out,
                                           options, latched_feature, excluded);
                 }},
             surface);
}

}  // namespace appell
