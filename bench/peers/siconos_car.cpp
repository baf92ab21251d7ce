// Siconos 4.4 (Debian libsiconos-kernel-dev) model of the parked car
// (vehicle_problem.hpp), stepped by Siconos' own Moreau–Jean scheme.
//
// With its wheels locked the car is one rigid body: a NewtonEulerDS of the
// composite mass and inertia about the composite centre of mass (chassis and
// four wheels, parallel-axis theorem; the products of inertia that the
// chassis' raised centre of mass brings are kept). Each tyre is one
// unilateral frictional contact (NewtonImpactFrictionNSL, restitution 0,
// μ = the scene's static μ, three rows: normal and two tangents) through a
// NewtonEuler3DR relation whose computeh places the contact, as the relation
// interface asks (the relation's documentation: set pc1, pc2, nc and y): the
// lowest point of a sphere of the wheel radius about the wheel centre, the
// point below it on the ground plane z = 0, the normal e_z and the gap. That
// is the contact of appell's torus tyre and of MuJoCo's sphere wheel.
//
// Time-stepping: TimeStepping + MoreauJeanOSI (θ, Jean 1999; Acary &
// Brogliato 2008, ch. 10) with a FrictionContact(3) one-step problem solved
// by Siconos Numerics' NSGS (non-smooth Gauss–Seidel over the contacts'
// Coulomb cones) to a stated tolerance — the published scheme appell's
// time-stepping window follows (docs/contacts.md §10), in an independent
// implementation.
#include "siconos_car.hpp"
#include "siconos_tyre.hpp"

#include <siconos/numerics/SolverOptions.h>

#include <Eigen/Geometry>

#include <cmath>
#include <stdexcept>

namespace peers {
namespace {

/// Composite body of the locked car: mass, centre of mass in the link frame,
/// inertia about it in link axes.
struct Composite {
  double mass = 0;
  V3 com = V3::Zero();
  M3 inertia = M3::Zero();
};

M3 shifted(const LinkInertia& l, const V3& d) {
  return M3(l.diag.asDiagonal()) + l.mass * (d.squaredNorm() * M3::Identity() - d * d.transpose());
}

Composite composite(const VehicleModel& v) {
  Composite c;
  c.mass = v.totalMass();
  c.com = v.chassis.mass * v.chassis.com;
  for (const V3& w : v.wheel_pos) c.com += v.wheel.mass * (w + v.wheel.com);
  c.com /= c.mass;
  c.inertia = shifted(v.chassis, v.chassis.com - c.com);
  for (const V3& w : v.wheel_pos) c.inertia += shifted(v.wheel, w + v.wheel.com - c.com);
  return c;
}

}  // namespace

VehicleRun runSiconosCar(const VehicleModel& v, const SiconosSettings& s, const std::vector<double>& sample_times) {
  if (!v.wheels_locked) throw std::invalid_argument("siconos: only the parked car (locked wheels) is modelled");
  const Composite c = composite(v);
  auto q0 = std::make_shared<SiconosVector>(7);
  auto v0 = std::make_shared<SiconosVector>(6);
  q0->zero();
  v0->zero();
  const V3 origin0(0, 0, v.wheel_radius);  // link origin at axle height: tyres just touching
  for (int k = 0; k < 3; ++k) (*q0)(k) = origin0[k] + c.com[k];
  (*q0)(3) = 1.0;
  auto inertia = std::make_shared<SimpleMatrix>(3, 3);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) (*inertia)(i, j) = c.inertia(i, j);
  auto body = std::make_shared<NewtonEulerDS>(q0, v0, c.mass, inertia);
  auto weight = std::make_shared<SiconosVector>(3);
  for (int k = 0; k < 3; ++k) (*weight)(k) = c.mass * v.gravity[k];
  body->setFExtPtr(weight);

  auto nsds = std::make_shared<NonSmoothDynamicalSystem>(0.0, v.duration);
  nsds->insertDynamicalSystem(body);
  auto law = std::make_shared<NewtonImpactFrictionNSL>(0.0, 0.0, v.mu_static, 3);
  for (const V3& w : v.wheel_pos) {
    auto tyre = std::make_shared<TyreOnGround>(w + v.wheel.com - c.com, v.wheel_radius);
    nsds->link(std::make_shared<Interaction>(law, tyre), body);
  }
  auto td = std::make_shared<TimeDiscretisation>(0.0, s.h);
  auto osi = std::make_shared<MoreauJeanOSI>(s.theta);
  auto problem = std::make_shared<FrictionContact>(3, SICONOS_FRICTION_3D_NSGS);
  problem->numericsSolverOptions()->dparam[SICONOS_DPARAM_TOL] = s.tolerance;
  problem->numericsSolverOptions()->iparam[SICONOS_IPARAM_MAX_ITER] = s.max_iterations;
  auto sim = std::make_shared<TimeStepping>(nsds, td, osi, problem);
  sim->setNewtonTolerance(s.newton_tolerance);
  sim->setNewtonMaxIteration(s.newton_iterations);

  auto sample = [&](double t) {
    ChassisSample cs;
    cs.t = t;
    const SiconosVector& q = *body->q();
    const SiconosVector& tw = *body->twist();
    const V3 x(q(0), q(1), q(2));
    cs.rotation = Eigen::Quaterniond(q(3), q(4), q(5), q(6)).normalized().toRotationMatrix();
    cs.omega = cs.rotation * V3(tw(3), tw(4), tw(5));  // the twist's angular part is in body axes
    cs.origin = x - cs.rotation * c.com;
    cs.velocity = V3(tw(0), tw(1), tw(2)) + cs.omega.cross(cs.origin - x);
    return cs;
  };
  VehicleRun r;
  r.engine = "siconos";
  r.setting = s.name;
  r.samples.push_back(sample(0));
  const long n = std::lround(v.duration / s.h);
  size_t next = 0;
  double paused = 0;
  const double t0 = cpuSeconds();
  for (long i = 1; i <= n; ++i) {
    sim->computeOneStep();
    sim->nextStep();
    const double t = i * s.h;
    if (next < sample_times.size() && t >= sample_times[next] - 0.5 * s.h) {
      const double tp = cpuSeconds();
      r.samples.push_back(sample(t));
      ++next;
      paused += cpuSeconds() - tp;
    }
  }
  r.cpu = cpuSeconds() - t0 - paused;
  r.steps = n;
  r.ok = std::isfinite(r.samples.back().origin.norm());
  if (!r.ok) r.message = "non-finite state";
  return r;
}

}  // namespace peers
