// Nearest and farthest points of an ellipsoid from a point: a 1-D root solve.
//
// In the ellipsoid's principal frame (semi-axes aᵢ, point s), a stationary
// point y of |y − s|² on the surface Σ yᵢ²/aᵢ² = 1 satisfies y − s = −t Q⁻¹ y
// (Lagrange), i.e. yᵢ = aᵢ² sᵢ /(aᵢ² + t), with t a root of
//      F(t) = Σ aᵢ² sᵢ² /(aᵢ² + t)² − 1.
// The outward normal there is m ∝ Q⁻¹ y, mᵢ ∝ sᵢ /(aᵢ² + t).
//   nearest  (s outside): the root t > 0. On (−a_min², ∞) F is convex and
//            decreasing and F(0) = Σ sᵢ²/aᵢ² − 1 > 0, so Newton from t = 0
//            climbs monotonically to the root.
//   farthest: the root t < −a_max². On (−∞, −a_max²) F is convex and
//            increasing, so Newton from any point with F > 0 descends
//            monotonically to it. If s has no component along the largest
//            axis, F stays finite at −a_max²; when it is ≤ 0 there the
//            farthest point is not unique (two mirror points) — reported.
// Convergence: |Δt| ≤ tol (|t| + a_max²), tol = max(newton_tol, 4ε), with an
// iteration cap; failure is reported, never returned as a point.
#include "geometry_internal.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace appell::detail {

namespace {

struct Secular {
  Vec3 a2, as2;  // aᵢ², aᵢ² sᵢ²
  double F(double t) const {
    double f = -1;
    for (int i = 0; i < 3; ++i) f += as2[i] / ((a2[i] + t) * (a2[i] + t));
    return f;
  }
  double dF(double t) const {
    double d = 0;
    for (int i = 0; i < 3; ++i) d += -2 * as2[i] / ((a2[i] + t) * (a2[i] + t) * (a2[i] + t));
    return d;
  }
};

}  // namespace

bool ellipsoidExtremalNormal(const Ellipsoid& e, const Vec3& s_body, bool outside,
                             const GeometryOptions& opt, Vec3& m, int& iterations,
                             const char*& reason) {
  const Vec3 s = e.orientation.transpose() * (s_body - e.centre);
  Secular sec;
  sec.a2 = e.semi_axes.cwiseAbs2();
  sec.as2 = sec.a2.cwiseProduct(s.cwiseAbs2());
  const double amax2 = sec.a2.maxCoeff();
  const double eps = std::numeric_limits<double>::epsilon();
  iterations = 0;

  double t;
  if (outside) {
    if (sec.F(0) <= 0) {
      reason = "the support sphere's centre is inside the ellipsoid: no unique nearest point";
      return false;
    }
    t = 0;
  } else {
    // Weight of the largest axis (all axes equal to it, for spheroids).
    double wmax = 0, fothers = -1;
    for (int i = 0; i < 3; ++i) {
      if (sec.a2[i] >= amax2 * (1 - 1e-12)) {
        wmax += sec.as2[i];
      } else {
        const double dd = sec.a2[i] - amax2;
        fothers += sec.as2[i] / (dd * dd);
      }
    }
    const double sw = std::sqrt(wmax);  // = a_max |s_max|
    if (sw > 1e-12 * amax2) {
      t = -amax2 - 0.5 * sw;  // there the largest-axis term alone is 4
    } else if (fothers > 0) {
      t = -amax2;
    } else {
      reason = "no unique farthest point of the ellipsoid from the bowl centre (two mirror "
               "points): the ellipsoid is not pressed against the bowl";
      return false;
    }
  }
  const double scale = amax2 + std::abs(t);
  bool converged = false;
  for (iterations = 1; iterations <= opt.max_iterations; ++iterations) {
    const double d = sec.dF(t);
    if (d == 0 || !std::isfinite(d)) break;
    const double step = sec.F(t) / d;
    t -= step;
    if (std::abs(step) <= std::max(opt.newton_tol, 4 * eps) * (std::abs(t) + scale)) {
      converged = true;
      break;
    }
  }
  if (!converged || !std::isfinite(t)) {
    reason = "ellipsoid nearest/farthest point: Newton did not converge";
    return false;
  }
  Vec3 ml;
  for (int i = 0; i < 3; ++i) ml[i] = s[i] / (sec.a2[i] + t);
  const double len = ml.norm();
  if (!(len > 0) || !std::isfinite(len)) {
    reason = "ellipsoid nearest/farthest point is not defined here";
    return false;
  }
  // Outside (t > 0) m points toward s; inside (t < −a²) away from it.
  m = e.orientation * (ml / len);
  return true;
}

}  // namespace appell::detail
