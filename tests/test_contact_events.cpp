// Unilateral contacts: touchdown, impacts, bouncing and lift-off as events
// (contact_events.hpp), against closed-form motions of a ball.
#include <gtest/gtest.h>

#include <appell/run.hpp>
#include <appell/simulator.hpp>
#include <appell/urdf.hpp>

#include "ball.hpp"
#include "simulation_helpers.hpp"

#include <algorithm>
#include <cmath>
#include <set>

using namespace appell;
using namespace appell::scenes;

namespace {

constexpr double kG = 9.81;


/// A ball of radius r whose centre starts h above its resting height, with
/// the given world angular velocity and horizontal centre velocity.
BuiltScene raisedBall(double h, const Vec3& omega, const Vec3& vG, double restitution) {
  BallParams p;
  p.omega = omega;
  BuiltScene s = ball(p);
  const auto& c = static_cast<const ShapeContact&>(*s.constraints[0]);
  ContactSpec spec = c.spec();
  spec.restitution = restitution;
  s.constraints[0] = makeContact(spec);
  setFloatingPose(s.q0, 0, Vec3(p.centre.x(), p.centre.y(), p.radius + h), Mat3::Identity());
  s.v0 = floatingVelocity(Mat3::Identity(), omega, vG);
  return s;
}


double centreHeight(const Simulator& sim) { return sim.q()[2]; }

}  // namespace

// Protects: touchdown located in time (event function = gap, root found on
// the dense output — DOP853's after its three extra stages — or on shortened
// steps) for every formulation and integrator; a plastic impact
// leaves the ball at rest on the plane.
TEST(ContactEvents, DroppedBallTouchesDownAtTheFreeFallTime) {
  const double h = 0.2;
  const double t_star = std::sqrt(2 * h / kG);
  for (IntegratorType it : {IntegratorType::DormandPrince54, IntegratorType::DormandPrince853,
                            IntegratorType::RK4}) {
    for (Formulation f : {Formulation::Tree, Formulation::Multipliers, Formulation::Appell}) {
      BuiltScene s = raisedBall(h, Vec3::Zero(), Vec3::Zero(), 0.0);
      Simulator sim(s.model, s.constraints, makeSolver(f, s.model, s.constraints), it, appell::test::tightIntegrator());
      ASSERT_TRUE(sim.setState(0, s.q0, s.v0)) << sim.lastStateError();
      EXPECT_FALSE(sim.isClosed(0)) << "a ball above the plane starts with its contact open";
      const auto events = appell::test::advanceCollecting(sim, 0.4, 1e-2);
      ASSERT_EQ(events.size(), 1u) << toString(f) << " " << toString(it);
      EXPECT_EQ(events[0].kind, ContactEventKind::Touchdown);
      EXPECT_NEAR(events[0].t, t_star, 1e-10) << toString(f) << " " << toString(it);
      EXPECT_NEAR(events[0].speed_before, -kG * t_star, 1e-8);
      // Plastic: the impulse takes the momentum m v.
      EXPECT_NEAR(events[0].normal_impulse, 0.5 * kG * t_star, 1e-8);
      EXPECT_TRUE(sim.isClosed(0));
      EXPECT_NEAR(centreHeight(sim), 0.1, 1e-12);
      EXPECT_LT(sim.v().norm(), 1e-10);
      EXPECT_NEAR(sim.lambda()[2], 0.5 * kG, 1e-9) << "at rest the normal force carries the weight";
    }
  }
}

