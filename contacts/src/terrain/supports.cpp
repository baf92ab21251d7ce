// Prescribed support motions: pose, spatial velocity and acceleration at t.
#include <appell/supports.hpp>
#include <appell/overloaded.hpp>

#include <cmath>
#include <stdexcept>

namespace appell {

namespace {

[[noreturn]] void fail(const Support& s, const std::string& what) {
  throw std::invalid_argument("support '" + s.name + "': " + what);
}

}  // namespace

SE3 twistExp(const Vec6& twist, double t) {
  // A point moves as ẋ = v + Ω × x, so x(t) = exp(tΩ̂) x₀ + p(t) with
  // p(t) = ∫₀ᵗ exp(sΩ̂) v ds = J(θ) v t, θ = Ω t, J the left Jacobian of SO(3):
  // J = 1 + (1 − cos θ)/θ² θ̂ + (θ − sin θ)/θ³ θ̂²  (series below 1e-4).
  const Vec3 theta = twist.head<3>() * t;
  const double a = theta.norm();
  const Mat3 K = skew(theta);
  double c1, c2;
  if (a < 1e-4) {
    c1 = 0.5 - a * a / 24.0;
    c2 = 1.0 / 6.0 - a * a / 120.0;
  } else {
    c1 = (1.0 - std::cos(a)) / (a * a);
    c2 = (a - std::sin(a)) / (a * a * a);
  }
  SE3 T;
  T.R = quatExp(theta).toRotationMatrix();
  T.p = (Mat3::Identity() + c1 * K + c2 * K * K) * (twist.tail<3>() * t);
  return T;
}

SupportState supportState(const SupportMotion& motion, double t) {
  return std::visit(
      Overloaded{[](const StaticMotion& m) {
                   SupportState s;
                   s.pose = m.pose;
                   return s;
                 },
                 [t](const ConstantTwistMotion& m) {
                   // A constant world twist has zero spatial acceleration.
                   SupportState s;
                   s.pose = twistExp(m.twist, t) * m.pose0;
                   s.V = m.twist;
                   return s;
                 },
                 [t](const SinusoidalTiltMotion& m) {
                   // Rotation θ(t) about the fixed world line (axis k through c):
                   // V = θ̇ [k; c × k], A = θ̈ [k; c × k] (k and c fixed).
                   const double arg = m.frequency * t + m.phase;
                   const double th = m.amplitude * std::sin(arg);
                   const double thd = m.amplitude * m.frequency * std::cos(arg);
                   const double thdd = -m.amplitude * m.frequency * m.frequency * std::sin(arg);
                   SE3 rot;
                   rot.R = axisAngle(m.axis, th);
                   rot.p = m.point - rot.R * m.point;
                   const Vec6 unit = spatial(m.axis, m.point.cross(m.axis));
                   SupportState s;
                   s.pose = rot * m.pose0;
                   s.V = thd * unit;
                   s.A = thdd * unit;
                   return s;
                 },
                 [t](const PrescribedMotion& m) { return m.state(t); }},
      motion);
}

bool isMoving(const SupportMotion& motion) { return !std::holds_alternative<StaticMotion>(motion); }

ConstantTwistMotion turntable(const Vec3& centre, const Vec3& axis, double rate, const SE3& pose0) {
  // Rotation about the line through `centre`: v_O = Ω × (O − centre) = centre × Ω.
  const Vec3 w = rate * axis.normalized();
  return {pose0, spatial(w, centre.cross(w))};
}

ConstantTwistMotion conveyor(const Vec3& velocity, const SE3& pose0) {
  return {pose0, spatial(Vec3::Zero(), velocity)};
}

void validateSupport(const Support& support) {
  std::visit(Overloaded{[&](const Plane& p) {
                          if (!p.point.allFinite()) fail(support, "plane point must be finite");
                          if (!p.normal.allFinite() || p.normal.norm() < 1e-12)
                            fail(support, "plane normal must be a finite non-zero vector");
                        },
                        [&](const SphereSurface& s) {
                          if (!s.centre.allFinite()) fail(support, "sphere centre must be finite");
                          if (!std::isfinite(s.radius) || s.radius <= 0)
                            fail(support, "sphere radius must be positive and finite");
                        },
                        [&](const TerrainMesh& t) {
                          try {
                            validateTerrain(t);
                          } catch (const std::invalid_argument& e) {
                            fail(support, e.what());
                          }
                        }},
             support.surface);
  std::visit(Overloaded{[&](const StaticMotion& m) {
                          if (!m.pose.R.allFinite() || !m.pose.p.allFinite())
                            fail(support, "pose must be finite");
                        },
                        [&](const ConstantTwistMotion& m) {
                          if (!m.twist.allFinite()) fail(support, "twist must be finite");
                        },
                        [&](const SinusoidalTiltMotion& m) {
                          if (!m.axis.allFinite() || std::abs(m.axis.norm() - 1.0) > 1e-9)
                            fail(support, "tilt axis must be a finite unit vector");
                          if (!std::isfinite(m.amplitude) || !std::isfinite(m.frequency) ||
                              !std::isfinite(m.phase) || !m.point.allFinite())
                            fail(support, "tilt parameters must be finite");
                        },
                        [&](const PrescribedMotion& m) {
                          if (!m.state) fail(support, "prescribed motion has no callback");
                        }},
             support.motion);
}

}  // namespace appell
