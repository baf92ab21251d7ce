// Supports: the surfaces bodies roll or slide on, and their prescribed motion.
//
// A support is a surface given in a support frame S, plus the motion of S in
// the world: pose S(t), world-frame spatial velocity V_S = [Ω; v_O] and its
// time derivative A_S = dV_S/dt (the spatial acceleration, Featherstone's
// convention as in spatial.hpp). The material velocity of the support at a
// world point x is   V_S(x, t) = v_O + Ω × x,  and along a moving point x(t)
//   d/dt V_S(x(t), t) = A_lin + A_ang × x + Ω × ẋ.
#pragma once

#include <appell/spatial.hpp>
#include <appell/terrain.hpp>

#include <functional>
#include <string>
#include <variant>

namespace appell {

/// Plane through `point` with unit `normal` (support frame); bodies stay on the
/// side the normal points to.
struct Plane {
  Vec3 point = Vec3::Zero();
  Vec3 normal = Vec3::UnitZ();
};

/// Sphere of `radius` about `centre` (support frame). Outside: bodies roll on
/// the outer face (a ball on a globe). Inside: bodies roll in a bowl.
struct SphereSurface {
  enum class Side { Outside, Inside };
  Vec3 centre = Vec3::Zero();
  double radius = 0;
  Side side = Side::Inside;
};

/// TerrainMesh: a triangle mesh, piecewise planar (terrain.hpp).
using SupportSurface = std::variant<Plane, SphereSurface, TerrainMesh>;

/// Pose, velocity and acceleration of the support frame at one instant (world).
struct SupportState {
  SE3 pose;                    ///< support frame in the world
  Vec6 V = Vec6::Zero();       ///< [Ω; v_O], world frame
  Vec6 A = Vec6::Zero();       ///< dV/dt, world frame
  /// Material velocity of the support at world point x.
  Vec3 pointVelocity(const Vec3& x) const { return V.tail<3>() + V.head<3>().cross(x); }
};

/// The support frame does not move.
struct StaticMotion {
  SE3 pose;
};

/// Constant world-frame twist V = [Ω; v_O]: pose(t) = exp(t V) · pose0.
/// A turntable (rate Ω about an axis through a point) and a conveyor
/// (translation along the plane) are the everyday cases; see turntable()/conveyor().
struct ConstantTwistMotion {
  SE3 pose0;
  Vec6 twist = Vec6::Zero();
};

/// Tilting about a world axis through a world point: the angle is
/// θ(t) = amplitude · sin(frequency · t + phase), pose(t) = Rot(axis, point, θ) · pose0.
struct SinusoidalTiltMotion {
  SE3 pose0;
  Vec3 point = Vec3::Zero();
  Vec3 axis = Vec3::UnitX();
  double amplitude = 0;
  double frequency = 0;  ///< rad/s
  double phase = 0;
};

/// User-prescribed motion: pose, V and A = dV/dt at time t, consistent with
/// one another (the contact rows trust them; a test of yours should check).
struct PrescribedMotion {
  std::function<SupportState(double t)> state;
};

using SupportMotion =
    std::variant<StaticMotion, ConstantTwistMotion, SinusoidalTiltMotion, PrescribedMotion>;

struct Support {
  SupportSurface surface;
  SupportMotion motion = StaticMotion{};
  std::string name = "ground";
  /// −1: the support belongs to the world and moves as `motion` says.
  /// ≥ 0: the support is fixed on that body (a cart, a rotor); `motion` must be
  /// a StaticMotion whose pose places the support frame in the body's frame.
  /// Rows then act on two bodies (Wa on the contact body, Wb on this one).
  int body = -1;
};

/// State of the support frame at time t. No allocation (a PrescribedMotion
/// callback is the user's business).
SupportState supportState(const SupportMotion& motion, double t);

/// True unless the motion is static.
bool isMoving(const SupportMotion& motion);

/// Turntable: rotation at `rate` (rad/s) about the world axis through `centre`.
ConstantTwistMotion turntable(const Vec3& centre, const Vec3& axis, double rate,
                              const SE3& pose0 = SE3::Identity());
/// Conveyor: translation at `velocity` (world).
ConstantTwistMotion conveyor(const Vec3& velocity, const SE3& pose0 = SE3::Identity());

/// exp of a world twist [Ω; v_O] held for time t: the rigid motion it generates.
SE3 twistExp(const Vec6& twist, double t);

/// Throws std::invalid_argument naming the support and the bad parameter
/// (zero normal, non-positive radius, zero tilt axis, empty callback, …).
void validateSupport(const Support& support);

}  // namespace appell