// Protects: the rolling impact. With the no-slip rows closed by the impact,
// the impulse acts at the contact point P, so the angular momentum about P
// is conserved: (I + m r²) ω'ₕ = I ωₕ + m r e_z × vₕ, ω'_z = ω_z.
TEST(ContactEvents, PlasticRollingImpactConservesAngularMomentumAboutTheContactPoint) {
  const double m = 0.5, r = 0.1, I = 0.4 * m * r * r;
  const Vec3 omega(1.5, -4.0, 2.0), vG(0.7, 0.2, 0.0);
  for (Formulation f : {Formulation::Tree, Formulation::Multipliers, Formulation::Appell}) {
    BuiltScene s = raisedBall(0.05, omega, vG, 0.0);
    Simulator sim(s.model, s.constraints, makeSolver(f, s.model, s.constraints),
                  IntegratorType::DormandPrince54, appell::test::tightIntegrator());
    ASSERT_TRUE(sim.setState(0, s.q0, s.v0));
    const auto events = appell::test::advanceCollecting(sim, 0.2, 1e-2);
    ASSERT_GE(events.size(), 1u);
    ASSERT_EQ(events[0].kind, ContactEventKind::Touchdown);
    // Flight: ω and the horizontal velocity are constant; the impact's
    // horizontal effect follows from L_P.
    const Vec3 Lh = I * Vec3(omega.x(), omega.y(), 0) + m * r * Vec3::UnitZ().cross(vG);
    const Vec3 w_after(Lh.x() / (I + m * r * r), Lh.y() / (I + m * r * r), omega.z());
    const Vec3 v_after = r * w_after.cross(Vec3::UnitZ());
    // After the impact the ball rolls on a fixed plane: ω and v_G constant.
    const Mat3 R = floatingRotation(sim.q(), 0);
    const Vec3 w_now = R * Vec3(sim.v().head<3>()), v_now = R * Vec3(sim.v().tail<3>());
    EXPECT_LT((w_now - w_after).norm(), 1e-9) << toString(f);
    EXPECT_LT((v_now - v_after).norm(), 1e-9) << toString(f);
  }
}

// Protects: Newton restitution and the end of a bouncing sequence. Impact
// speeds fall as eᵏ√(2gh), impacts happen at t₁ = √(2h/g),
// t_{k+1} = t_k + 2eᵏ√(2h/g), flights conserve energy, and below rest_speed
// the contact closes plastically: finitely many events, the ball at rest.
TEST(ContactEvents, BouncingBallApexesDecayAsRestitutionSquaredAndTheSequenceEnds) {
  const double h = 0.3, e = 0.5;
  const double v1 = std::sqrt(2 * kG * h);
  for (Formulation f : {Formulation::Tree, Formulation::Multipliers}) {
    BuiltScene s = raisedBall(h, Vec3::Zero(), Vec3::Zero(), e);
    SimulatorOptions so;
    so.contacts.rest_speed = 0.05;
    Simulator sim(s.model, s.constraints, makeSolver(f, s.model, s.constraints),
                  IntegratorType::DormandPrince54, appell::test::tightIntegrator(), so);
    ASSERT_TRUE(sim.setState(0, s.q0, s.v0));
    const double E_rest = 0.5 * kG * 0.1;  // m g r: resting on the plane
    const double E0 = sim.energy() - E_rest;
    std::vector<ContactEvent> events;
    double apex = 0;
    std::vector<double> apexes;
    while (sim.time() < 3.0) {
      const StepStatus st = sim.step(2e-3);
      ASSERT_TRUE(st.ok) << st.message;
      apex = std::max(apex, centreHeight(sim) - 0.1);
      for (const auto& ev : sim.events()) {
        if (!events.empty()) apexes.push_back(apex);
        apex = 0;
        events.push_back(ev);
      }
      if (!sim.isClosed(0) && events.size() < 3) {
        EXPECT_NEAR(sim.energy() - E_rest, E0 * std::pow(e * e, events.size()), 1e-9 * E0);
      }
    }
    // Bounces while eᵏ v₁ ≥ rest_speed, then one plastic touchdown.
    int bounces = 0;
    while (std::pow(e, bounces) * v1 >= so.contacts.rest_speed) ++bounces;
    ASSERT_EQ(static_cast<int>(events.size()), bounces + 1) << toString(f);
    double t = std::sqrt(2 * h / kG);
    for (int k = 0; k < bounces; ++k) {
      EXPECT_EQ(events[k].kind, ContactEventKind::Bounce);
      EXPECT_NEAR(events[k].t, t, 1e-9) << "impact " << k;
      EXPECT_NEAR(-events[k].speed_before, std::pow(e, k) * v1, 1e-8) << "impact " << k;
      EXPECT_NEAR(events[k].speed_after, std::pow(e, k + 1) * v1, 1e-8) << "impact " << k;
      t += 2 * std::pow(e, k + 1) * v1 / kG;
    }
    EXPECT_EQ(events.back().kind, ContactEventKind::Touchdown);
    for (int k = 0; k + 1 < static_cast<int>(apexes.size()) && k < 3; ++k)
      EXPECT_NEAR(apexes[k], h * std::pow(e, 2 * (k + 1)), 2e-3 * h) << "apex " << k;
    EXPECT_TRUE(sim.isClosed(0));
    EXPECT_LT(sim.v().norm(), 1e-10);
  }
}

