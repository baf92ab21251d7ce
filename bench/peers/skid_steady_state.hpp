// The skid-steer's steady turn in closed form (up to a 7 × 7 Newton solve):
// the reference report_peers_vehicles checks every engine's yaw rate against.
//
// A planar steady state with all four tyres sliding (Coulomb, one μ): the
// chassis' centre of mass moves at (v_x, v_y) in chassis axes and turns at Ω,
// so its acceleration is a = (−Ω v_y, Ω v_x); wheel i spins at ω_i. Tyre i at
// (x_i, y_i) slips at s_i = (v_x − Ω y_i − r ω_i, v_y + Ω x_i) and carries
// F_i = −μ N_i s_i/|s_i|. Seven equations: Σ F_x = m a_x, Σ F_y = m a_y,
// Σ (x_i F_y,i − y_i F_x,i) = 0 (no yaw acceleration), and per wheel the
// servo balancing the tyre, clamp(kv (ω*_i − ω_i), ±limit) = r F_x,i. The
// normal loads carry the load transfer of the centre of mass' height h over
// the ground: Σ N_i = m g, Σ y_i N_i = −h m a_y, Σ x_i N_i = −h m a_x; four
// loads on three equations are split by the planar (minimum-norm) rule
// N_i = m g/4 − h m a_y y_i/(4 b²) − h m a_x x_i/(4 a²) for wheels at
// (±a, ±b). Neglected: the wheels' gyroscopic moments (ω_i Ω I_yy ≈ 0.3 N·m
// against tyre moments of ≈ 25 N·m) and the wheels' own centripetal loads.
// The skid-steer analyses in Wong, "Theory of Ground Vehicles" (4th ed.,
// 2008, ch. 7) rest on the same balance.
#pragma once

#include "vehicle_problem.hpp"

#include <Eigen/Dense>

namespace peers {

struct SkidSteadyState {
  double vx = 0, vy = 0, yaw_rate = 0;  ///< centre of mass velocity (chassis axes), Ω
  std::array<double, 4> wheel_rate{};
  double residual = 0;                  ///< max |equation| at the solution (N, N·m)
};

inline Eigen::Matrix<double, 7, 1> skidResidual(const VehicleModel& v, double mu, const Eigen::Matrix<double, 7, 1>& u) {
  const double m = v.totalMass(), g = -v.gravity.z(), r = v.wheel_radius;
  const double h = (v.chassis.mass * (r + v.chassis.com.z()) + 4 * v.wheel.mass * r) / m;
  const double a = v.wheel_pos[0].x(), b = v.wheel_pos[0].y();
  const double vx = u[0], vy = u[1], W = u[2], ax = -W * vy, ay = W * vx;
  Eigen::Matrix<double, 7, 1> out = Eigen::Matrix<double, 7, 1>::Zero();
  out[0] = -m * ax;
  out[1] = -m * ay;
  for (int i = 0; i < 4; ++i) {
    const double x = v.wheel_pos[i].x(), y = v.wheel_pos[i].y();
    const double N = m * g / 4 - h * m * ay * y / (4 * b * b) - h * m * ax * x / (4 * a * a);
    const double sx = vx - W * y - r * u[3 + i], sy = vy + W * x, s = std::hypot(sx, sy);
    const double fx = -mu * N * sx / s, fy = -mu * N * sy / s;
    out[0] += fx;
    out[1] += fy;
    out[2] += x * fy - y * fx;
    out[3 + i] = std::clamp(v.servo_kv * (v.setpoint[i] - u[3 + i]), -v.servo_limit, v.servo_limit) - r * fx;
  }
  return out;
}

/// Newton with a finite-difference Jacobian and a backtracking line search,
/// from a turn that slides every tyre (Ω = 1 rad/s, wheels at their set-points).
inline SkidSteadyState skidSteadyState(const VehicleModel& v, double mu) {
  using V7 = Eigen::Matrix<double, 7, 1>;
  V7 u;
  u << v.wheel_radius * (v.setpoint[0] + v.setpoint[1]) / 2, 0, 1, v.setpoint[0], v.setpoint[1], v.setpoint[2],
      v.setpoint[3];
  for (int it = 0; it < 100; ++it) {
    const V7 f = skidResidual(v, mu, u);
    if (f.cwiseAbs().maxCoeff() < 1e-12) break;
    Eigen::Matrix<double, 7, 7> J;
    for (int j = 0; j < 7; ++j) {
      V7 up = u;
      const double d = 1e-7 * std::max(1.0, std::abs(u[j]));
      up[j] += d;
      J.col(j) = (skidResidual(v, mu, up) - f) / d;
    }
    const V7 step = J.partialPivLu().solve(-f);
    double lambda = 1;
    while (lambda > 1e-6 && skidResidual(v, mu, u + lambda * step).cwiseAbs().maxCoeff() >= f.cwiseAbs().maxCoeff())
      lambda /= 2;
    u += lambda * step;
  }
  SkidSteadyState s;
  s.vx = u[0];
  s.vy = u[1];
  s.yaw_rate = u[2];
  for (int i = 0; i < 4; ++i) s.wheel_rate[i] = u[3 + i];
  s.residual = skidResidual(v, mu, u).cwiseAbs().maxCoeff();
  return s;
}

}  // namespace peers
