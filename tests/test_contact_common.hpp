// Shared fixtures of the contact tests: a catalogue of shapes and supports
// (fixed and moving), random rigid placements near contact, finite differences.
#pragma once

#include <appell/contact_geometry.hpp>
#include <appell/contacts.hpp>

#include "random_draws.hpp"

#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

namespace appell::testing {

using appell::test::drawVec3;  // (random_draws.hpp: one draw order for every compiler)
inline Vec3 randomVec(std::mt19937& rng, double scale = 1.0) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  return scale * drawVec3(u, rng);
}
inline Vec3 randomUnit(std::mt19937& rng) {
  std::normal_distribution<double> g;
  return drawVec3(g, rng).normalized();
}
inline Quat randomQuat(std::mt19937& rng) {
  std::normal_distribution<double> g;
  const double z = g(rng);
  const double y = g(rng);
  const double x = g(rng);
  const double w = g(rng);
  return Quat(w, x, y, z).normalized();
}
inline double uniform(std::mt19937& rng, double a, double b) {
  return std::uniform_real_distribution<double>(a, b)(rng);
}

struct ShapeCase {
  std::string name;
  Shape shape;
};

/// Every smooth shape, off-centre in its body frame.
inline std::vector<ShapeCase> shapeCases() {
  const Mat3 tilt = (Eigen::AngleAxisd(0.4, Vec3(1, 2, 3).normalized()) *
                     Eigen::AngleAxisd(-0.7, Vec3::UnitX()))
                        .toRotationMatrix();
  return {
      {"sphere", Sphere{0.3, Vec3(0.05, -0.02, 0.1)}},
      {"ellipsoid", Ellipsoid{Vec3(0.4, 0.25, 0.15), Vec3(0.02, 0.03, -0.05), tilt}},
      {"disk", Disk{0.35, Vec3(0.01, 0.0, 0.02), Vec3(0.2, 1.0, 0.1).normalized()}},
      {"torus", Torus{0.3, 0.06, Vec3(-0.02, 0.01, 0.03), Vec3(0.1, 1.0, -0.2).normalized()}},
      {"hemisphere", SphericalCap{0.3, Vec3(0.0, 0.02, 0.05), Vec3(0.1, 0.0, -1.0).normalized(),
                                  M_PI / 2}},
      {"point", PointShape{Vec3(0.1, 0.2, -0.1)}},
  };
}

/// A support whose frame translates along a curve and rotates about a fixed
/// axis by a polynomial angle: V and A = dV/dt in closed form (a user callback).
inline PrescribedMotion wobblingMotion() {
  PrescribedMotion m;
  m.state = [](double t) {
    const Vec3 k = Vec3(0.3, -0.5, 1.0).normalized();
    const double th = 0.2 * t + 0.15 * t * t, thd = 0.2 + 0.3 * t, thdd = 0.3;
    const Vec3 p(0.1 * std::sin(t), 0.05 * t * t, 0.1 * std::cos(2 * t));
    const Vec3 pd(0.1 * std::cos(t), 0.1 * t, -0.2 * std::sin(2 * t));
    const Vec3 pdd(-0.1 * std::sin(t), 0.1, -0.4 * std::cos(2 * t));
    SupportState s;
    s.pose.R = axisAngle(k, th);
    s.pose.p = p;
    // v_O = ṗ + ω × (0 − p);  A = d/dt [ω; v_O].
    s.V << thd * k, pd - thd * k.cross(p);
    s.A << thdd * k, pdd - thdd * k.cross(p) - thd * k.cross(pd);
    return s;
  };
  return m;
}

struct SupportCase {
  std::string name;
  Support support;
};

