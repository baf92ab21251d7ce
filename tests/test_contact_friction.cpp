// Coulomb friction at unilateral contacts (docs/contacts.md §8): stick and
// slip modes, their transitions as events, and the sliding dynamics against
// closed forms for a homogeneous ball (m, r, I = 2/5 m r²) on a plane.
#include <gtest/gtest.h>

#include <appell/simulator.hpp>

#include "ball.hpp"
#include "painleve_rod.hpp"
#include "simulation_helpers.hpp"

#include <Eigen/Geometry>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

using namespace appell;
using namespace appell::scenes;

namespace {

constexpr double kG = 9.81, kM = 0.5, kR = 0.1;


/// A ball on the plane z = 0 with friction μ, centre velocity vG and world
/// angular velocity ω (not necessarily rolling), under gravity `g`.
BuiltScene ballWithFriction(double mu, const Vec3& vG, const Vec3& omega, const Vec3& g) {
  BallParams p;
  p.radius = kR;
  p.mass = kM;
  p.mu = mu;
  p.omega = omega;
  return scenes::ballWithFriction(p, vG, g);
}

Vec3 centreVelocity(const Simulator& sim) { return floatingRotation(sim.q(), 0) * Vec3(sim.v().tail<3>()); }
Vec3 angularVelocity(const Simulator& sim) { return floatingRotation(sim.q(), 0) * Vec3(sim.v().head<3>()); }


}  // namespace

// Protects: slip → stick. A ball launched sliding at v₀ without spin slides
// with a = −μg, ω̇ = 5μg/(2r) until v = rω, at t* = 2v₀/(7μg); then it rolls
// at 5v₀/7 (the classic billiard result), in every formulation.
TEST(ContactFriction, SlidingBallStartsRollingAtFiveSevenths) {
  const double mu = 0.2, v0 = 2.0, t_star = 2 * v0 / (7 * mu * kG);
  for (Formulation f : {Formulation::Tree, Formulation::Multipliers, Formulation::Appell}) {
    BuiltScene s = ballWithFriction(mu, Vec3(v0, 0, 0), Vec3::Zero(), Vec3(0, 0, -kG));
    Simulator sim(s.model, s.constraints, makeSolver(f, s.model, s.constraints),
                  IntegratorType::DormandPrince54, appell::test::tightIntegrator());
    ASSERT_TRUE(sim.setState(0, s.q0, s.v0)) << sim.lastStateError();
    ASSERT_TRUE(sim.constraintData().isSliding(0)) << "an initial state that slips starts sliding";
    const auto events = appell::test::advanceCollecting(sim, 0.5 * t_star);
    EXPECT_NEAR(centreVelocity(sim).x(), v0 - mu * kG * sim.time(), 1e-9) << toString(f);
    EXPECT_NEAR(angularVelocity(sim).y(), 5 * mu * kG / (2 * kR) * sim.time(), 1e-8) << toString(f);
    EXPECT_NEAR(sim.lambda().head<2>().norm(), mu * kM * kG, 1e-9) << "the friction force on the tangent rows";
    EXPECT_NEAR((sim.lambda()[0] * sim.contactFrame(0).t1 + sim.lambda()[1] * sim.contactFrame(0).t2).x(),
                -mu * kM * kG, 1e-9) << "against the slip";
    EXPECT_NEAR(sim.lambda()[2], kM * kG, 1e-9);
    const auto later = appell::test::advanceCollecting(sim, 2 * t_star);
    ASSERT_EQ(later.size(), 1u) << toString(f);
    EXPECT_EQ(later[0].kind, ContactEventKind::Stick);
    EXPECT_NEAR(later[0].t, t_star, 1e-10) << toString(f);
    EXPECT_FALSE(sim.constraintData().isSliding(0));
    EXPECT_NEAR(centreVelocity(sim).x(), 5 * v0 / 7, 1e-9) << toString(f);
    EXPECT_LT(sim.velocityResidual(), 1e-12);
  }
}