// Protects: lift-off located where λₙ crosses zero. A resting ball pulled up
// by F(t) = k t leaves the plane at t* = m g / k, then rises as
// z − r = k (t − t*)³ / (6 m).
TEST(ContactEvents, BallPulledUpLiftsOffWhenTheNormalForceVanishes) {
  const double m = 0.5, k = 2.0;
  const double t_star = m * kG / k;
  for (Formulation f : {Formulation::Tree, Formulation::Multipliers, Formulation::Appell}) {
    for (IntegratorType it : {IntegratorType::DormandPrince54, IntegratorType::DormandPrince853,
                              IntegratorType::RK4}) {
      BuiltScene s = raisedBall(0.0, Vec3(0, 3.0, 0), Vec3(0.3, 0, 0), 0.0);
      Simulator sim(s.model, s.constraints, makeSolver(f, s.model, s.constraints), it, appell::test::tightIntegrator());
      sim.setJointForces([&](double t, const VecX& q, const VecX&, VecX& tau) {
        tau.tail<3>() = floatingRotation(q, 0).transpose() * Vec3(0, 0, k * t);
      });
      ASSERT_TRUE(sim.setState(0, s.q0, s.v0));
      EXPECT_TRUE(sim.isClosed(0));
      const auto events = appell::test::advanceCollecting(sim, t_star + 0.5, 1e-2);
      ASSERT_EQ(events.size(), 1u) << toString(f) << " " << toString(it);
      EXPECT_EQ(events[0].kind, ContactEventKind::LiftOff);
      EXPECT_NEAR(events[0].t, t_star, 1e-10) << toString(f) << " " << toString(it);
      EXPECT_FALSE(sim.isClosed(0));
      EXPECT_NEAR(centreHeight(sim) - 0.1, k * std::pow(0.5, 3) / (6 * m), 1e-9);
    }
  }
}

// Protects: the active set reaches every formulation the same way. For each
// of the 16 open/closed combinations of the car's four tyres (an open tyre
// writes zero rows), the tree solver and the dense KKT give the same v̇ and
// the same minimum-norm λ, with λ = 0 on the open rows.
TEST(ContactEvents, TreeAndKktAgreeAtEveryActiveSetOfTheCar) {
  Scene scene = loadScene(std::string(APPELL_SOURCE_DIR) + "/examples/car/car.urdf");
  const Model& model = scene.model;
  ASSERT_EQ(scene.constraints.size(), 4u);
  auto tree = makeSolver(Formulation::Tree, model, scene.constraints);
  auto kkt = makeSolver(Formulation::Multipliers, model, scene.constraints);
  Data data(model);
  ConstraintData cd(model, scene.constraints);
  VecX tau = VecX::Zero(model.nv);
  for (int i = 6; i < model.nv; ++i) tau[i] = 0.3 * std::sin(1.0 + i);  // the wheels and steering driven
  const VecX& v = scene.v0;  // on the rolling manifold: redundant rows stay consistent
  for (int set = 0; set < 16; ++set) {
    for (int c = 0; c < 4; ++c) cd.setActive(c, (set >> c) & 1);
    ConstrainedResult rt, rk;
    evaluateConstraintRows(model, data, scene.constraints, cd, 0, scene.q0, v);
    tree->solve(model, data, scene.constraints, cd, scene.q0, v, tau, rt);
    evaluateConstraintRows(model, data, scene.constraints, cd, 0, scene.q0, v);
    kkt->solve(model, data, scene.constraints, cd, scene.q0, v, tau, rk);
    ASSERT_TRUE(rt.ok && rk.ok) << rt.error << rk.error;
    EXPECT_LT((rt.vdot - rk.vdot).lpNorm<Eigen::Infinity>(), 1e-9 * (1 + rk.vdot.norm())) << "set " << set;
    EXPECT_LT((rt.lambda - rk.lambda).lpNorm<Eigen::Infinity>(), 1e-8 * (1 + rk.lambda.norm())) << "set " << set;
    EXPECT_EQ(rt.redundant, rk.redundant) << "set " << set;
    for (int c = 0; c < 4; ++c) {
      if (cd.isActive(c)) continue;
      for (int r = 0; r < scene.constraints[c]->rows(); ++r)
        EXPECT_EQ(rt.lambda[cd.offset[c] + r], 0.0) << "open tyre " << c;
    }
  }
  EXPECT_EQ(cd.m_active, cd.m);
}

