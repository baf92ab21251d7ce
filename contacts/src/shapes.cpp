// Shape names, validation, the rolling test, and the inverse Gauss map σ(m).
#include <appell/shapes.hpp>

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace appell {

namespace {

template <class... Ts>
struct Overloaded : Ts... {
  using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;

bool finite(const Vec3& x) { return x.allFinite(); }

[[noreturn]] void fail(const char* shape, const std::string& what) {
  throw std::invalid_argument(std::string(shape) + ": " + what);
}

void checkRadius(const char* shape, const char* what, double r, bool allow_zero) {
  if (!std::isfinite(r) || r < 0 || (!allow_zero && r == 0)) {
    std::ostringstream s;
    s << what << " must be " << (allow_zero ? "≥ 0" : "> 0") << " and finite (got " << r << ")";
    fail(shape, s.str());
  }
}

void checkAxis(const char* shape, const Vec3& axis) {
  if (!finite(axis) || std::abs(axis.norm() - 1.0) > 1e-9)
    fail(shape, "axis must be a finite unit vector");
}

}  // namespace

const char* shapeName(const Shape& shape) {
  return std::visit(Overloaded{[](const PointShape&) { return "point"; },
                               [](const Sphere&) { return "sphere"; },
                               [](const Ellipsoid&) { return "ellipsoid"; },
                               [](const Disk&) { return "disk"; },
                               [](const Torus&) { return "torus"; },
                               [](const SphericalCap&) { return "spherical cap"; },
                               [](const Box&) { return "box"; },
                               [](const Cylinder&) { return "cylinder"; },
                               [](const Mesh&) { return "mesh"; }},
                    shape);
}

bool isSmoothContactShape(const Shape& shape) {
  return !(std::holds_alternative<Box>(shape) || std::holds_alternative<Cylinder>(shape) ||
           std::holds_alternative<Mesh>(shape));
}

bool canRoll(const Shape& shape, std::string* why) {
  const char* reason = std::visit(
      Overloaded{
          [](const PointShape&) -> const char* {
            return "a point cannot roll (no-slip would pin it): use a knife edge or sliding "
                   "contact, or give it a radius (sphere)";
          },
          [](const Box&) -> const char* {
            return "a box cannot roll: its faces and edges give no unique smooth contact point; "
                   "use a sphere, ellipsoid, disk, torus or spherical cap";
          },
          [](const Cylinder&) -> const char* {
            return "a cylinder cannot roll as a solid (its rim edges and flat ends are not "
                   "smooth): declare the wheel's rim as a disk, or as a torus with a tyre radius";
          },
          [](const Mesh&) -> const char* {
            return "a mesh is collision-only: give an analytic rolling shape (sphere, "
                   "ellipsoid, disk, torus, spherical cap)";
          },
          [](const auto&) -> const char* { return nullptr; }},
      shape);
  if (reason && why) *why = reason;
  return reason == nullptr;
}

void validateShape(const Shape& shape) {
  std::visit(
      Overloaded{
          [](const PointShape& s) {
            if (!finite(s.position)) fail("point", "position must be finite");
          },
          [](const Sphere& s) {
            checkRadius("sphere", "radius", s.radius, false);
            if (!finite(s.centre)) fail("sphere", "centre must be finite");
          },
          [](const Ellipsoid& s) {
            for (int i = 0; i < 3; ++i) checkRadius("ellipsoid", "semi-axis", s.semi_axes[i], false);
            if (!finite(s.centre)) fail("ellipsoid", "centre must be finite");
            if (!s.orientation.allFinite() ||
                !(s.orientation.transpose() * s.orientation).isApprox(Mat3::Identity(), 1e-9) ||
                s.orientation.determinant() < 0)
              fail("ellipsoid", "orientation must be a rotation matrix");
          },
          [](const Disk& s) {
            checkRadius("disk", "radius", s.radius, false);
            if (!finite(s.centre)) fail("disk", "centre must be finite");
            checkAxis("disk", s.axis);
          },
          [](const Torus& s) {
            checkRadius("torus", "major radius", s.major, false);
            checkRadius("torus", "minor (tyre) radius", s.minor, true);
            if (!finite(s.centre)) fail("torus", "centre must be finite");
            checkAxis("torus", s.axis);
          },
          [](const SphericalCap& s) {
            checkRadius("spherical cap", "radius", s.radius, false);
            if (!finite(s.centre)) fail("spherical cap", "centre must be finite");
            checkAxis("spherical cap", s.axis);
            if (!(s.half_angle > 0 && s.half_angle <= M_PI))
              fail("spherical cap", "half-angle must lie in (0, π]");
          },
          [](const Box& s) {
            for (int i = 0; i < 3; ++i) checkRadius("box", "half-extent", s.half_extents[i], false);
          },
          [](const Cylinder& s) {
            checkRadius("cylinder", "radius", s.radius, false);
            checkRadius("cylinder", "length", s.length, false);
          },
          [](const Mesh& s) {
            if (s.file.empty()) fail("mesh", "file name is empty");
          }},
      shape);
}

namespace {

// Torus (disk when r = 0), outer convex part: σ = c + R u + r m, u = P m/|P m|.
// Σ = R (P − u uᵀ)/|P m| + r (1 − m mᵀ): the ring direction has radius of
// curvature R/|P m| + r, the tube direction r.
GaussPoint torusPoint(const Vec3& c, const Vec3& a, double R, double r, const Vec3& m, double tol) {
  GaussPoint g;
  const Vec3 pm = m - a * a.dot(m);
  const double len = pm.norm();
  if (len < tol) {
    g.singular = true;
    g.reason = "wheel lying flat: the contact normal is parallel to the wheel axis, every rim "
               "point touches";
    g.y = c + R * a.unitOrthogonal() + r * m;  // finite stand-in
    return g;
  }
  const Vec3 u = pm / len;
  const Mat3 P = Mat3::Identity() - a * a.transpose();
  g.y = c + R * u + r * m;
  g.Sigma = (R / len) * (P - u * u.transpose()) + r * (Mat3::Identity() - m * m.transpose());
  return g;
}

}  // namespace

GaussPoint inverseGaussMap(const Shape& shape, const Vec3& m, double tol) {
  const Mat3 Pm = Mat3::Identity() - m * m.transpose();
  return std::visit(
      Overloaded{
          [&](const PointShape& s) {
            GaussPoint g;
            g.y = s.position;
            return g;
          },
          [&](const Sphere& s) {
            GaussPoint g;
            g.y = s.centre + s.radius * m;
            g.Sigma = s.radius * Pm;
            return g;
          },
          [&](const SphericalCap& s) {
            GaussPoint g;
            g.y = s.centre + s.radius * m;
            g.Sigma = s.radius * Pm;
            if (m.dot(s.axis) < std::cos(s.half_angle) - tol) {
              g.singular = true;
              g.reason = "contact outside the spherical cap: the body would touch on its rim or "
                         "flat face";
            }
            return g;
          },
          [&](const Ellipsoid& s) {
            // σ = c + Q m/√(mᵀQm), Σ = (Q − Q m mᵀ Q/(mᵀQm))/√(mᵀQm).
            GaussPoint g;
            const Mat3 Q = s.orientation * s.semi_axes.cwiseAbs2().asDiagonal() *
                           s.orientation.transpose();
            const Vec3 Qm = Q * m;
            const double k = std::sqrt(m.dot(Qm));
            g.y = s.centre + Qm / k;
            g.Sigma = (Q - Qm * Qm.transpose() / (k * k)) / k;
            return g;
          },
          [&](const Disk& s) { return torusPoint(s.centre, s.axis, s.radius, 0.0, m, tol); },
          [&](const Torus& s) { return torusPoint(s.centre, s.axis, s.major, s.minor, m, tol); },
          [&](const auto&) {
            GaussPoint g;
            g.singular = true;
            g.reason = "collision-only shape has no smooth contact point";
            return g;
          }},
      shape);
}

bool fitsInBowl(const Shape& shape, double R, std::string* why) {
  std::ostringstream s;
  std::visit(Overloaded{[&](const PointShape&) {},
                        [&](const Sphere& x) {
                          if (!(x.radius < R))
                            s << "sphere radius " << x.radius << " is not below the bowl radius " << R;
                        },
                        [&](const SphericalCap& x) {
                          if (!(x.radius < R))
                            s << "cap radius " << x.radius << " is not below the bowl radius " << R;
                        },
                        [&](const Ellipsoid& x) {
                          const double rho = x.semi_axes.maxCoeff() * x.semi_axes.maxCoeff() /
                                             x.semi_axes.minCoeff();
                          if (!(rho < R))
                            s << "ellipsoid's largest radius of curvature a_max²/a_min = " << rho
                              << " is not below the bowl radius " << R
                              << " (the contact would not be unique)";
                        },
                        [&](const Disk& x) {
                          if (!(x.radius < R))
                            s << "disk radius " << x.radius << " is not below the bowl radius " << R;
                        },
                        [&](const Torus& x) {
                          if (!(x.major + x.minor < R))
                            s << "torus outer radius " << x.major + x.minor
                              << " is not below the bowl radius " << R;
                        },
                        [&](const auto&) { s << "collision-only shape cannot roll in a bowl"; }},
             shape);
  const std::string msg = s.str();
  if (!msg.empty() && why) *why = msg;
  return msg.empty();
}

}  // namespace appell
