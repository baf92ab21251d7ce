// Contact tangent frames that never switch (docs/contacts.md §3, "Tangent
// frame"): every smooth support takes the frame at its pole z_S carried
// along the great circle to the normal, a smooth function of n everywhere
// but at the antipode. What the tests hold it to:
//   - the frame is orthonormal and right-handed, and its rates are the time
//     derivatives of the frame along a motion (central differences);
//   - it is continuous along a path over a globe, across the 45° latitude
//     where the old frame (the support's x axis, switched to y near n)
//     jumped;
//   - a homogeneous ball launched sliding from the top of a globe gives the
//     same motion — positions, velocities, contact forces, event times — to
//     1e-12 whether launched along x, along y or at 45° between, at
//     tolerance 1e-13 (with the switching frame the launch along x stopped
//     at the switch: "step size fell below h_min");
//   - on a terrain the frame is the same function of n on faces, edges and
//     vertices, so it is continuous where the contact changes piece.
#include "simulation_helpers.hpp"

#include <appell/contact_geometry.hpp>
#include <appell/contacts.hpp>
#include <appell/simulator.hpp>
#include <appell/terrain.hpp>

#include "scene.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace appell;

namespace {

constexpr double kG = 9.81, kMass = 0.5, kRadius = 0.1, kGlobe = 1.0;

Mat3 rotZ(double a) { return Eigen::AngleAxisd(a, Vec3::UnitZ()).toRotationMatrix(); }

/// A homogeneous ball (m, r, I = 2/5 m r²) on top of a globe of radius 1
/// centred 1 m below the origin, its centre moving at v0 along the
/// horizontal direction at angle `heading` from x, without spin.
scenes::BuiltScene ballOnGlobe(double heading, double v0, double mu) {
  ModelBuilder b;
  const double I = 0.4 * kMass * kRadius * kRadius;
  const int body = b.addBody("ball", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(),
                             scenes::principalInertia(kMass, Vec3(I, I, I)), "free");
  scenes::BuiltScene s;
  s.model = b.build();
  s.model.gravity = Vec3(0, 0, -kG);
  ContactSpec spec;
  spec.kind = ContactKind::Rolling;
  spec.body = body;
  spec.shape = Sphere{kRadius, Vec3::Zero()};
  spec.support = Support{SphereSurface{Vec3(0, 0, -kGlobe), kGlobe, SphereSurface::Side::Outside},
                         StaticMotion{}, "globe"};
  spec.mu = mu;
  spec.options.name = "ball";
  s.constraints.push_back(makeContact(spec));
  s.q0 = neutralConfiguration(s.model);
  scenes::setFloatingPose(s.q0, 0, Vec3(0, 0, kRadius), Mat3::Identity());
  s.v0 = scenes::floatingVelocity(Mat3::Identity(), Vec3::Zero(),
                                  v0 * Vec3(std::cos(heading), std::sin(heading), 0));
  return s;
}

struct GlobeRun {
  std::vector<ContactEvent> events;
  std::vector<double> times;
  std::vector<Vec3> centre, velocity, omega, force;  // world, rotated back by −heading
  std::vector<double> lateral_force;                 // friction force across the plane of motion
  double max_latitude = 0;                           // of the contact normal, from the top
};

/// Steps to t_end at rtol = atol = tol, recording the state on a grid of
/// 0.01 s (steps are cut to land on it) in the frame of the launch (rotated
/// back by −heading).
GlobeRun runOnGlobe(double heading, double t_end, double tol) {
  scenes::BuiltScene s = ballOnGlobe(heading, 0.5, 0.05);
  IntegratorOptions io = test::tightIntegrator();
  io.rtol = io.atol = tol;
  Simulator sim(s.model, s.constraints, makeSolver(Formulation::Tree, s.model, s.constraints),
                IntegratorType::DormandPrince54, io);
  EXPECT_TRUE(sim.setState(0, s.q0, s.v0)) << sim.lastStateError();
  const Mat3 back = rotZ(-heading);
  const Vec3 across = Vec3(-std::sin(heading), std::cos(heading), 0);
  GlobeRun run;
  int grid = 1;
  while (sim.time() < t_end - 1e-12) {
    const StepStatus st = sim.step(std::min(0.01, 0.01 * grid - sim.time()));
    EXPECT_TRUE(st.ok) << "launched at " << heading << " rad: " << st.message << " at t = "
                       << sim.time();
    if (!st.ok) break;
    run.events.insert(run.events.end(), sim.events().begin(), sim.events().end());
    if (std::abs(sim.time() - 0.01 * grid) > 1e-12) continue;
    ++grid;
    const Mat3 R = scenes::floatingRotation(sim.q(), 0);
    run.times.push_back(sim.time());
    run.centre.push_back(back * sim.q().head<3>());
    run.velocity.push_back(back * (R * Vec3(sim.v().tail<3>())));
    run.omega.push_back(back * (R * Vec3(sim.v().head<3>())));
    const ContactFrame& f = sim.contactFrame(0);
    const Vec3 force = sim.lambda()[0] * f.t1 + sim.lambda()[1] * f.t2 + sim.lambda()[2] * f.normal;
    run.force.push_back(back * force);
    run.lateral_force.push_back(std::abs(force.dot(across)));
    if (sim.constraintData().isActive(0))
      run.max_latitude = std::max(run.max_latitude, std::acos(std::min(1.0, f.normal.z())));
  }
  return run;
}

/// The frame at the contact of a ball resting on the globe at polar angle θ
/// and azimuth φ (the ball's centre on the globe's radius there).
ContactGeometry frameOnGlobe(const Constraint& c, double theta, double phi, const Vec6& V) {
  const Vec3 dir(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
  SE3 pose;
  pose.p = Vec3(0, 0, -kGlobe) + (kGlobe + kRadius) * dir;
  ContactGeometry g;
  static_cast<const ShapeContact&>(c).geometry(pose, V, 0.0, g);
  return g;
}

}  // namespace

// Protects: the frame is orthonormal, right-handed and differentiable, its
// rates those of the frame along a motion — on a globe, static and carried
// by a support spinning about a tilted axis, from the pole to 3° from the
// antipode (nearer, the frame turns like 1/|p + n| and central differences
// lose their order; the next test covers it).
TEST(ContactFrames, TransportedFrameIsOrthonormalAndItsRatesAreItsDerivatives) {
  const scenes::BuiltScene s = ballOnGlobe(0.0, 0.5, 0.05);
  const auto& contact = static_cast<const ShapeContact&>(*s.constraints[0]);
  ContactSpec spun = contact.spec();
  spun.support.motion = turntable(Vec3(0, 0, -kGlobe), Vec3(0.3, -0.2, 1).normalized(), 1.7);
  const auto spinning = makeContact(spun);
  const Vec6 V = (Vec6() << 0.4, -1.1, 0.7, 0.3, 0.9, -0.5).finished();
  const double h = 1e-6;
  const std::vector<const Constraint*> contacts{s.constraints[0].get(), spinning.get()};
  for (const Constraint* c : contacts) {
    for (const double theta : {0.0, 0.3, M_PI / 4, 1.2, M_PI / 2, 2.5, M_PI - 0.05}) {
      SE3 pose;
      const Vec3 dir(std::sin(theta) * std::cos(0.7), std::sin(theta) * std::sin(0.7),
                     std::cos(theta));
      pose.p = Vec3(0, 0, -kGlobe) + (kGlobe + kRadius) * dir;
      pose.R = Eigen::AngleAxisd(0.4, Vec3(1, 2, 3).normalized()).toRotationMatrix();
      auto at = [&](double t) {
        SE3 p = pose;
        p.p += t * (Vec3(V.tail<3>()) + Vec3(V.head<3>()).cross(pose.p));
        p.R = Eigen::AngleAxisd(t * V.head<3>().norm(), Vec3(V.head<3>()).normalized())
                  .toRotationMatrix() * pose.R;
        ContactGeometry g;
        static_cast<const ShapeContact&>(*c).geometry(p, V, t, g);
        return g;
      };
      const ContactGeometry g = at(0), gp = at(h), gm = at(-h);
      ASSERT_FALSE(g.singular) << g.reason;
      EXPECT_NEAR(g.t1.norm(), 1.0, 1e-14) << theta;
      EXPECT_NEAR(g.t1.dot(g.normal), 0.0, 1e-14) << theta;
      EXPECT_LT((g.t1.cross(g.t2) - g.normal).norm(), 1e-14) << theta;
      EXPECT_LT(((gp.t1 - gm.t1) / (2 * h) - g.t1_rate).norm(), 1e-7 * (1 + g.t1_rate.norm()))
          << "θ = " << theta;
      EXPECT_LT(((gp.t2 - gm.t2) / (2 * h) - g.t2_rate).norm(), 1e-7 * (1 + g.t2_rate.norm()))
          << "θ = " << theta;
    }
  }
}

// Protects: the one singular point. Approaching the antipode (the bottom
// of the globe) the frame stays orthonormal to the round-off of the formula
// (ε/|p + n|); within 1.4 µrad of it, and at it, the frame is the support's
// −y axis on the tangent plane — finite, never NaN.
TEST(ContactFrames, NearAndAtTheAntipodeTheFrameStaysFiniteAndOrthonormal) {
  const scenes::BuiltScene s = ballOnGlobe(0.0, 0.5, 0.05);
  const Vec6 V = (Vec6() << 0.4, -1.1, 0.7, 0.3, 0.9, -0.5).finished();
  for (const double gap : {1e-3, 1e-5, 1e-6, 1e-7, 1e-9, 0.0}) {
    const ContactGeometry g = frameOnGlobe(*s.constraints[0], M_PI - gap, 0.3, V);
    ASSERT_FALSE(g.singular) << g.reason;
    const double tol = 1e-15 * (1 + 1 / std::max(gap, 1e-6));
    EXPECT_NEAR(g.t1.norm(), 1.0, tol) << gap;
    EXPECT_NEAR(g.t1.dot(g.normal), 0.0, tol) << gap;
    EXPECT_LT((g.t1.cross(g.t2) - g.normal).norm(), tol) << gap;
    EXPECT_TRUE(g.t1_rate.allFinite() && g.t2_rate.allFinite()) << gap;
    if (gap < 1.4e-6) {
      EXPECT_LT((g.t1 + Vec3::UnitY()).norm(), 1e-6) << "the fallback, at " << gap;
    }
  }
}

// Protects: no switch along a meridian. Walking the contact from the top
// of the globe down to 80° in steps of 1e-4 rad, the frame turns by less
// than 2e-4 per step in any direction (the old frame turned by 90° at 45°),
// and along a meridian it is parallel-transported: t1, t2 keep their angle
// to the meridian's tangent.
TEST(ContactFrames, FrameIsContinuousAcrossTheOldSwitchLatitude) {
  const scenes::BuiltScene s = ballOnGlobe(0.0, 0.5, 0.05);
  for (const double phi : {0.0, M_PI / 4, M_PI / 2, 2.0}) {
    ContactGeometry prev = frameOnGlobe(*s.constraints[0], 0.0, phi, Vec6::Zero());
    double worst = 0, worst_angle = 0;
    for (double theta = 1e-4; theta < 80 * M_PI / 180; theta += 1e-4) {
      const ContactGeometry g = frameOnGlobe(*s.constraints[0], theta, phi, Vec6::Zero());
      worst = std::max(worst, (g.t1 - prev.t1).norm());
      // The meridian's tangent (towards increasing θ) in the frame.
      const Vec3 tangent(std::cos(theta) * std::cos(phi), std::cos(theta) * std::sin(phi),
                         -std::sin(theta));
      const double angle = std::atan2(g.t2.dot(tangent), g.t1.dot(tangent));
      const double angle0 = phi + M_PI / 2;  // at the pole: t1 = −y, t2 = x
      worst_angle = std::max(worst_angle, std::abs(std::remainder(angle - angle0, 2 * M_PI)));
      prev = g;
    }
    EXPECT_LT(worst, 2e-4) << "azimuth " << phi;
    EXPECT_LT(worst_angle, 1e-13) << "azimuth " << phi;
  }
}

// Protects: the reproducer. A ball launched sliding (0.5 m/s, no
// spin, μ = 0.05) from the top of a globe slides down past 45° and lifts
// off. Launched along x, along y and at 45° between, at tolerance 1e-13, the
// three runs agree, in the launch's own frame, on the centre and its
// velocity, the angular velocity and the contact force to 1e-12, on the
// events and their times to 1e-12, and no friction acts across the plane of
// motion.
TEST(ContactFrames, SlidingBallOnAGlobeDoesNotDependOnItsLaunchDirection) {
  const double t_end = 1.1, tol = 1e-13;
  const GlobeRun x = runOnGlobe(0.0, t_end, tol);
  ASSERT_FALSE(x.events.empty());
  EXPECT_GT(x.max_latitude, M_PI / 4 + 0.05) << "the contact passes the old switch latitude";
  EXPECT_EQ(x.events.back().kind, ContactEventKind::LiftOff);
  for (const double heading : {M_PI / 2, M_PI / 4, -2.2}) {
    const GlobeRun r = runOnGlobe(heading, t_end, tol);
    ASSERT_EQ(r.events.size(), x.events.size()) << heading;
    for (size_t k = 0; k < r.events.size(); ++k) {
      EXPECT_EQ(r.events[k].kind, x.events[k].kind) << heading;
      EXPECT_NEAR(r.events[k].t, x.events[k].t, 1e-12) << heading;
    }
    ASSERT_EQ(r.times.size(), x.times.size()) << heading;
    double worst = 0, worst_force = 0, worst_lateral = 0;
    for (size_t k = 0; k < r.times.size(); ++k) {
      EXPECT_NEAR(r.times[k], x.times[k], 1e-12);
      worst = std::max({worst, (r.centre[k] - x.centre[k]).lpNorm<Eigen::Infinity>(),
                        (r.velocity[k] - x.velocity[k]).lpNorm<Eigen::Infinity>(),
                        (r.omega[k] - x.omega[k]).lpNorm<Eigen::Infinity>()});
      worst_force = std::max(worst_force, (r.force[k] - x.force[k]).lpNorm<Eigen::Infinity>());
      worst_lateral = std::max(worst_lateral, r.lateral_force[k]);
    }
    EXPECT_LT(worst, 1e-12) << "launched at " << heading << " rad";
    EXPECT_LT(worst_force, 1e-12) << "launched at " << heading << " rad";
    EXPECT_LT(worst_lateral, 1e-12) << "launched at " << heading << " rad";
  }
}