// Protects: contacts that change together are decided together. Each step of
// the rimless wheel (examples/rimless_wheel) lands a pair of feet while the
// trailing pair lifts off in the same impact problem; angular momentum about
// the new contact line is conserved, so with G − Pᵢ = (±l sin α, l cos α + ρ)
// in the plane of the wheel,
//     ω⁺/ω⁻ = (I + m (G−P₂)·(G−P₁)) / (I + m |G−P₂|²),
// and the kinetic energy of the rolling stance drops by that ratio squared.
TEST(ContactEvents, RimlessWheelLandsAndLiftsFeetPairwiseWithTheImpactLaw) {
  Scene scene = loadScene(std::string(APPELL_SOURCE_DIR) + "/examples/rimless_wheel/rimless_wheel.urdf");
  const double m = 2, I = 0.1, l = 0.4, rho = 0.02, alpha = M_PI / 8;
  const double d12 = -std::pow(l * std::sin(alpha), 2) + std::pow(l * std::cos(alpha) + rho, 2);
  const double d22 = std::pow(l * std::sin(alpha), 2) + std::pow(l * std::cos(alpha) + rho, 2);
  const double ratio = (I + m * d12) / (I + m * d22);
  for (Formulation f : {Formulation::Tree, Formulation::Multipliers}) {
    Simulator sim(scene.model, scene.constraints, makeSolver(f, scene.model, scene.constraints),
                  IntegratorType::DormandPrince54, appell::test::tightIntegrator());
    ASSERT_TRUE(sim.setState(0, scene.q0, scene.v0)) << sim.lastStateError();
    int closed = 0;
    for (int c = 0; c < 16; ++c) closed += sim.isClosed(c) ? 1 : 0;
    EXPECT_EQ(closed, 2) << "one pair of feet in stance";
    int impacts = 0;
    double loss = 0;
    while (sim.time() < 3.0) {
      const StepStatus st = sim.step(1e-2);
      ASSERT_TRUE(st.ok) << st.message;
      const double dloss = sim.impactEnergyLoss() - loss;
      loss = sim.impactEnergyLoss();
      if (sim.events().empty()) continue;
      ++impacts;
      ASSERT_EQ(sim.events().size(), 4u) << "two touchdowns and two lift-offs at t = " << sim.time();
      int down = 0, up = 0;
      for (const ContactEvent& e : sim.events()) {
        EXPECT_EQ(e.t, sim.time());
        down += e.kind == ContactEventKind::Touchdown;
        up += e.kind == ContactEventKind::LiftOff;
      }
      EXPECT_EQ(down, 2);
      EXPECT_EQ(up, 2);
      const double T_after = sim.kineticEnergy();
      EXPECT_NEAR(T_after / (T_after + dloss), ratio * ratio, 1e-9) << "impact at t = " << sim.time();
      closed = 0;
      for (int c = 0; c < 16; ++c) closed += sim.isClosed(c) ? 1 : 0;
      EXPECT_EQ(closed, 2);
    }
    EXPECT_GE(impacts, 7) << toString(f);
    EXPECT_LT(sim.velocityResidual(), 1e-12);
  }
}

// Protects: a robot placed above the floor is not refused; it falls, lands on
// its wheels and caster and ends resting on all three contacts with bounded
// residuals. Passive (no wheel torques), it falls flat: all three touch down
// together at √(2h/g), and E + impact losses is conserved. Driven, the wheel
// torques pitch it in flight, it lands caster first and rocks between caster
// and wheels with ever smaller impacts until it rests on all three.
TEST(ContactEvents, RobotStartedAboveTheGroundFallsLandsAndDrives) {
  for (bool driven : {false, true}) {
    Scene scene = loadScene(std::string(APPELL_SOURCE_DIR) + "/examples/diff_drive/diff_drive.urdf");
    scene.q0[2] += 0.05;  // 5 cm up
    if (!driven) scene.tau.setZero();
    RunOptions o = runOptions(scene.settings);
    o.duration = 2.0;
    std::vector<double> times;
    const RunSummary s = runScene(scene, o, [&](const Simulator& sim) { times.push_back(sim.time()); });
    ASSERT_TRUE(s.ok) << s.failure;
    ASSERT_GE(s.events.size(), 3u);
    std::set<std::string> landed;
    for (const RunEvent& e : s.events) {
      if (e.kind == ContactEventKind::Touchdown) landed.insert(e.contact);
      // Each event is a sample (a CSV row) at its time.
      EXPECT_TRUE(std::find(times.begin(), times.end(), e.t) != times.end()) << e.contact;
    }
    EXPECT_EQ(landed.size(), 3u);
    if (!driven) {
      ASSERT_EQ(s.events.size(), 3u);
      for (const RunEvent& e : s.events) EXPECT_NEAR(e.t, std::sqrt(2 * 0.05 / kG), 1e-9) << e.contact;
      EXPECT_LT(s.relativeEnergyDeviation(), 1e-8);
    }
    EXPECT_GT(s.impact_energy_loss, 0.0);
    EXPECT_LT(s.max_velocity_residual, 1e-12);
    EXPECT_LT(s.max_gap_residual, 1e-9);
    EXPECT_LT(s.events.back().t, 0.5) << "it comes to rest on its three contacts";
    for (const ContactStats& c : s.contacts) EXPECT_EQ(c.pulling, 0) << c.name;
  }
}