// Protects: stick → slip located where the friction demand reaches μλₙ. A
// rolling ball pushed at its centre by F = kt needs the friction (2/7)F, so
// it slips at t* = 7μmg/(2k); sliding, a = (F − μmg)/m. (Adaptive steps:
// with fixed RK4 steps the slip just after onset, O(h²) small, is below the
// stages' truncation error for a ball spinning at 60 rad/s, and its
// direction is noise — docs/contacts.md §8.)
TEST(ContactFriction, PushedBallSlipsWhenTheDemandReachesMu) {
  const double mu = 0.3, k = 4.0, t_star = 7 * mu * kM * kG / (2 * k);
  for (Formulation f : {Formulation::Tree, Formulation::Multipliers, Formulation::Appell}) {
    for (IntegratorType it : {IntegratorType::DormandPrince54}) {
      BuiltScene s = ballWithFriction(mu, Vec3::Zero(), Vec3::Zero(), Vec3(0, 0, -kG));
      // The events' exactness is what is checked: at this tolerance (1e-13)
      // the steps after the slip take 5 000 evaluations within 10 µs, which the
      // automatic scheme's stall rule takes for a stall (docs/contacts.md §10,
      // a known limit) — so it is off here.
      SimulatorOptions so;
      so.timestepping.stall_work = so.timestepping.stall_steps = std::numeric_limits<long>::max();
      Simulator sim(s.model, s.constraints, makeSolver(f, s.model, s.constraints), it,
                    appell::test::tightIntegrator(), so);
      sim.setJointForces([&](double t, const VecX& q, const VecX&, VecX& tau) {
        tau.tail<3>() = floatingRotation(q, 0).transpose() * Vec3(k * t, 0, 0);
      });
      ASSERT_TRUE(sim.setState(0, s.q0, s.v0));
      const auto events = appell::test::advanceCollecting(sim, t_star + 0.2);
      std::string listed;
      for (const ContactEvent& e : events) listed += " " + std::string(toString(e.kind)) + "@" + std::to_string(e.t);
      ASSERT_EQ(events.size(), 1u) << toString(f) << " " << toString(it) << ":" << listed;
      EXPECT_EQ(events[0].kind, ContactEventKind::Slip);
      EXPECT_NEAR(events[0].t, t_star, 1e-10) << toString(f) << " " << toString(it);
      // Rolling until t*: v = (5/7) k t²/(2m); then a = (kt − μmg)/m.
      const double t = sim.time(), vs = 5.0 / 7 * k * t_star * t_star / (2 * kM);
      const double v = vs + (k * (t * t - t_star * t_star) / 2 - mu * kM * kG * (t - t_star)) / kM;
      EXPECT_NEAR(centreVelocity(sim).x(), v, 1e-8) << toString(f) << " " << toString(it);
      EXPECT_NEAR(sim.lambda().head<2>().norm(), mu * kM * kG, 1e-9);
    }
  }
}

