// A smooth shape on the outside of a sphere (nearest point to its centre C)
// or inside it (a bowl: the farthest point from C).
//
// Body frame: s = Rᵀ(C − p), contact point y = σ(m) with y − s = ε d m
// (ε = −1 outside: the outward normal m points at C; ε = +1 inside: away
// from it), d = |y − s|. Differentiating,
//     Σ ṁ − ṡ = ε ḋ m + ε d ṁ   ⇒   (Σ − ε d)|_{m⊥} ṁ = (1 − m mᵀ) ṡ,
// with ṡ = Rᵀ(V_S(C) − V_B(C)) the velocity of C relative to the body.
// Outside, Σ + d is positive definite on m⊥ for any convex part. Inside it is
// Σ − d, which must be negative definite: every radius of curvature at the
// contact below d — the local form of "the shape fits the bowl"; its failure
// is reported. n = −R m, ṅ = ω × n − R ṁ. Gap: d − R_s outside, R_s − d inside.
#include "geometry_internal.hpp"

#include <Eigen/Eigenvalues>

namespace appell::detail {

void sphereSurfaceGeometry(const Shape& shape, const SphereSurface& sphere, const SupportState& S,
                           const SE3& pose, const Vec6& V, ContactGeometry& out,
                           const GeometryOptions& opt) {
  const Twist body(V), sup(S.V);
  const bool outside = sphere.side == SphereSurface::Side::Outside;
  const double eps = outside ? -1.0 : 1.0;
  const Vec3 C = S.pose.apply(sphere.centre);
  const Vec3 s = pose.R.transpose() * (C - pose.p);
  const Vec3 sdot = pose.R.transpose() * (sup.at(C) - body.at(C));

  Vec3 m;
  const char* reason = nullptr;
  const bool ok = extremalNormal(shape, s, outside, opt, m, out.iterations, reason);
  const GaussPoint g = inverseGaussMap(shape, m, opt.singular_tol);
  const double d = eps * m.dot(g.y - s);

  out.normal = -(pose.R * m);
  out.gap = outside ? d - sphere.radius : sphere.radius - d;

  // ṁ on the tangent plane of m: 2×2 system in the basis (e1, e2).
  Eigen::Matrix<double, 3, 2> E;
  E.col(0) = m.unitOrthogonal();
  E.col(1) = m.cross(E.col(0));
  const Eigen::Matrix2d B = E.transpose() * (g.Sigma - eps * d * Mat3::Identity()) * E;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(B);
  const Eigen::Vector2d lam = es.eigenvalues();
  Vec3 mdot = Vec3::Zero();
  const char* bad = nullptr;
  if (ok && !g.singular) {
    if (!(d > 0)) {
      bad = "the support sphere's centre is inside the body: no unique contact";
    } else if (outside ? !(lam.minCoeff() > opt.singular_tol * d)
                       : !(lam.maxCoeff() < -opt.singular_tol * d)) {
      bad = outside ? "degenerate curvature at the contact (shape not convex there)"
                    : "the shape does not fit the bowl here: a radius of curvature at the contact "
                      "reaches the distance to the bowl centre";
    } else if (!outside) {
      // Ellipsoids: uniqueness of the farthest point (Blaschke's rolling theorem)
      // needs every radius of curvature below d.
      if (const auto* el = std::get_if<Ellipsoid>(&shape)) {
        const double amax = el->semi_axes.maxCoeff(), amin = el->semi_axes.minCoeff();
        if (!(amax * amax / amin < d))
          bad = "no unique contact in the bowl: the ellipsoid's largest radius of curvature "
                "a_max²/a_min is not below its distance to the bowl centre";
      }
    }
    if (!bad) {
      const Eigen::Vector2d rhs = E.transpose() * sdot;
      mdot = E * es.eigenvectors() *
             (es.eigenvectors().transpose() * rhs).cwiseQuotient(lam);
    }
  }
  out.normal_rate = body.w.cross(out.normal) - pose.R * mdot;
  finishPoint(pose, body, g, mdot, out);

  // The support's frame carried from its pole z_S along the great circle to
  // n: continuous wherever the contact goes but the antipode (a ball on top
  // of a globe, or at the bottom of a bowl, is at the pole). A reference axis
  // switched where it nears n made the rows jump at 45° from that axis.
  transportedFrame(S.pose.R, sup.w, out);

  if (!ok) markSingular(out, reason);
  else if (g.singular) markSingular(out, g.reason);
  else if (bad) markSingular(out, bad);
}

}  // namespace appell::detail
