// Shape names, scene-file parameters, validation, the rolling test, the
// inverse Gauss map σ(m) and the extreme point toward a sphere's centre: every
// per-shape fact in one file, each as a visit with one handler per alternative.
#include <appell/shapes.hpp>
#include <appell/name_table.hpp>
#include <appell/overloaded.hpp>

#include "geometry_internal.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <type_traits>
#include <utility>

namespace appell {

namespace {

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

// ---- scene-file parameters ------------------------------------------------

Vec3 centre(const ShapeParameters& p) { return p.has("xyz") ? p.vector("xyz") : Vec3::Zero(); }

Vec3 direction(const ShapeParameters& p, const char* name, const Vec3& fallback) {
  if (!p.has(name)) return fallback;
  const Vec3 v = p.vector(name);
  if (!(v.norm() > 1e-12)) throw std::invalid_argument(std::string("'") + name + "' is a zero vector");
  return v.normalized();
}

Shape makePoint(const ShapeParameters& p) { return PointShape{centre(p)}; }
Shape makeSphere(const ShapeParameters& p) { return Sphere{p.number("radius"), centre(p)}; }
Shape makeEllipsoid(const ShapeParameters& p) {
  Ellipsoid e;
  e.semi_axes = p.vector("semi_axes");
  e.centre = centre(p);
  if (p.has("rpy")) e.orientation = p.rotation("rpy");
  return e;
}
Shape makeDisk(const ShapeParameters& p) {
  return Disk{p.number("radius"), centre(p), direction(p, "axis", Vec3::UnitZ())};
}
// `radius` is the wheel's outer radius, as for a cylinder collision with a
// tyre: the tube's centre circle has radius − tyre_radius.
Shape makeTorus(const ShapeParameters& p) {
  const double outer = p.number("radius"), tyre = p.number("tyre_radius");
  if (!(tyre < outer)) throw std::invalid_argument("'tyre_radius' must be smaller than 'radius'");
  return Torus{outer - tyre, tyre, centre(p), direction(p, "axis", Vec3::UnitZ())};
}
// Without half_angle a hemisphere.
Shape makeCap(const ShapeParameters& p) {
  SphericalCap c;
  c.radius = p.number("radius");
  c.centre = centre(p);
  c.axis = direction(p, "axis", -Vec3::UnitZ());
  if (p.has("half_angle")) c.half_angle = p.number("half_angle");
  return c;
}

// ---- the table: one describe() per alternative ----------------------------

ShapeType describe(std::type_identity<PointShape>) {
  return {"point", {}, "a body point (blade points, sliding feet)", ShapeRole::Point,
          "a point cannot roll: kind 'rolling' pins it (a sticking point, as at a box's "
          "corners); use a knife edge or sliding contact, or give it a radius (sphere)",
          {"xyz"}, R"(xyz="0.1 0 0")", makePoint};
}
ShapeType describe(std::type_identity<Sphere>) {
  return {"sphere", {}, "sphere of `radius` about `xyz`", ShapeRole::Rolling, nullptr,
          {"radius", "xyz"}, R"(radius="0.1" xyz="0 0 0.01")", makeSphere};
}
ShapeType describe(std::type_identity<Ellipsoid>) {
  return {"ellipsoid", {}, "semi-axes `semi_axes` along the axes rotated by `rpy`, centre `xyz`",
          ShapeRole::Rolling, nullptr, {"semi_axes", "xyz", "rpy"},
          R"(semi_axes="0.1 0.2 0.3" xyz="0 0 0.01" rpy="0 0 1.5708")", makeEllipsoid};
}
ShapeType describe(std::type_identity<Disk>) {
  return {"disk", {}, "thin disk rolling on its rim: `radius`, centre `xyz`, axle `axis`",
          ShapeRole::Rolling, nullptr, {"radius", "xyz", "axis"},
          R"(radius="0.3" xyz="0 0 0" axis="0 1 0")", makeDisk};
}
ShapeType describe(std::type_identity<Torus>) {
  return {"torus", {}, "wheel with a tyre: outer `radius`, `tyre_radius`, centre `xyz`, axle `axis`",
          ShapeRole::Rolling, nullptr, {"radius", "tyre_radius", "xyz", "axis"},
          R"(radius="0.3" tyre_radius="0.05" xyz="0 0 0" axis="0 1 0")", makeTorus};
}
ShapeType describe(std::type_identity<SphericalCap>) {
  return {"cap", {"hemisphere", "spherical_cap"},
          "spherical cap: sphere `radius` about `xyz`, pole direction `axis`, `half_angle` "
          "(default π/2: a hemisphere)",
          ShapeRole::Rolling, nullptr, {"radius", "xyz", "axis", "half_angle"},
          R"(radius="0.2" xyz="0 0 0.05" axis="0 0 -1" half_angle="1.2")", makeCap};
}
ShapeType describe(std::type_identity<Box>) {
  return {"box", {}, "box (collision only)", ShapeRole::CollisionOnly,
          "a box cannot roll: its faces and edges give no unique smooth contact point", {},
          nullptr, nullptr};
}
ShapeType describe(std::type_identity<Cylinder>) {
  return {"cylinder", {}, "solid cylinder (collision only)", ShapeRole::CollisionOnly,
          "a cylinder cannot roll as a solid (its rim edges and flat ends are not smooth): "
          "declare the wheel's rim as a disk, or as a torus with a tyre radius",
          {}, nullptr, nullptr};
}
ShapeType describe(std::type_identity<Mesh>) {
  return {"mesh", {}, "triangle mesh (collision only)", ShapeRole::CollisionOnly,
          "a mesh is collision-only: give an analytic rolling shape", {}, nullptr, nullptr};
}

template <std::size_t... I>
std::vector<ShapeType> buildTable(std::index_sequence<I...>) {
  return {describe(std::type_identity<std::variant_alternative_t<I, Shape>>{})...};
}

}  // namespace

std::span<const ShapeType> shapeTable() {
  static const std::vector<ShapeType> table =
      buildTable(std::make_index_sequence<std::variant_size_v<Shape>>{});
  return table;
}

const ShapeType& shapeType(const Shape& shape) { return shapeTable()[shape.index()]; }

const ShapeType* findShapeType(std::string_view text) { return findByName(shapeTable(), text); }

std::string rollingShapeNames() {
  std::string s;
  for (const ShapeType& t : shapeTable())
    if (t.role == ShapeRole::Rolling) s += (s.empty() ? "" : ", ") + std::string(t.name);
  return s;
}

std::string declarableShapeNames() {
  std::vector<ShapeType> declarable;
  for (const ShapeType& t : shapeTable())
    if (t.make) declarable.push_back(t);
  return knownNames(std::span<const ShapeType>(declarable));
}

const char* shapeName(const Shape& shape) { return shapeType(shape).name; }

bool isSmoothContactShape(const Shape& shape) {
  return shapeType(shape).role != ShapeRole::CollisionOnly;
}

bool canRoll(const Shape& shape, std::string* why) {
  const ShapeType& t = shapeType(shape);
  if (t.role == ShapeRole::Rolling) return true;
  if (why) {
    *why = t.cannot_roll;
    if (t.role == ShapeRole::CollisionOnly) *why += "; use one of: " + rollingShapeNames();
  }
  return false;
}

const Vec3* wheelAxis(const Shape& shape) {
  return std::visit(Overloaded{[](const PointShape&) -> const Vec3* { return nullptr; },
                               [](const Sphere&) -> const Vec3* { return nullptr; },
                               [](const Ellipsoid&) -> const Vec3* { return nullptr; },
                               [](const Disk& s) -> const Vec3* { return &s.axis; },
                               [](const Torus& s) -> const Vec3* { return &s.axis; },
                               [](const SphericalCap&) -> const Vec3* { return nullptr; },
                               [](const Box&) -> const Vec3* { return nullptr; },
                               [](const Cylinder&) -> const Vec3* { return nullptr; },
                               [](const Mesh&) -> const Vec3* { return nullptr; }},
                    shape);
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
  g.margin = len;
  const double inv_len = 1.0 / len;
  const Vec3 u = pm * inv_len;
  g.y = c + R * u + r * m;
  g.Sigma.noalias() = (R * inv_len) * (Mat3::Identity() - a * a.transpose() - u * u.transpose());
  if (r != 0) g.Sigma.noalias() += r * (Mat3::Identity() - m * m.transpose());  // r = 0: a disk
  return g;
}

GaussPoint collisionOnly() {
  GaussPoint g;
  g.singular = true;
  g.reason = "collision-only shape has no smooth contact point";
  return g;
}

}  // namespace