// Protects separate static and kinetic coefficients: the static μₛ is the
// cone sticking stays in, the kinetic μₖ the force while sliding. A rolling
// ball pushed at its centre by F = kt slips when (2/7)F reaches μₛmg, at
// t* = 7μₛmg/(2k), then accelerates at (F − μₖmg)/m with the friction force
// μₖmg; a ball launched sliding on the flat decelerates at μₖg and starts
// rolling at t = 2v₀/(7μₖg) (it sticks: the rolling ball needs no friction).
TEST(ContactFriction, StaticAndKineticCoefficients) {
  const double mu_s = 0.4, mu_k = 0.25, k = 4.0, t_star = 7 * mu_s * kM * kG / (2 * k);
  for (Formulation f : {Formulation::Tree, Formulation::Multipliers}) {
    BuiltScene s = ballWithFriction(mu_s, Vec3::Zero(), Vec3::Zero(), Vec3(0, 0, -kG));
    ContactSpec spec = static_cast<const ShapeContact&>(*s.constraints[0]).spec();
    spec.mu_kinetic = mu_k;
    s.constraints[0] = makeContact(spec);
    Simulator sim(s.model, s.constraints, makeSolver(f, s.model, s.constraints),
                  IntegratorType::DormandPrince54, appell::test::tightIntegrator());
    sim.setJointForces([&](double t, const VecX& q, const VecX&, VecX& tau) {
      tau.tail<3>() = floatingRotation(q, 0).transpose() * Vec3(k * t, 0, 0);
    });
    ASSERT_TRUE(sim.setState(0, s.q0, s.v0));
    const auto events = appell::test::advanceCollecting(sim, t_star + 0.2);
    ASSERT_EQ(events.size(), 1u) << toString(f);
    EXPECT_EQ(events[0].kind, ContactEventKind::Slip);
    EXPECT_NEAR(events[0].t, t_star, 1e-10) << "slips at the static cone";
    const double t = sim.time(), vs = 5.0 / 7 * k * t_star * t_star / (2 * kM);
    const double v = vs + (k * (t * t - t_star * t_star) / 2 - mu_k * kM * kG * (t - t_star)) / kM;
    EXPECT_NEAR(centreVelocity(sim).x(), v, 1e-8) << "slides against the kinetic force";
    EXPECT_NEAR(sim.lambda().head<2>().norm(), mu_k * kM * kG, 1e-9);
  }
  const double v0 = 2.0, t_roll = 2 * v0 / (7 * mu_k * kG);
  BuiltScene s = ballWithFriction(mu_s, Vec3(v0, 0, 0), Vec3::Zero(), Vec3(0, 0, -kG));
  ContactSpec spec = static_cast<const ShapeContact&>(*s.constraints[0]).spec();
  spec.mu_kinetic = mu_k;
  s.constraints[0] = makeContact(spec);
  Simulator sim(s.model, s.constraints, makeSolver(Formulation::Tree, s.model, s.constraints),
                IntegratorType::DormandPrince54, appell::test::tightIntegrator());
  ASSERT_TRUE(sim.setState(0, s.q0, s.v0));
  const auto events = appell::test::advanceCollecting(sim, t_roll + 0.1);
  ASSERT_EQ(events.size(), 1u);  // sliding from the start (setState), then it sticks
  EXPECT_EQ(events[0].kind, ContactEventKind::Stick);
  EXPECT_NEAR(events[0].t, t_roll, 1e-10) << "decelerates at μₖg";
  EXPECT_NEAR(centreVelocity(sim).x(), 5 * v0 / 7, 1e-9);
  // A kinetic coefficient above the static one is refused by name.
  spec.mu_kinetic = 0.5;
  const ConstraintList bad{makeContact(spec)};
  try {
    Simulator wrong(s.model, bad, makeSolver(Formulation::Tree, s.model, bad),
                    IntegratorType::DormandPrince54);
    ADD_FAILURE() << "μₖ > μₛ accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("kinetic friction"), std::string::npos) << e.what();
  }
}

// Protects: the friction angle. On an incline of angle α a ball rolls
// (sticks) when tan α ≤ (7/2)μ, with a = (5/7)g sin α; above it slides from
// rest with a = g(sin α − μ cos α) and ω̇ = 5μg cos α/(2r).
TEST(ContactFriction, BallOnAnInclineRollsBelowTheFrictionAngleAndSlidesAbove) {
  const double mu = 0.1;
  for (double alpha : {0.3, 0.45}) {  // tan: 0.31 < 0.35 rolls; 0.48 > 0.35 slides
    const Vec3 g(kG * std::sin(alpha), 0, -kG * std::cos(alpha));  // the plane tilted: gravity tilted
    for (Formulation f : {Formulation::Tree, Formulation::Multipliers}) {
      BuiltScene s = ballWithFriction(mu, Vec3::Zero(), Vec3::Zero(), g);
      Simulator sim(s.model, s.constraints, makeSolver(f, s.model, s.constraints),
                    IntegratorType::DormandPrince54, appell::test::tightIntegrator());
      ASSERT_TRUE(sim.setState(0, s.q0, s.v0));
      const bool slides = std::tan(alpha) > 3.5 * mu;
      EXPECT_EQ(sim.constraintData().isSliding(0), slides) << "alpha " << alpha;
      appell::test::advanceCollecting(sim, 0.5);
      const double a = slides ? kG * (std::sin(alpha) - mu * std::cos(alpha)) : 5.0 / 7 * kG * std::sin(alpha);
      EXPECT_NEAR(centreVelocity(sim).x(), a * sim.time(), 1e-9) << "alpha " << alpha << " " << toString(f);
      const double wdot = slides ? 5 * mu * kG * std::cos(alpha) / (2 * kR) : a / kR;
      EXPECT_NEAR(angularVelocity(sim).y(), wdot * sim.time(), 1e-8) << "alpha " << alpha;
    }
  }
}

