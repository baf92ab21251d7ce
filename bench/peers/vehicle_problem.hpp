// The two vehicle scenes report_peers_vehicles runs in every engine, as plain
// numbers (the peers build their own models from them), and what a run of
// each reports. The numbers are those of the appell scene files:
//
//   skid-steer   examples/skid_steer_step/skid_steer_step.urdf — 57 kg, four
//                fixed wheels on velocity servos (kv 10 N·m·s, ±20 N·m), a
//                step command (left 2 rad/s, right 10 rad/s at t = 0), tyres
//                μₛ 0.8 / μₖ 0.7, 10 s on flat ground;
//   parked car   examples/car/car.urdf with its wheels locked (fixed joints,
//                the brakes), at rest on a 10° slope (gravity tilted so that
//                downhill is +x), tyres μₛ 0.9 / μₖ 0.7, 60 s — the scene of
//                tests/test_friction_vehicles.cpp's
//                BrakedCarParkedOnASlopeDoesNotCreep.
//
// report_peers_vehicles checks these numbers against the loaded appell
// scenes (total mass, wheel positions) before it runs anything.
#pragma once

#include "disk_problem.hpp"  // V3, cpuSeconds, median

#include <array>
#include <limits>
#include <string>
#include <vector>

namespace peers {

/// A rigid link: mass, centre of mass and principal moments in its frame
/// (all the scenes' inertias are diagonal in their link frames).
struct LinkInertia {
  double mass = 0;
  V3 com = V3::Zero();
  V3 diag = V3::Zero();
};

/// A chassis on four wheels whose axles are the chassis y axis; the link
/// origin is at axle height, wheel i's centre at wheel_pos[i] (FL, FR, RL, RR).
struct VehicleModel {
  LinkInertia chassis, wheel;
  std::array<V3, 4> wheel_pos;
  double wheel_radius = 0, wheel_width = 0;
  double mu_static = 0, mu_kinetic = 0;
  V3 gravity = V3(0, 0, -9.81);
  double duration = 0;
  bool wheels_locked = false;            ///< the parked car: no wheel joints
  double servo_kv = 0, servo_limit = 0;  ///< τ = clamp(kv (ω* − ω), ±limit)
  std::array<double, 4> setpoint{};      ///< ω* per wheel (rad/s), from t = 0
  double totalMass() const { return chassis.mass + 4 * wheel.mass; }
};

inline VehicleModel skidSteerStep() {
  VehicleModel v;
  v.chassis = {46.6, V3(0, 0, 0.1), V3(1.640708, 3.388208, 4.543500)};
  v.wheel = {2.6, V3::Zero(), V3(0.0203179166667, 0.0353925, 0.0203179166667)};
  v.wheel_pos = {V3(0.256, 0.285, 0), V3(0.256, -0.285, 0), V3(-0.256, 0.285, 0), V3(-0.256, -0.285, 0)};
  v.wheel_radius = 0.165;
  v.wheel_width = 0.11;
  v.mu_static = 0.8;
  v.mu_kinetic = 0.7;
  v.duration = 10;
  v.servo_kv = 10;
  v.servo_limit = 20;
  v.setpoint = {2, 10, 2, 10};
  return v;
}

inline VehicleModel parkedCar(double slope_rad) {
  VehicleModel v;
  v.chassis = {20, V3(0.1, 0, 0.1), V3(0.666666666666667, 1.73333333333333, 2.26666666666667)};
  v.wheel = {1, V3::Zero(), V3(0.005925, 0.01125, 0.005925)};
  v.wheel_pos = {V3(0.4, 0.35, 0), V3(0.4, -0.35, 0), V3(-0.4, 0.35, 0), V3(-0.4, -0.35, 0)};
  v.wheel_radius = 0.15;
  v.wheel_width = 0.06;
  v.mu_static = 0.9;
  v.mu_kinetic = 0.7;
  v.gravity = V3(9.81 * std::sin(slope_rad), 0, -9.81 * std::cos(slope_rad));
  v.duration = 60;
  v.wheels_locked = true;
  return v;
}

/// The chassis link's state at one time: origin, rotation, the world
/// velocity of the link origin and the world angular velocity.
struct ChassisSample {
  double t = 0;
  V3 origin = V3::Zero();
  M3 rotation = M3::Identity();
  V3 velocity = V3::Zero();
  V3 omega = V3::Zero();
  std::array<double, 4> wheel_rate{};  ///< wheel joint rates (rad/s), FL FR RL RR; 0 when locked
  /// Soft-contact engines: tyres in contact, and the largest angle (rad)
  /// between a sliding tyre's friction force and its slip's opposite
  /// (Coulomb's law: 0); −1 / NaN where not measured.
  int contacts = -1;
  double friction_angle = std::numeric_limits<double>::quiet_NaN();
  /// Velocity of the link origin along the chassis' x axis (forward) and y.
  double forward() const { return velocity.dot(rotation.col(0)); }
  double lateral() const { return velocity.dot(rotation.col(1)); }
};

/// One run of one engine: its CPU time for the whole simulated duration
/// (sampling excluded), the chassis at the sample times, and engine notes.
struct VehicleRun {
  std::string engine, setting;
  double cpu = 0;
  long steps = 0;
  std::vector<ChassisSample> samples;
  double max_penetration = 0;  ///< soft contacts: max −dist over the samples
  bool ok = false;
  std::string message;
};

}  // namespace peers