namespace {

/// A ball (m₁) above a paddle (m₂) that slides vertically on a prismatic
/// joint, held up by a constant joint force m₂ g; the paddle's top face is
/// the support, carried by the paddle body (a body–body contact).
struct BallOnPaddle {
  Model model;
  ConstraintList constraints;
  VecX q0, v0, tau;
};

BallOnPaddle ballOnPaddle(double m1, double m2, double h, double e) {
  ModelBuilder b;
  const int paddle = b.addBody("paddle", -1, SE3::Identity(), JointType::Prismatic, Vec3::UnitZ(),
                               principalInertia(m2, Vec3(0.1, 0.1, 0.2)), "slide");
  const double r = 0.1, I = 0.4 * m1 * r * r;
  const int ball = b.addBody("ball", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(),
                             principalInertia(m1, Vec3(I, I, I)), "free");
  BallOnPaddle s;
  s.model = b.build();
  Support top{Plane{}, StaticMotion{}, "paddle_top"};
  top.body = paddle;
  ContactSpec spec;
  spec.kind = ContactKind::Rolling;
  spec.body = ball;
  spec.shape = Sphere{r, Vec3::Zero()};
  spec.support = top;
  spec.restitution = e;
  spec.options.name = "ball_paddle";
  s.constraints.push_back(makeContact(spec));
  s.q0 = neutralConfiguration(s.model);
  setFloatingPose(s.q0, 1, Vec3(0, 0, r + h), Mat3::Identity());
  s.v0 = VecX::Zero(s.model.nv);
  s.tau = VecX::Zero(s.model.nv);
  s.tau[0] = m2 * kG;  // the paddle floats
  return s;
}

}  // namespace

// Protects: body–body contacts make and break like world contacts (their rows
// are loop rows of the tree solver). The ball meets the floating paddle at
// √(2h/g); the impact conserves the vertical momentum: plastic, both move at
// m₁v/(m₁+m₂) and then fall together at m₁g/(m₁+m₂); elastic, the ball
// leaves at (m₁−m₂)/(m₁+m₂)·v and the paddle at 2m₁/(m₁+m₂)·v.
TEST(ContactEvents, BallOnAFloatingPaddleExchangesMomentumAtImpact) {
  const double m1 = 0.5, m2 = 1.5, h = 0.2;
  const double t_star = std::sqrt(2 * h / kG), v = -kG * t_star;
  for (double e : {0.0, 1.0}) {
    for (Formulation f : {Formulation::Tree, Formulation::Multipliers, Formulation::Appell}) {
      BallOnPaddle s = ballOnPaddle(m1, m2, h, e);
      Simulator sim(s.model, s.constraints, makeSolver(f, s.model, s.constraints),
                    IntegratorType::DormandPrince54, appell::test::tightIntegrator());
      const VecX tau = s.tau;
      sim.setJointForces([tau](double, const VecX&, const VecX&, VecX& out) { out = tau; });
      ASSERT_TRUE(sim.setState(0, s.q0, s.v0));
      EXPECT_FALSE(sim.isClosed(0));
      std::vector<ContactEvent> events;
      while (sim.time() < t_star + 0.1) {
        const StepStatus st = sim.step(1e-2);
        ASSERT_TRUE(st.ok) << st.message;
        events.insert(events.end(), sim.events().begin(), sim.events().end());
        if (!events.empty() && sim.time() == events.front().t) {
          const double vb = (floatingRotation(sim.q(), 1) * Vec3(sim.v().tail<3>())).z();
          const double vp = sim.v()[0];
          if (e == 0) {
            EXPECT_NEAR(vb, m1 * v / (m1 + m2), 1e-9) << toString(f);
            EXPECT_NEAR(vp, m1 * v / (m1 + m2), 1e-9) << toString(f);
          } else {
            EXPECT_NEAR(vb, (m1 - m2) / (m1 + m2) * v, 1e-9) << toString(f);
            EXPECT_NEAR(vp, 2 * m1 / (m1 + m2) * v, 1e-9) << toString(f);
          }
        }
      }
      ASSERT_EQ(events.size(), 1u) << toString(f) << " e = " << e;
      EXPECT_NEAR(events[0].t, t_star, 1e-10);
      EXPECT_EQ(events[0].kind, e == 0 ? ContactEventKind::Touchdown : ContactEventKind::Bounce);
      if (e == 0) {  // together, falling at m₁ g / (m₁ + m₂)
        const double dt = sim.time() - t_star;
        EXPECT_NEAR(sim.v()[0], m1 * v / (m1 + m2) - m1 * kG / (m1 + m2) * dt, 1e-9);
        EXPECT_NEAR(sim.lambda()[2], m1 * m2 * kG / (m1 + m2), 1e-9) << "the ball's load on the paddle";
      }
    }
  }
}