GaussPoint inverseGaussMap(const Shape& shape, const Vec3& m, double tol) {
  const auto Pm = [&m] { return Mat3(Mat3::Identity() - m * m.transpose()); };
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
            g.Sigma = s.radius * Pm();
            return g;
          },
          [&](const SphericalCap& s) {
            GaussPoint g;
            g.y = s.centre + s.radius * m;
            g.Sigma = s.radius * Pm();
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
          [&](const Box&) { return collisionOnly(); },
          [&](const Cylinder&) { return collisionOnly(); },
          [&](const Mesh&) { return collisionOnly(); }},
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
                        [&](const Box&) { s << "a box cannot roll in a bowl"; },
                        [&](const Cylinder&) { s << "a cylinder cannot roll in a bowl"; },
                        [&](const Mesh&) { s << "a mesh cannot roll in a bowl"; }},
             shape);
  const std::string msg = s.str();
  if (!msg.empty() && why) *why = msg;
  return msg.empty();
}

namespace detail {

namespace {

// A disk or torus (tube radius irrelevant here): the tube centre nearest C
// (outside) or farthest from it (inside) lies on the centre circle, in the
// direction of C's projection on the wheel plane.
bool wheelExtremalNormal(const Vec3& c, const Vec3& a, double Rm, const Vec3& s, bool outside,
                         double tol, Vec3& m, const char*& reason) {
  const Vec3 w = (s - c) - a * a.dot(s - c);
  const double wl = w.norm();
  m = -a;
  if (wl <= tol * (Rm + s.norm())) {
    reason = "the support sphere's centre lies on the wheel's axis: every rim point is "
             "equally near, no unique contact";
    return false;
  }
  const Vec3 u = outside ? Vec3(w / wl) : Vec3(-w / wl);
  const Vec3 k = c + Rm * u;  // tube centre at the contact
  const Vec3 dir = outside ? Vec3(s - k) : Vec3(k - s);
  const double len = dir.norm();
  if (len <= tol * (Rm + s.norm())) {
    reason = "the support sphere's centre lies on the wheel's rim circle";
    return false;
  }
  m = dir / len;
  // The Gauss map covers the outer (convex) part of the wheel only.
  if ((m - a * a.dot(m)).dot(u) <= 0) {
    reason = "contact on the inner (non-convex) side of the wheel: the sphere pokes "
             "through the wheel's hole";
    return false;
  }
  return true;
}

}  // namespace

bool extremalNormal(const Shape& shape, const Vec3& s, bool outside, const GeometryOptions& opt,
                    Vec3& m, int& iterations, const char*& reason) {
  const double tol = opt.singular_tol;
  // Shapes symmetric about a centre c: the extreme point lies on the line from c to s.
  auto fromCentre = [&](const Vec3& c, double size) {
    const Vec3 dir = outside ? Vec3(s - c) : Vec3(c - s);
    const double len = dir.norm();
    if (len <= tol * (size + s.norm())) {
      reason = "the support sphere's centre coincides with the shape's centre: every direction "
               "is a contact normal";
      m = Vec3::UnitZ();
      return false;
    }
    m = dir / len;
    return true;
  };
  auto collisionOnly = [&] {
    reason = "collision-only shape has no smooth contact point";
    m = Vec3::UnitZ();
    return false;
  };
  return std::visit(
      Overloaded{
          [&](const PointShape& x) { return fromCentre(x.position, 1.0); },
          [&](const Sphere& x) { return fromCentre(x.centre, x.radius); },
          [&](const SphericalCap& x) { return fromCentre(x.centre, x.radius); },
          [&](const Ellipsoid& x) {
            if (ellipsoidExtremalNormal(x, s, outside, opt, m, iterations, reason)) return true;
            // A finite stand-in for the report.
            const Vec3 dir = outside ? Vec3(s - x.centre) : Vec3(x.centre - s);
            m = dir.norm() > 0 && dir.allFinite() ? Vec3(dir.normalized()) : Vec3(Vec3::UnitZ());
            return false;
          },
          [&](const Disk& x) {
            return wheelExtremalNormal(x.centre, x.axis, x.radius, s, outside, tol, m, reason);
          },
          [&](const Torus& x) {
            return wheelExtremalNormal(x.centre, x.axis, x.major, s, outside, tol, m, reason);
          },
          [&](const Box&) { return collisionOnly(); },
          [&](const Cylinder&) { return collisionOnly(); },
          [&](const Mesh&) { return collisionOnly(); }},
      shape);
}

}  // namespace detail

}  // namespace appell
