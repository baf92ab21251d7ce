// The problem every engine of the peer comparison solves: a uniform thin disk
// (m = 1 kg, R = 0.5 m, inertia A = mR²/4 about diameters, C = mR²/2 about the
// axle) rolling without slipping on the plane z = 0 under g = 9.81 m/s², for
// 10 s, from one initial state handed to all engines in world coordinates.
//
// State in world coordinates: centre of mass c, rotation R (body z = axle),
// angular velocity ω and centre velocity v_c. Energy, the same formula for
// every engine:
//     E = ½ m |v_c|² + ½ ωᵀ R diag(A, A, C) Rᵀ ω + m g c_z.
//
// The contact. For a rim of radius R whose plane passes through c + e a (a the
// axle, e the offset of the rim's plane along it; e = 0 for a thin disk, e = −h
// for the lower face of a cylinder of half-thickness h), the lowest rim point is
//     P = c + e a − R u,   u = (e_z − a_z a)/√(1 − a_z²)
// (u is the unit in-plane direction closest to the vertical). Rolling without
// slipping asks P_z = 0 (one holonomic row) and that the material point of the
// body at P has zero velocity, v_c + ω × (P − c) = 0 (its vertical component is
// the time derivative of the height row; the horizontal two are nonholonomic).
//
// The disk is a thin disk for appell and Simbody. MuJoCo has no thin disk, so it
// gets a cylinder of half-thickness h = 1 mm with the same inertia; a rigid
// cylinder leaning by θ > 0 rests on the rim of its lower face, i.e. on a disk
// rim offset by e = −h along the axle, which is how its exact reference is
// computed (appell's Disk shape with its centre moved along the axis).
#pragma once

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <string>
#include <vector>

namespace peers {

using V3 = Eigen::Vector3d;
using M3 = Eigen::Matrix3d;

struct DiskState {
  V3 centre = V3::Zero();
  M3 rotation = M3::Identity();
  V3 omega = V3::Zero();     ///< world frame
  V3 velocity = V3::Zero();  ///< of the centre, world frame
};

struct DiskProblem {
  double mass = 1.0, radius = 0.5, gravity = 9.81;
  double half_thickness = 0.0;  ///< h: 0 for the thin disk; the cylinder rests on the face at −h
  double duration = 10.0;
  DiskState initial;
  double A() const { return mass * radius * radius / 4; }
  double C() const { return mass * radius * radius / 2; }
};

inline double energy(const DiskProblem& p, const DiskState& s) {
  const M3 I = s.rotation * V3(p.A(), p.A(), p.C()).asDiagonal() * s.rotation.transpose();
  return 0.5 * p.mass * s.velocity.squaredNorm() + 0.5 * s.omega.dot(I * s.omega) +
         p.mass * p.gravity * s.centre.z();
}

/// Lowest point of a rim of radius R in the plane through c + e a (see the header).
inline V3 lowestRimPoint(const V3& c, const V3& a, double e, double R) {
  const V3 u = (V3::UnitZ() - a.z() * a).normalized();
  return c + e * a - R * u;
}

/// Horizontal speed of the body's material point at the lowest point of a
/// cylinder of half-thickness h (the lower of its two face rims): the slip.
inline double slipSpeed(const DiskProblem& p, const DiskState& s, double* height = nullptr) {
  const V3 a = s.rotation.col(2);
  const V3 P1 = lowestRimPoint(s.centre, a, p.half_thickness, p.radius);
  const V3 P2 = lowestRimPoint(s.centre, a, -p.half_thickness, p.radius);
  const V3 P = P1.z() < P2.z() ? P1 : P2;
  if (height) *height = P.z();
  const V3 vp = s.velocity + s.omega.cross(P - s.centre);
  return std::hypot(vp.x(), vp.y());
}

/// One run of one engine with one setting.
struct PeerRun {
  std::string engine, method;  ///< e.g. "simbody", "merson"
  double setting = 0;          ///< accuracy / tolerance, or step
  double cpu = 0;              ///< CPU seconds for the whole run (median over repeats)
  long steps = 0, evaluations = 0;
  DiskState at1, at10;  ///< states at t = 1 s and t = 10 s
  bool ok = true;
  std::string message;
  // MuJoCo diagnostics (filled by a separate untimed run)
  double max_slip = 0, mean_slip = 0, max_penetration = 0;
};

/// CPU time of this process (s): what every timing of the comparison reports.
inline double cpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/// Median of a sample (copied).
inline double median(std::vector<double> x) {
  if (x.empty()) return 0;
  std::nth_element(x.begin(), x.begin() + x.size() / 2, x.end());
  return x[x.size() / 2];
}

}  // namespace peers