inline std::vector<SupportCase> supportCases() {
  const Plane tilted{Vec3(0.1, 0.2, -0.3), Vec3(0.1, -0.2, 1.0).normalized()};
  const Plane ground{Vec3::Zero(), Vec3::UnitZ()};
  const SphereSurface globe{Vec3(0.2, -0.1, 0.3), 1.5, SphereSurface::Side::Outside};
  const SphereSurface bowl{Vec3(0.1, 0.3, 2.0), 2.0, SphereSurface::Side::Inside};
  SinusoidalTiltMotion tilt;
  tilt.point = Vec3(0.3, 0.0, 0.0);
  tilt.axis = Vec3::UnitX();
  tilt.amplitude = 0.4;
  tilt.frequency = 2.1;
  tilt.phase = 0.3;
  return {
      {"plane", {tilted, StaticMotion{}, "plane"}},
      {"turntable", {ground, turntable(Vec3(0.5, 0.2, 0), Vec3::UnitZ(), 1.3), "turntable"}},
      {"conveyor", {tilted, conveyor(Vec3(0.7, 0.2, 0.0) - Vec3(0.7, 0.2, 0.0).dot(tilted.normal) * tilted.normal), "conveyor"}},
      {"tilting plane", {ground, tilt, "tilting plane"}},
      {"wobbling plane", {tilted, wobblingMotion(), "wobbling plane"}},
      {"globe", {globe, StaticMotion{}, "globe"}},
      {"spinning globe",
       {globe, turntable(Vec3(0.5, 0.0, 0.0), Vec3(0.0, 0.6, 0.8), 0.9), "spinning globe"}},
      {"bowl", {bowl, StaticMotion{}, "bowl"}},
      {"tilting bowl", {bowl, tilt, "tilting bowl"}},
      {"wobbling bowl", {bowl, wobblingMotion(), "wobbling bowl"}},
  };
}

/// Acceptance of a random placement for smooth finite differences: regular,
/// away from singular sets and from the tangent-frame switch.
inline bool wellPosed(const Shape& shape, const SupportSurface& surface, const SupportState& S,
                      const SE3& pose, const ContactGeometry& g) {
  if (g.singular) return false;
  const Vec3 m = -(pose.R.transpose() * g.normal);
  if (const auto* d = std::get_if<Disk>(&shape); d && std::abs(m.dot(d->axis)) > 0.85) return false;
  if (const auto* d = std::get_if<Torus>(&shape); d && std::abs(m.dot(d->axis)) > 0.85) return false;
  if (const auto* c = std::get_if<SphericalCap>(&shape);
      c && m.dot(c->axis) < std::cos(c->half_angle) + 0.2)
    return false;
  if (std::holds_alternative<SphereSurface>(surface)) {
    const Vec3 e = S.pose.R.col(0);
    const double q = (e - g.normal * g.normal.dot(e)).squaredNorm();
    if (std::abs(q - 0.5) < 0.05) return false;
  }
  return true;
}

/// Random pose with the body's contact point at signed gap `gap` from the
/// support (at support state S). Returns false if no well-posed placement was found.
inline bool placeNearContact(const Shape& shape, const SupportSurface& surface,
                             const SupportState& S, std::mt19937& rng, double gap, SE3& pose,
                             const GeometryOptions& opt = {}) {
  for (int attempt = 0; attempt < 2000; ++attempt) {
    pose.R = randomQuat(rng).toRotationMatrix();
    if (const auto* p = std::get_if<Plane>(&surface)) {
      const Vec3 n = S.pose.R * p->normal.normalized();
      pose.p = S.pose.apply(p->point) + 0.8 * n + randomVec(rng, 0.5);
    } else {
      const auto& sp = std::get<SphereSurface>(surface);
      const Vec3 C = S.pose.apply(sp.centre);
      // Inside a bowl start slightly beyond contact, so that the body is pressed
      // against the wall (the farthest point is then unique) and shift back.
      const double r = sp.side == SphereSurface::Side::Outside ? sp.radius + 0.5 : sp.radius - 0.15;
      pose.p = C + r * randomUnit(rng);
    }
    ContactGeometry g;
    for (int k = 0; k < 3; ++k) {
      contactGeometry(shape, surface, S, pose, Vec6::Zero(), g, opt);
      if (g.singular) break;
      pose.p += (gap - g.gap) * g.normal;
    }
    if (g.singular) continue;
    contactGeometry(shape, surface, S, pose, Vec6::Zero(), g, opt);
    if (std::abs(g.gap - gap) > 1e-9 || !wellPosed(shape, surface, S, pose, g)) continue;
    return true;
  }
  return false;
}

/// Fourth-order central difference of f at 0 with step h.
template <class F>
auto centralDiff(F&& f, double h) {
  return ((f(-2 * h) - 8 * f(-h) + 8 * f(h) - f(2 * h)) / (12 * h)).eval();
}

inline bool rollsOn(const Shape& s) { return canRoll(s); }
inline bool hasBlade(const Shape& s) {
  return shapeType(s).role == ShapeRole::Point || wheelAxis(s) != nullptr;
}

}  // namespace appell::testing