// Protects: the bilateral idealisation stays available. A contact declared
// unilateral = false (or a simulator with events off) never opens: pulled
// up by F = kt it holds, and its normal force goes negative at t > mg/k.
TEST(ContactEvents, BilateralContactsHoldWhenPulled) {
  const double m = 0.5, k = 2.0, t_star = m * kG / k;
  for (bool per_contact : {true, false}) {
    BuiltScene s = raisedBall(0.0, Vec3(0, 3.0, 0), Vec3(0.3, 0, 0), 0.0);
    SimulatorOptions so;
    if (per_contact) {
      ContactSpec spec = static_cast<const ShapeContact&>(*s.constraints[0]).spec();
      spec.unilateral = false;
      s.constraints[0] = makeContact(spec);
      EXPECT_FALSE(s.constraints[0]->unilateral());
    } else {
      so.contacts.enabled = false;
    }
    Simulator sim(s.model, s.constraints, makeSolver(Formulation::Tree, s.model, s.constraints),
                  IntegratorType::DormandPrince54, appell::test::tightIntegrator(), so);
    sim.setJointForces([&](double t, const VecX& q, const VecX&, VecX& tau) {
      tau.tail<3>() = floatingRotation(q, 0).transpose() * Vec3(0, 0, k * t);
    });
    ASSERT_TRUE(sim.setState(0, s.q0, s.v0));
    const auto events = appell::test::advanceCollecting(sim, t_star + 0.5, 1e-2);
    EXPECT_TRUE(events.empty());
    EXPECT_TRUE(sim.isClosed(0));
    EXPECT_NEAR(sim.lambda()[2], m * kG - k * sim.time(), 1e-9) << "the contact pulls";
    EXPECT_NEAR(centreHeight(sim), 0.1, 1e-12);
  }
}

// Protects: watching for events changes nothing when none happens. The
// watch evaluates the rows at each step's end to test for a feature switch,
// and the drift projection then reuses those rows instead of evaluating them
// again (their covectors, b and gaps depend on (q, t) only). The examples
// with a moving support (turntable: b ≠ 0) and with four driven wheels run
// the same states, to the bit, with events on and off.
TEST(ContactEvents, TheEventWatchLeavesAnEventlessRunUnchanged) {
  for (const char* name : {"ball_turntable/ball_turntable.urdf", "car/car.urdf"}) {
    const Scene scene = loadScene(std::string(APPELL_SOURCE_DIR) + "/examples/" + name);
    std::vector<VecX> end(2);
    for (int enabled = 0; enabled < 2; ++enabled) {
      SimulatorOptions so;
      so.contacts.enabled = enabled != 0;
      Simulator sim(scene.model, scene.constraints,
                    makeSolver(Formulation::Tree, scene.model, scene.constraints),
                    IntegratorType::RK4, IntegratorOptions{}, so);
      if (scene.tau.size() == scene.model.nv) {
        const VecX tau = scene.tau;
        sim.setJointForces([tau](double, const VecX&, const VecX&, VecX& out) { out = tau; });
      }
      ASSERT_TRUE(sim.setState(0, scene.q0, scene.v0));
      for (int k = 0; k < 500; ++k) {
        const StepStatus st = sim.step(2e-3);
        ASSERT_TRUE(st.ok) << name << ": " << st.message;
        ASSERT_EQ(st.events, 0) << name;
      }
      end[enabled].resize(scene.model.nq + scene.model.nv);
      end[enabled] << sim.q(), sim.v();
    }
    EXPECT_EQ(end[0], end[1]) << name << ": max difference " << (end[0] - end[1]).lpNorm<Eigen::Infinity>();
  }
}