// Protects: Painlevé's paradox is reported, not solved wrongly. A thin rod
// (half-length l, I = m l²/3 about its centre) leaning at θ = atan 2 with its
// lower end on the floor, the end sliding away from the rod's foot side.
// Its friction μλₙ turns the rod down onto the floor, so the end's normal
// acceleration answers its load with the coefficient
// (1 + 3 cos θ (cos θ − μ sin θ))/m, negative for μ > 4/3 there (Stewart,
// SIAM Review 42 (2000) 3–39): no consistent sliding mode. The simulator
// names the contact and says so from μ = 1.34 up; at μ = 1.32 or 0.3, or
// sliding the other way, the rod slides normally.
TEST(ContactFriction, PainleveRodIsReportedWithTheContactNamed) {
  auto rod = [](double mu, double slip) { return painleveRod({.mu = mu, .slip = slip}); };
  struct Case {
    double mu, slip;
    bool paradox;
  };
  // The threshold is 4/3 exactly: just below it the rod slides.
  for (const Case c : {Case{2.0, -1.0, true}, Case{1.34, -1.0, true}, Case{1.32, -1.0, false},
                       Case{2.0, 1.0, false}, Case{0.3, -1.0, false}}) {
    SCOPED_TRACE("mu = " + std::to_string(c.mu) + ", slip " + std::to_string(c.slip));
    BuiltScene s = rod(c.mu, c.slip);
    // The event scheme's refusal (the automatic one takes the rod with
    // time-stepping: test_contact_timestepping.cpp).
    SimulatorOptions events;
    events.scheme = ContactScheme::Events;
    Simulator sim(s.model, s.constraints, makeSolver(Formulation::Tree, s.model, s.constraints),
                  IntegratorType::DormandPrince54, appell::test::tightIntegrator(), events);
    const bool started = sim.setState(0, s.q0, s.v0);
    if (c.paradox) {
      EXPECT_FALSE(started);
      EXPECT_NE(sim.lastStateError().find("'tip'"), std::string::npos) << sim.lastStateError();
      EXPECT_NE(sim.lastStateError().find("Painlevé"), std::string::npos) << sim.lastStateError();
      EXPECT_TRUE(sim.q().allFinite() && sim.v().allFinite());
      continue;
    }
    ASSERT_TRUE(started) << sim.lastStateError();
    EXPECT_TRUE(sim.constraintData().isSliding(0));
    EXPECT_GT(sim.lambda()[2], 0) << "the floor pushes";
    const StepStatus st = sim.step(1e-3);
    EXPECT_TRUE(st.ok) << st.message;
  }
}

