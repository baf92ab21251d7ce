// Joint actuators: servos that turn a set-point schedule into joint forces.
//
// A servo on a one-degree-of-freedom joint (revolute, continuous, prismatic)
// with position q and rate q̇ applies the generalized force
//     position servo:  τ = k_p (q*(t) − q) + k_v (q̇*(t) − q̇)
//     velocity servo:  τ = k_v (q̇*(t) − q̇)
// saturated at the joint's effort limit, |τ| ≤ τ_max (URDF <limit effort>,
// or the actuator's own) — MuJoCo's <position kp kv> and <velocity kv>
// actuators, and the effort-limited joint controllers of ros2_control. The
// set-point is piecewise linear in time (held before the first and after the
// last point); a position servo's rate set-point q̇* is the schedule's slope,
// so a ramp is tracked without lag. Joint forces from actuators add to the
// constant ones; nothing here allocates (Simulator::setJointForces calls it
// inside every stage).
#pragma once

#include <appell/model.hpp>

#include <limits>
#include <string>
#include <vector>

namespace appell {

/// A piecewise-linear function of time through (t_k, value_k), t strictly
/// increasing; constant before the first and after the last point.
struct Schedule {
  std::vector<double> t, value;

  /// Throws std::invalid_argument when empty, of unequal sizes, not finite,
  /// or with times not strictly increasing (naming the point).
  void validate() const;
  double at(double time) const;
  /// d/dt of at() (0 outside the points' span; at a kink, the slope ahead).
  double rate(double time) const;
};

enum class ActuatorType { Position, Velocity };
const char* toString(ActuatorType type);

struct Actuator {
  std::string name;
  int joint = -1;                   ///< a revolute, continuous or prismatic joint
  ActuatorType type = ActuatorType::Velocity;
  double kp = 0, kv = 0;            ///< N·m/rad (N/m) and N·m·s/rad (N·s/m)
  double effort_limit = std::numeric_limits<double>::infinity();  ///< |τ| ≤ this
  Schedule setpoint;                ///< q* (position) or q̇* (velocity) against t

  /// Throws std::invalid_argument naming the actuator: an unknown or
  /// multi-degree-of-freedom joint, negative or non-finite gains, a servo
  /// with no gain that acts, an effort limit ≤ 0, a bad schedule.
  void validate(const Model& model) const;
  /// The force at time t for the joint's position q and rate q̇, before
  /// saturation (demand) and after it (force).
  double demand(double t, double q, double qdot) const;
  double force(double t, double q, double qdot) const;
};

/// τ += the force of every actuator at (t, q, v).
void applyActuators(const Model& model, const std::vector<Actuator>& actuators, double t,
                    const VecX& q, const VecX& v, VecX& tau);

}  // namespace appell
