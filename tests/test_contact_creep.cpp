// Regularized Coulomb friction (Constraint::creepSpeed, docs/contacts.md §8):
// a contact with a creep speed v_c never sticks; while closed it carries
//     f = −μ λₙ s / max(|s|, v_c)
// of its slip s. Checked against the closed forms of a homogeneous ball
// (m, r, I = 2/5 m r²) on a plane, where the slip obeys ṡ = −(7/2) μ g φ(s)
// (φ(s) = s/max(|s|, v_c)) plus the drive of gravity along an incline.
#include <gtest/gtest.h>

#include <appell/simulator.hpp>

#include "ball.hpp"
#include "simulation_helpers.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

using namespace appell;
using namespace appell::scenes;

namespace {

constexpr double kG = 9.81, kM = 0.5, kR = 0.1;

BuiltScene creepingBall(double mu, double creep, const Vec3& vG, const Vec3& g) {
  BallParams p;
  p.radius = kR;
  p.mass = kM;
  p.mu = mu;
  p.creep_speed = creep;
  p.omega = Vec3::Zero();
  return ballWithFriction(p, vG, g);
}

Vec3 centreVelocity(const Simulator& sim) { return floatingRotation(sim.q(), 0) * Vec3(sim.v().tail<3>()); }
Vec3 angularVelocity(const Simulator& sim) { return floatingRotation(sim.q(), 0) * Vec3(sim.v().head<3>()); }
/// The contact point's slip along x: v − r ω_y.
double slip(const Simulator& sim) { return centreVelocity(sim).x() - kR * angularVelocity(sim).y(); }

}  // namespace

// Protects: the creep law and its two regimes. A ball launched at v₀ without
// spin slides at the Coulomb rate while s > v_c — s = v₀ − (7/2)μg t,
// v = v₀ − μg t — until t₁ = (v₀ − v_c)/((7/2)μg); below v_c the slip decays
// as v_c e^{−(t−t₁)/τ}, τ = 2v_c/(7μg), and v = v(t₁) − μgτ(1 − e^{−(t−t₁)/τ})
// → 5v₀/7: the Coulomb ball's final speed, approached without a stick
// event. Friction's work is the kinetic energy lost, m(v₀² − v_c²)/7 in the
// first regime plus m v_c²(1 − e^{−2(t−t₁)/τ})/7 in the second. In the tree
// and the multiplier formulations.
TEST(ContactCreep, SlidingBallCreepsTowardsRollingAsTheClosedForm) {
  const double mu = 0.2, v0 = 2.0, vc = 0.05;
  const double rate = 3.5 * mu * kG, t1 = (v0 - vc) / rate, tau = vc / rate;
  for (Formulation f : {Formulation::Tree, Formulation::Multipliers}) {
    BuiltScene s = creepingBall(mu, vc, Vec3(v0, 0, 0), Vec3(0, 0, -kG));
    Simulator sim(s.model, s.constraints, makeSolver(f, s.model, s.constraints),
                  IntegratorType::DormandPrince54, appell::test::tightIntegrator());
    ASSERT_TRUE(sim.setState(0, s.q0, s.v0)) << sim.lastStateError();
    ASSERT_TRUE(sim.constraintData().isSliding(0)) << "a regularized contact closes sliding";
    const double E0 = sim.energy();
    // The first regime (no event at s = v_c: φ is continuous there).
    auto events = appell::test::advanceCollecting(sim, 0.5 * t1);
    EXPECT_NEAR(centreVelocity(sim).x(), v0 - mu * kG * sim.time(), 1e-9) << toString(f);
    EXPECT_NEAR(slip(sim), v0 - rate * sim.time(), 1e-9) << toString(f);
    EXPECT_NEAR(sim.lambda().head<2>().norm(), mu * kM * kG, 1e-9) << "saturated: Coulomb's force";
    // The second regime, three time constants in.
    const double t = t1 + 3 * tau;
    const auto later = appell::test::advanceCollecting(sim, t);
    events.insert(events.end(), later.begin(), later.end());
    EXPECT_TRUE(events.empty()) << toString(f) << ": no stick or slip event, got "
                                << (events.empty() ? "" : toString(events[0].kind));
    EXPECT_TRUE(sim.constraintData().isSliding(0));
    const double decay = std::exp(-(t - t1) / tau);
    EXPECT_NEAR(slip(sim), vc * decay, 1e-9) << toString(f);
    EXPECT_NEAR(centreVelocity(sim).x(), v0 - mu * kG * t1 - mu * kG * tau * (1 - decay), 1e-9)
        << toString(f);
    EXPECT_NEAR(sim.lambda().head<2>().norm(), mu * kM * kG * decay, 1e-9) << "the creep force";
    const double lost = kM * (v0 * v0 - vc * vc) / 7 + kM * vc * vc * (1 - decay * decay) / 7;
    EXPECT_NEAR(E0 - sim.energy(), lost, 1e-9) << toString(f);
    EXPECT_NEAR(sim.frictionWork(), lost, 1e-9) << "friction's work is the energy lost";
    EXPECT_LT(sim.velocityResidual(), 1e-12);
  }
}