// Protects sliding impacts (the friction issue's second item): a ball
// without spin thrown onto the plane at (2, 0, −1) m/s from 0.2 m above it,
// μ = 0.1, restitution e = 0 or 0.5. Sticking through the impact would need
// the tangential impulse (2/7) m s⁻ (s⁻ = 2 m/s the contact point's slip)
// against μ Pₙ = μ (1 + e) m vₙ — outside the cone, so the ball slides
// through the impact (friction_impact.cpp): v⁺ = v⁻ − μ (1 + e) vₙ,
// ω⁺ = 5 μ (1 + e) vₙ / (2 r), the slip after it s⁻ − (7/2) μ (1 + e) vₙ
// along the same direction; the impulse ratio is exactly μ (before, the
// ball left rolling with a flagged impulse). Plastic, it then slides on and
// sticks at t* = t₁ + s⁺/((7/2) μ g). The work balance, impacts and sliding
// included, closes; the three formulations agree.
TEST(ContactFriction, BallThrownOntoThePlaneSlidesThroughTheImpact) {
  const double mu = 0.1, h = 0.2, vx = 2.0, vz = -1.0;
  const double vn = std::sqrt(vz * vz + 2 * kG * h), t1 = (vz + vn) / kG;
  for (double e : {0.0, 0.5}) {
    for (Formulation f : {Formulation::Tree, Formulation::Multipliers, Formulation::Appell}) {
      BuiltScene s = ballWithFriction(mu, Vec3(vx, 0, vz), Vec3::Zero(), Vec3(0, 0, -kG));
      ContactSpec spec = static_cast<const ShapeContact&>(*s.constraints[0]).spec();
      spec.restitution = e;
      s.constraints[0] = makeContact(spec);
      s.q0[2] = kR + h;
      Simulator sim(s.model, s.constraints, makeSolver(f, s.model, s.constraints),
                    IntegratorType::DormandPrince54, appell::test::tightIntegrator());
      ASSERT_TRUE(sim.setState(0, s.q0, s.v0)) << sim.lastStateError();
      const double E0 = sim.energy();
      std::vector<ContactEvent> events;
      while (events.empty() && sim.time() < 1) {
        const StepStatus st = sim.step(1e-2);
        ASSERT_TRUE(st.ok) << st.message;
        events = sim.events();
      }
      const std::string what = std::string(toString(f)) + ", e = " + std::to_string(e);
      ASSERT_EQ(events.size(), 2u) << what;
      EXPECT_EQ(events[0].kind, ContactEventKind::Slip) << what;
      EXPECT_EQ(events[1].kind, e > 0 ? ContactEventKind::Bounce : ContactEventKind::Touchdown) << what;
      EXPECT_NEAR(events[1].t, t1, 1e-10) << what;
      const double pn = kM * (1 + e) * vn;
      EXPECT_NEAR(events[1].normal_impulse, pn, 1e-10) << what;
      EXPECT_NEAR(events[1].tangential_impulse, mu * pn, 1e-12) << what;
      EXPECT_NEAR(centreVelocity(sim).x(), vx - mu * pn / kM, 1e-10) << what;
      EXPECT_NEAR(centreVelocity(sim).z(), e * vn, 1e-10) << what;
      EXPECT_NEAR(angularVelocity(sim).y(), 5 * mu * pn / (2 * kM * kR), 1e-9) << what;
      const double slip = vx - 3.5 * mu * pn / kM;
      if (e > 0) {
        EXPECT_FALSE(sim.isClosed(0)) << what;
        continue;
      }
      ASSERT_TRUE(sim.constraintData().isSliding(0)) << what;
      EXPECT_NEAR(sim.constraintData().slide[0].slip.norm(), slip, 1e-10) << what;
      const double t_stick = t1 + slip / (3.5 * mu * kG);
      const auto later = appell::test::advanceCollecting(sim, t_stick + 0.1);
      ASSERT_EQ(later.size(), 1u) << what;
      EXPECT_EQ(later[0].kind, ContactEventKind::Stick) << what;
      EXPECT_NEAR(later[0].t, t_stick, 1e-9) << what;
      EXPECT_LT(std::abs(sim.energy() + sim.impactEnergyLoss() + sim.frictionWork() - E0), 1e-9 * E0)
          << what;
    }
  }
}

namespace {

/// The ball of ballWithFriction rolling without spin, with spin friction ℓ.
BuiltScene ballWithSpinFriction(double mu, double ell, const Vec3& vG, const Vec3& omega) {
  BuiltScene s = ballWithFriction(mu, vG, omega, Vec3(0, 0, -kG));
  ContactSpec spec = static_cast<const ShapeContact&>(*s.constraints[0]).spec();
  spec.kind = ContactKind::RollingWithoutSpin;
  spec.mu_spin = ell;
  s.constraints[0] = makeContact(spec);
  return s;
}

}  // namespace

