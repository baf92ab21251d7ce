// The rolling shape of a mesh wheel and its roundness (wheel_fit.hpp states
// the fit, the runout and the rule).
#include <appell/wheel_fit.hpp>

#include <Eigen/QR>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace appell {

namespace {

using Vec2 = Eigen::Vector2d;  // a point across the axle

double cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

// R minus the distance from the origin to the nearest edge of the convex hull
// of `points` (Andrew's monotone chain, counter-clockwise), R when the hull
// has no area.
double runoutAbout(std::vector<Vec2> points, double R) {
  std::sort(points.begin(), points.end(),
            [](const Vec2& a, const Vec2& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
  points.erase(std::unique(points.begin(), points.end()), points.end());  // a prism's two rims project alike
  std::vector<Vec2> hull(2 * points.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {  // lower hull
    while (k >= 2 && cross2(hull[k - 1] - hull[k - 2], points[i] - hull[k - 2]) <= 0) --k;
    hull[k++] = points[i];
  }
  for (std::size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {  // upper hull
    while (k >= lower && cross2(hull[k - 1] - hull[k - 2], points[i] - hull[k - 2]) <= 0) --k;
    hull[k++] = points[i];
  }
  if (k < 4) return R;  // fewer than 3 distinct corners (k counts the first twice)
  double nearest = INFINITY;
  for (std::size_t i = 0; i + 1 < k; ++i) {
    const Vec2 edge = hull[i + 1] - hull[i];
    nearest = std::min(nearest, cross2(edge, -hull[i]) / edge.norm());  // < 0: origin outside
  }
  return R - nearest;
}

}  // namespace

bool isWheel(const WheelFit& fit) {
  const double allowed = kWheelTolerance * fit.outer_radius;
  return fit.runout <= allowed && (!fit.torus || fit.max_deviation <= allowed);
}

WheelFit fitWheel(const std::vector<Vec3>& vertices, const Vec3& axle_point, const Vec3& axle) {
  if (vertices.size() < 3) throw std::invalid_argument("a wheel mesh needs at least 3 vertices");
  const Vec3 a = axle.normalized();
  std::vector<std::array<double, 2>> zr(vertices.size());
  double R = 0, zlo = INFINITY, zhi = -INFINITY;
  for (std::size_t k = 0; k < vertices.size(); ++k) {
    const Vec3 p = vertices[k] - axle_point;
    const double z = a.dot(p), r = (p - z * a).norm();
    zr[k] = {z, r};
    R = std::max(R, r);
    zlo = std::min(zlo, z);
    zhi = std::max(zhi, z);
  }
  WheelFit fit;
  fit.outer_radius = R;
  fit.width = zhi - zlo;
  if (!(R > 0)) throw std::invalid_argument("the wheel mesh lies on its axle (no radius)");
  if (!(fit.width > 1e-9 * R))
    throw std::invalid_argument("the wheel mesh is flat across its axle (no width): give an explicit shape");
  const double zc = 0.5 * (zlo + zhi);
  {
    const Vec3 u = a.unitOrthogonal(), w = a.cross(u);
    std::vector<Vec2> across(vertices.size());
    for (std::size_t k = 0; k < vertices.size(); ++k) {
      const Vec3 p = vertices[k] - axle_point;
      across[k] = Vec2(u.dot(p), w.dot(p));
    }
    fit.runout = runoutAbout(std::move(across), R);
  }

  // The tread and its circle fit, in coordinates about (z_c, R) scaled by R
  // for conditioning.
  std::vector<int> tread;
  for (std::size_t k = 0; k < zr.size(); ++k)
    if (zr[k][1] >= R - 0.5 * fit.width) tread.push_back(static_cast<int>(k));
  fit.tread_vertices = static_cast<int>(tread.size());
  Eigen::MatrixX3d M(tread.size(), 3);
  Eigen::VectorXd y(tread.size());
  for (std::size_t i = 0; i < tread.size(); ++i) {
    const double z = (zr[tread[i]][0] - zc) / R, r = (zr[tread[i]][1] - R) / R;
    M.row(i) << 2 * z, 2 * r, 1;
    y[i] = z * z + r * r;
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixX3d> qr(M);
  const bool has_profile = qr.rank() == 3;  // a flat tread's points are collinear
  double rho = INFINITY, z0 = 0, r0 = 0;
  if (has_profile) {
    const Vec3 s = qr.solve(y);
    rho = R * std::sqrt(std::max(0.0, s[2] + s[0] * s[0] + s[1] * s[1]));
    z0 = zc + R * s[0];
    r0 = R + R * s[1];
  }
  // A rounded tread has vertices on its crown (|β| < π/4 on the tube circle,
  // β = atan2(z − z₀, r − r₀)); a flat one fitted by a circle of radius w/2
  // has them all at the circle's vertical sides (|β| ≈ π/2): a cylinder,
  // however its rims are tessellated or rounded off by export noise.
  int crown = 0;
  if (has_profile)
    for (int k : tread)
      if (std::abs(std::atan2(zr[k][0] - z0, zr[k][1] - r0)) < 0.25 * 3.141592653589793) ++crown;
  if (has_profile && rho < fit.width && r0 > 0 && crown >= 3) {
    fit.torus = true;
    fit.tube_radius = rho;
    fit.shape = Torus{r0, rho, axle_point + z0 * a, a};
    for (int k : tread)
      fit.max_deviation = std::max(fit.max_deviation,
                                   std::abs(std::hypot(zr[k][0] - z0, zr[k][1] - r0) - rho));
  } else {
    fit.shape = Disk{R, axle_point + zc * a, a};
    for (int k : tread) fit.max_deviation = std::max(fit.max_deviation, R - zr[k][1]);
  }
  return fit;
}

}  // namespace appell