// Protects: where Coulomb's ball sticks, the creeping one slips steadily. On
// an incline of angle α with tan α < (7/2)μ the sticking ball rolls; with a
// creep speed the slip from rest obeys ṡ = g sin α − (7/2)μ g cos α s/v_c,
// so s = s*(1 − e^{−t/τ}) with s* = (2/7) v_c tan α/μ, τ = 2v_c/(7μ g cos α),
// and the centre accelerates at g sin α − μ g cos α s/v_c.
TEST(ContactCreep, BallOnAnInclineSlipsAtTheSteadyCreep) {
  const double mu = 0.3, vc = 0.02, alpha = 0.3;
  const double s_star = 2.0 / 7 * vc * std::tan(alpha) / mu;
  const double tau = 2 * vc / (7 * mu * kG * std::cos(alpha));
  const Vec3 g(kG * std::sin(alpha), 0, -kG * std::cos(alpha));  // the plane tilted: gravity tilted
  BuiltScene s = creepingBall(mu, vc, Vec3::Zero(), g);
  Simulator sim(s.model, s.constraints, makeSolver(Formulation::Tree, s.model, s.constraints),
                IntegratorType::DormandPrince54, appell::test::tightIntegrator());
  ASSERT_TRUE(sim.setState(0, s.q0, s.v0)) << sim.lastStateError();
  const double t = 4 * tau;
  EXPECT_TRUE(appell::test::advanceCollecting(sim, t).empty());
  const double e = std::exp(-t / tau);
  EXPECT_NEAR(slip(sim), s_star * (1 - e), 1e-10);
  // v = ∫ (g sin α − μ g cos α s/v_c) dt.
  const double v = kG * std::sin(alpha) * t - mu * kG * std::cos(alpha) * s_star / vc * (t - tau * (1 - e));
  EXPECT_NEAR(centreVelocity(sim).x(), v, 1e-10);
  EXPECT_LT(s_star, vc) << "the case is in the linear range";
}

// Protects: bad creep declarations are refused with the contact named.
TEST(ContactCreep, BadCreepDeclarationsNameTheContact) {
  BallParams p;
  BuiltScene s = ball(p);
  ContactSpec spec = static_cast<const ShapeContact&>(*s.constraints[0]).spec();
  spec.options.name = "tyre";
  auto refused = [&](ContactSpec c, const std::string& reason) {
    try {
      makeContact(c);
      ADD_FAILURE() << "accepted: " << reason;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("'tyre'"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(reason), std::string::npos) << e.what();
    }
  };
  ContactSpec c = spec;
  c.mu = 0.5;
  c.creep_speed = -0.1;
  refused(c, "creep speed must be ≥ 0");
  c.creep_speed = std::nan("");
  refused(c, "creep speed must be ≥ 0");
  c = spec;  // μ = ∞
  c.creep_speed = 0.1;
  refused(c, "needs a finite friction coefficient");
  c.mu = 0.5;
  c.unilateral = false;
  refused(c, "needs a unilateral contact");
}