// Protects: an impact's friction impulse stays in its cone. The
// backspinning ball of examples/bouncing_ball needs |Λₜ| = 0.43 N·s against
// Λₙ = 3.54 N·s at its first impact to leave it rolling: inside the cone for
// μ = 0.8; for μ = 0.05 it slides through the impact (a slip event, then
// the bounce) with |Λₜ| = μΛₙ exactly, and no impulse is flagged.
TEST(ContactEvents, ImpulsesStayInTheFrictionCone) {
  for (double mu : {0.8, 0.05}) {
    Scene scene = loadScene(std::string(APPELL_SOURCE_DIR) + "/examples/bouncing_ball/bouncing_ball.urdf");
    ContactSpec spec = scene.contacts[0]->spec();
    spec.mu = mu;
    scene.contacts[0] = makeContact(spec);
    scene.constraints[0] = scene.contacts[0];
    RunOptions o = runOptions(scene.settings);
    o.duration = 0.5;
    const RunSummary s = runScene(scene, o);
    ASSERT_TRUE(s.ok) << s.failure;
    ASSERT_EQ(s.events.size(), mu < 0.1 ? 2u : 1u);
    if (mu < 0.1) {
      EXPECT_EQ(s.events[0].kind, ContactEventKind::Slip);
    }
    const RunEvent& e = s.events.back();
    EXPECT_EQ(e.kind, ContactEventKind::Bounce);
    EXPECT_NEAR(e.normal_impulse, 3.54356, 1e-5);
    EXPECT_NEAR(e.tangential_impulse / e.normal_impulse, mu < 0.1 ? mu : 0.428571 / 3.54356,
                mu < 0.1 ? 1e-12 : 1e-5);
    EXPECT_FALSE(e.outside_friction_cone) << "μ = " << mu;
  }
}

// Protects: simultaneous touchdowns decided together. The car of
// examples/car dropped level from 10 cm lands on its four tyres at once
// (one impact problem with 12 rows of rank 9); tree and KKT agree on the
// post-impact state and both leave all four closed.
TEST(ContactEvents, CarDroppedLevelLandsOnFourWheelsAtOnce) {
  std::vector<VecX> after;
  for (Formulation f : {Formulation::Tree, Formulation::Multipliers}) {
    Scene scene = loadScene(std::string(APPELL_SOURCE_DIR) + "/examples/car/car.urdf");
    scene.q0[2] += 0.1;
    scene.tau.setZero();
    Simulator sim(scene.model, scene.constraints, makeSolver(f, scene.model, scene.constraints),
                  IntegratorType::DormandPrince54, appell::test::tightIntegrator());
    ASSERT_TRUE(sim.setState(0, scene.q0, scene.v0));
    for (int c = 0; c < 4; ++c) EXPECT_FALSE(sim.isClosed(c));
    const auto events = appell::test::advanceCollecting(sim, 0.3, 1e-2);
    ASSERT_EQ(events.size(), 4u) << toString(f);
    for (const ContactEvent& e : events) {
      EXPECT_EQ(e.kind, ContactEventKind::Touchdown);
      EXPECT_NEAR(e.t, std::sqrt(2 * 0.1 / kG), 1e-10);
      EXPECT_GT(e.normal_impulse, 0);
    }
    for (int c = 0; c < 4; ++c) EXPECT_TRUE(sim.isClosed(c));
    EXPECT_LT(sim.velocityResidual(), 1e-12);
    after.push_back(sim.v());
  }
  EXPECT_LT((after[0] - after[1]).lpNorm<Eigen::Infinity>(), 1e-9);
}