// Protects spin (torsional) friction (the friction issue's first item): a
// ball rolling without spin, μ = 0.5, spin friction ℓ = 0.01 m, started
// spinning at ω₀ = 10 rad/s about the vertical. The spin row slides with
// the torque ℓ m g, so ω = ω₀ − (ℓ m g / I) t to round-off; it sticks at
// t* = ω₀ I / (ℓ m g) and stays; friction took ½ I ω₀². A torque k t about
// the vertical on the ball at rest is held until it reaches ℓ m g (the slip
// event there), then spins it up at (k t − ℓ m g)/I. Sliding and spinning at
// once, force and torque share the ellipsoid |(fₜ, τ μ/ℓ)| ≤ μλₙ along the
// slip (v, ω ℓ/μ) — Leine & Glocker's elliptic approximation of the
// Contensou coupling: at v = 1 m/s and ω ℓ/μ = 1 m/s each takes 1/√2 of
// its limit. Three formulations.
TEST(ContactFriction, SpinFrictionStopsASpinningBallAtTheTorsionalRate) {
  const double mu = 0.5, ell = 0.01, w0 = 10, I = 0.4 * kM * kR * kR;
  const double rate = ell * kM * kG / I, t_star = w0 / rate;
  for (Formulation f : {Formulation::Tree, Formulation::Multipliers, Formulation::Appell}) {
    const std::string what = toString(f);
    {
      BuiltScene s = ballWithSpinFriction(mu, ell, Vec3::Zero(), Vec3(0, 0, w0));
      Simulator sim(s.model, s.constraints, makeSolver(f, s.model, s.constraints),
                    IntegratorType::DormandPrince54, appell::test::tightIntegrator());
      ASSERT_TRUE(sim.setState(0, s.q0, s.v0)) << sim.lastStateError();
      ASSERT_TRUE(sim.constraintData().isSliding(0)) << what;
      const double E0 = sim.energy();
      auto events = appell::test::advanceCollecting(sim, 0.5 * t_star);
      EXPECT_TRUE(events.empty()) << what;
      EXPECT_NEAR(angularVelocity(sim).z(), w0 - rate * sim.time(), 1e-9) << what;
      EXPECT_NEAR(sim.lambda()[3], -ell * kM * kG, 1e-9) << what << ": the spin row's torque";
      EXPECT_LT(centreVelocity(sim).norm(), 1e-12) << what;
      events = appell::test::advanceCollecting(sim, 1.5 * t_star);
      ASSERT_EQ(events.size(), 1u) << what;
      EXPECT_EQ(events[0].kind, ContactEventKind::Stick) << what;
      EXPECT_NEAR(events[0].t, t_star, 1e-9) << what;
      EXPECT_LT(std::abs(angularVelocity(sim).z()), 1e-12) << what;
      EXPECT_NEAR(sim.frictionWork(), 0.5 * I * w0 * w0, 1e-9) << what;
      EXPECT_LT(std::abs(sim.energy() + sim.frictionWork() - E0), 1e-10) << what;
    }
    {
      const double k = 2.0, t_slip = ell * kM * kG / k;
      BuiltScene s = ballWithSpinFriction(mu, ell, Vec3::Zero(), Vec3::Zero());
      Simulator sim(s.model, s.constraints, makeSolver(f, s.model, s.constraints),
                    IntegratorType::DormandPrince54, appell::test::tightIntegrator());
      sim.setJointForces([&](double t, const VecX& q, const VecX&, VecX& tau) {
        tau.head<3>() = floatingRotation(q, 0).transpose() * Vec3(0, 0, k * t);
      });
      ASSERT_TRUE(sim.setState(0, s.q0, s.v0)) << sim.lastStateError();
      auto events = appell::test::advanceCollecting(sim, 2 * t_slip);
      ASSERT_EQ(events.size(), 1u) << what;
      EXPECT_EQ(events[0].kind, ContactEventKind::Slip) << what;
      EXPECT_NEAR(events[0].t, t_slip, 1e-9) << what;
      const double t = sim.time();
      EXPECT_NEAR(angularVelocity(sim).z(), (0.5 * k * (t * t - t_slip * t_slip) - ell * kM * kG * (t - t_slip)) / I,
                  1e-8) << what;
    }
    {
      BuiltScene s = ballWithSpinFriction(mu, ell, Vec3(1, 0, 0), Vec3(0, 0, mu / ell));
      Simulator sim(s.model, s.constraints, makeSolver(f, s.model, s.constraints),
                    IntegratorType::DormandPrince54, appell::test::tightIntegrator());
      ASSERT_TRUE(sim.setState(0, s.q0, s.v0)) << sim.lastStateError();
      const Vec3 ft = sim.lambda()[0] * sim.contactFrame(0).t1 + sim.lambda()[1] * sim.contactFrame(0).t2;
      EXPECT_NEAR(ft.x(), -mu * kM * kG / std::sqrt(2.0), 1e-9) << what;
      EXPECT_NEAR(ft.y(), 0, 1e-12) << what;
      EXPECT_NEAR(sim.lambda()[3], -ell * kM * kG / std::sqrt(2.0), 1e-9) << what;
    }
  }
  // Spin friction needs a spin row and a finite μ > 0.
  ContactSpec spec = static_cast<const ShapeContact&>(*ballWithSpinFriction(mu, ell, Vec3::Zero(), Vec3::Zero()).constraints[0]).spec();
  spec.kind = ContactKind::Rolling;
  EXPECT_THROW(makeContact(spec), std::invalid_argument);
  spec.kind = ContactKind::RollingWithoutSpin;
  spec.mu = std::numeric_limits<double>::infinity();
  EXPECT_THROW(makeContact(spec), std::invalid_argument);
  spec.mu = 0.5;
  spec.mu_spin = -1;
  EXPECT_THROW(makeContact(spec), std::invalid_argument);
}
