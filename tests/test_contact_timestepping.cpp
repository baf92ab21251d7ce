// The time-stepping contact scheme and the automatic switch
// (docs/contacts.md §10): Moreau–Jean steps against closed forms — a box on
// four corners pushed to sliding, a ball sliding into rolling — its energy
// and momentum balances, and the automatic scheme: no window where the
// events are exact, a window where they give up.
#include <gtest/gtest.h>

#include <appell/run.hpp>
#include <appell/simulator.hpp>
#include <appell/urdf.hpp>
#include <appell/vertex_contacts.hpp>

#include "ball.hpp"
#include "corner_box.hpp"
#include "painleve_rod.hpp"
#include "scene.hpp"
#include "simulation_helpers.hpp"

#include <cmath>
#include <fstream>
#include <iostream>
#include <regex>
#include <sstream>

using namespace appell;
using namespace appell::scenes;

namespace {

constexpr double kG = 9.81;
const Vec3 kHalf(0.2, 0.1, 0.05);
constexpr double kMass = 2.0;

using BoxScene = BuiltScene;

// A uniform box resting flat on z = 0 (its lowest corners at `h`), its eight
// corners point contacts of `kind` with friction μ (∞: none given).
BoxScene box(double h, ContactKind kind, double mu, const Mat3& R = Mat3::Identity()) {
  return cornerBox({.half = kHalf, .mass = kMass, .h = h, .R = R, .kind = kind, .mu = mu});
}

SimulatorOptions scheme(ContactScheme c, double step = 1e-3) {
  SimulatorOptions o;
  o.scheme = c;
  o.timestepping.step = step;
  return o;
}

Vec3 worldLinear(const Simulator& sim) {
  return floatingRotation(sim.q(), 0) * Vec3(sim.v().tail<3>());
}

// Time-stepping of the pushed box: four corners on one face are redundant,
// Gauss–Seidel creeps at the slip onset, so the problem is solved to 1e-8
// m/s or 500 sweeps.
SimulatorOptions pushedBoxScheme(double h) {
  SimulatorOptions so = scheme(ContactScheme::TimeStepping, h);
  so.timestepping.residual_tol = 1e-8;
  so.timestepping.max_sweeps = 500;
  return so;
}

// Pushes the box at its centre by F = k t from rest to T in steps of h; the
// time its speed first passes 1e-6 m/s (sticking holds the slip to the
// residual, 1e-8 m/s), −1 if never, NaN (and a test failure) if a step fails.
double pushBox(Simulator& sim, const BoxScene& s, double k, double T, double h) {
  sim.setJointForces([k](double t, const VecX& q, const VecX&, VecX& tau) {
    tau.tail<3>() = floatingRotation(q, 0).transpose() * Vec3(k * t, 0, 0);
  });
  if (!sim.setState(0, s.q0, s.v0)) {
    ADD_FAILURE() << sim.lastStateError();
    return std::nan("");
  }
  double t_slip = -1;
  while (sim.time() < T - 1e-12) {
    const StepStatus st = sim.step(std::min(h, T - sim.time()));
    if (!st.ok) {
      ADD_FAILURE() << st.message;
      return std::nan("");
    }
    if (t_slip < 0 && worldLinear(sim).x() > 1e-6) t_slip = sim.time();
  }
  return t_slip;
}

}  // namespace

// Protects the Moreau–Jean step against the closed form of a box on four
// corners (redundant normal rows, statically indeterminate friction) pushed
// at its centre by F = k t: it sticks while F ≤ μ m g, so slip starts at
// t* = μ m g / k, then accelerates at (F − μ m g)/m: v(t) = k (t − t*)²/(2m).
// Time-stepping is O(h): the onset within a step or two, the velocity to
// O(h) — the error halves with h — and 0.7 s in 700 steps.
TEST(ContactTimeStepping, BoxPushedToSlidingOnFourCorners) {
  const double mu = 0.5, k = 30.0, t_star = mu * kMass * kG / k, T = 0.7;
  double errors[2] = {0, 0};
  int run = 0;
  for (double h : {1e-3, 5e-4}) {
    SCOPED_TRACE("h = " + std::to_string(h));
    BoxScene s = box(0, ContactKind::Rolling, mu);
    Simulator sim(s.model, s.constraints, makeSolver(Formulation::Tree, s.model, s.constraints),
                  IntegratorType::RK4, {}, pushedBoxScheme(h));
    const double t_slip = pushBox(sim, s, k, T, h);
    EXPECT_EQ(sim.counters().timestepping_steps, std::lround(T / h));
    std::cout << "h = " << h << ": " << sim.counters().unconverged << " problems at max sweeps, "
              << "largest residual " << sim.counters().max_contact_residual << " m/s\n";
    EXPECT_LT(sim.counters().unconverged, 10);
    EXPECT_LT(sim.counters().max_contact_residual, 1e-5) << "m/s";
    // (Within two steps; t is a sum of steps, so the bound allows its round-off:
    // at h = 0.5 ms the slip shows at t* + 2h, 2e-16 s past 2h.)
    EXPECT_NEAR(t_slip, t_star, 2 * h + 1e-12) << "slip starts where F reaches μ m g";
    const double v = k * (T - t_star) * (T - t_star) / (2 * kMass);
    errors[run++] = std::abs(worldLinear(sim).x() - v);
    EXPECT_LT(errors[run - 1], 10 * h * k / kMass * (T - t_star)) << worldLinear(sim).x() << " vs " << v;
    EXPECT_LT(std::abs(worldLinear(sim).y()), 1e-12) << "no sideways drift";
    EXPECT_LT(std::abs(worldLinear(sim).z()), 1e-9) << "on the floor";
    EXPECT_NEAR(sim.q()[2], kHalf.z(), 1e-9);
    int closed = 0;
    for (int c = 0; c < 8; ++c) closed += sim.isClosed(c);
    EXPECT_EQ(closed, 4);
  }
  EXPECT_LT(errors[1], 0.7 * errors[0]) << "first order: the error shrinks with h";
}

// Protects Coulomb's two coefficients in the time-stepping step: the box on
// four corners pushed by F = k t sticks on the static cone until F = μₛ m g,
// t* = μₛ m g / k, then slides against the kinetic force μₖ m g:
// v(t) = (k (t² − t*²)/2 − μₖ m g (t − t*)) / m. Before 2026-11-27 every
// step solved the static cone, and a sliding contact pushed out of an
// O(h) overlap was taken for a rebound (reported open): the box slid
// against μₛ m g, 0.73 m/s slower at 0.7 s.
TEST(ContactTimeStepping, BoxSticksOnTheStaticConeAndSlidesOnTheKinetic) {
  const double mu_s = 0.5, mu_k = 0.3, k = 30.0, T = 0.7, h = 1e-3;
  const double t_star = mu_s * kMass * kG / k;
  BoxScene s = cornerBox({.half = kHalf, .mass = kMass, .mu = mu_s, .mu_kinetic = mu_k});
  Simulator sim(s.model, s.constraints, makeSolver(Formulation::Tree, s.model, s.constraints),
                IntegratorType::RK4, {}, pushedBoxScheme(h));
  const double t_slip = pushBox(sim, s, k, T, h);
  EXPECT_NEAR(t_slip, t_star, 2 * h + 1e-12) << "slip starts where F reaches μₛ m g";
  const double v = (k * (T * T - t_star * t_star) / 2 - mu_k * kMass * kG * (T - t_star)) / kMass;
  EXPECT_NEAR(worldLinear(sim).x(), v, 10 * h * k / kMass * (T - t_star)) << "slides against μₖ m g";
  int sliding = 0;
  for (int c = 0; c < 8; ++c) sliding += sim.isClosed(c) && sim.constraintData().isSliding(c);
  EXPECT_EQ(sliding, 4) << "the four bottom corners closed and sliding";
}

// Protects the time-stepping balances: a frictionless box thrown sideways
// and spinning onto the floor keeps its horizontal momentum to O(h) (every
// impulse is vertical; the explicit step of a spinning body's body-frame
// velocity drifts by h² ω² |v| / 2 per step); with friction μ = 0.3 its
// impacts and friction take energy (impact losses ≥ 0, the friction work
// never decreases) and E + impact losses + friction work stays E₀ to O(h).
TEST(ContactTimeStepping, MomentumIsKeptAndFrictionOnlyDissipates) {
  const Mat3 R = axisAngle(Vec3(1, 1, 0).normalized(), 0.3);
  for (double mu : {std::numeric_limits<double>::infinity(), 0.3}) {
    const bool frictionless = !std::isfinite(mu);
    SCOPED_TRACE(frictionless ? "frictionless" : "mu = 0.3");
    BoxScene s = box(0.05, frictionless ? ContactKind::Sliding : ContactKind::Rolling,
                     frictionless ? INFINITY : mu, R);
    s.v0.tail<3>() = R.transpose() * Vec3(1.5, -0.5, 0);
    s.v0.head<3>() = R.transpose() * Vec3(0, 0, 4.0);
    Simulator sim(s.model, s.constraints, makeSolver(Formulation::Tree, s.model, s.constraints),
                  IntegratorType::RK4, {}, scheme(ContactScheme::TimeStepping));
    ASSERT_TRUE(sim.setState(0, s.q0, s.v0));
    const double E0 = sim.energy();
    const Vec3 p0 = kMass * worldLinear(sim);
    double friction = 0, worst_p = 0, worst_e = 0;
    while (sim.time() < 1.5 - 1e-12) {
      ASSERT_TRUE(sim.step(1e-3).ok);
      EXPECT_GE(sim.frictionWork(), friction - 1e-12) << "at t = " << sim.time();
      friction = sim.frictionWork();
      EXPECT_GE(sim.impactEnergyLoss(), -1e-12);
      worst_p = std::max(worst_p, (kMass * worldLinear(sim) - p0).head<2>().norm());
      worst_e = std::max(worst_e, std::abs(sim.energy() + sim.impactEnergyLoss() + sim.frictionWork() - E0));
    }
    std::cout << (frictionless ? "frictionless" : "mu 0.3") << ": momentum drift " << worst_p
              << " of " << p0.norm() << ", balance " << worst_e << " J of " << E0 << "\n";
    if (frictionless) {
      EXPECT_LT(worst_p, 2.5e-2 * p0.norm()) << "horizontal momentum to O(h)";
      EXPECT_EQ(sim.frictionWork(), 0.0);
    } else {
      EXPECT_GT(sim.frictionWork(), 0.1 * E0) << "the floor's friction took a share";
      EXPECT_LT(sim.v().norm(), 1e-6) << "at rest";
    }
    EXPECT_GT(sim.impactEnergyLoss(), 0.0);
    EXPECT_LT(worst_e, 5e-2 * E0) << "the balance closes to O(h)";
  }
}

// Protects exactness where the events decide: the ball launched sliding
// sticks at t* = 2v₀/(7μg) and rolls at 5v₀/7 under the default (auto)
// scheme to 1e-10 with no time-stepping window; the time-stepping scheme
// reaches 5v₀/7 to first order in h (its contact rows at the step's
// predicted end, docs/contacts.md §10).
TEST(ContactTimeStepping, SlidingBallAutoTakesNoWindowAndStaysExact) {
  const double mu = 0.2, v0 = 2.0, t_star = 2 * v0 / (7 * mu * kG);
  BallParams p;
  p.mu = mu;
  p.omega = Vec3::Zero();
  for (ContactScheme c : {ContactScheme::Auto, ContactScheme::TimeStepping}) {
    SCOPED_TRACE(toString(c));
    BuiltScene s = ballWithFriction(p, Vec3(v0, 0, 0), Vec3(0, 0, -kG));
    SimulatorOptions o;
    o.scheme = c;
    EXPECT_EQ(SimulatorOptions{}.scheme, ContactScheme::Auto) << "auto is the default";
    Simulator sim(s.model, s.constraints, makeSolver(Formulation::Tree, s.model, s.constraints),
                  IntegratorType::DormandPrince54, appell::test::tightIntegrator(), o);
    ASSERT_TRUE(sim.setState(0, s.q0, s.v0)) << sim.lastStateError();
    double t_roll = -1;
    std::vector<ContactEvent> events;
    while (sim.time() < 2 * t_star - 1e-12) {
      ASSERT_TRUE(sim.step(std::min(1e-3, 2 * t_star - sim.time())).ok);
      events.insert(events.end(), sim.events().begin(), sim.events().end());
      if (t_roll < 0 && std::abs(worldLinear(sim).x() - 5 * v0 / 7) < 1e-9) t_roll = sim.time();
    }
    if (c == ContactScheme::Auto) {
      EXPECT_NEAR(worldLinear(sim).x(), 5 * v0 / 7, 1e-10);
      EXPECT_EQ(sim.counters().windows, 0) << "no window where the events are exact";
      EXPECT_EQ(sim.counters().timestepping_steps, 0);
      ASSERT_EQ(events.size(), 1u);
      EXPECT_EQ(events[0].kind, ContactEventKind::Stick);
      EXPECT_NEAR(events[0].t, t_star, 1e-10);
    } else {
      // First order: measured 1.4261 against 5v₀/7 = 1.4286 at h = 1 ms.
      EXPECT_GT(sim.counters().timestepping_steps, 0);
      EXPECT_NEAR(worldLinear(sim).x(), 5 * v0 / 7, 5e-3);
      EXPECT_GT(t_roll, -2.0) << "(rolling is reached to O(h), not to 1e-9)";
    }
  }
}

// Protects the switch: the Painlevé rod (μ = 2, sliding towards its foot)
// has no consistent contact mode for the events (test_contact_friction);
// the event scheme refuses it naming the contact, the automatic one opens a
// time-stepping window there — logged as a TimeStepping event on 'tip' —
// and runs on: the impulse scheme resolves the paradox by a tangential
// impact, the floor never pulls, and the rod does not sink.
TEST(ContactTimeStepping, AutoOpensAWindowWhereTheEventsFindNoMode) {
  const BuiltScene s = painleveRod({.mu = 2.0, .slip = -1.0});
  Simulator events(s.model, s.constraints, makeSolver(Formulation::Tree, s.model, s.constraints),
                   IntegratorType::DormandPrince54, appell::test::tightIntegrator(),
                   scheme(ContactScheme::Events));
  EXPECT_FALSE(events.setState(0, s.q0, s.v0));
  EXPECT_NE(events.lastStateError().find("'tip'"), std::string::npos);

  Simulator sim(s.model, s.constraints, makeSolver(Formulation::Tree, s.model, s.constraints),
                IntegratorType::DormandPrince54, appell::test::tightIntegrator());
  ASSERT_TRUE(sim.setState(0, s.q0, s.v0)) << sim.lastStateError();
  EXPECT_EQ(sim.counters().windows, 1);
  EXPECT_EQ(sim.stepScheme(), ContactScheme::TimeStepping);
  EXPECT_NE(sim.windowReason().find("Painlevé"), std::string::npos) << sim.windowReason();
  const StepStatus st = sim.step(1e-3);
  ASSERT_TRUE(st.ok) << st.message;
  ASSERT_FALSE(sim.events().empty());
  EXPECT_EQ(sim.events()[0].kind, ContactEventKind::TimeStepping);
  EXPECT_EQ(sim.events()[0].constraint, 0);
  const double E0 = sim.energy() + sim.impactEnergyLoss() + sim.frictionWork();
  while (sim.time() < 0.5) {
    ASSERT_TRUE(sim.step(1e-3).ok);
    EXPECT_GE(sim.lambda()[2], 0) << "the floor never pulls";
    EXPECT_GT(sim.contactFrame(0).gap, -1e-9) << "no sinking";
  }
  EXPECT_LE(sim.energy(), E0 + 1e-2 * std::abs(E0)) << "no energy gained";
}

// Protects the scheme's names: the table that --contacts, the scene's
// <simulation contacts="…"> and Python read, and its refusals.
TEST(ContactTimeStepping, SchemeNames) {
  EXPECT_EQ(contactSchemeFromString("auto"), ContactScheme::Auto);
  EXPECT_EQ(contactSchemeFromString("events"), ContactScheme::Events);
  EXPECT_EQ(contactSchemeFromString("timestepping"), ContactScheme::TimeStepping);
  EXPECT_EQ(contactSchemeFromString("moreau-jean"), ContactScheme::TimeStepping);
  EXPECT_STREQ(toString(ContactScheme::TimeStepping), "timestepping");
  try {
    contactSchemeFromString("penalty");
    ADD_FAILURE() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'penalty'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("timestepping"), std::string::npos) << e.what();
  }
  EXPECT_STREQ(toString(ContactEventKind::TimeStepping), "timestepping");
  EXPECT_STREQ(toString(ContactEventKind::Events), "events");
  BoxScene s = box(0, ContactKind::Rolling, 0.5);
  SimulatorOptions o;
  o.timestepping.theta = 0;
  EXPECT_THROW(Simulator(s.model, s.constraints, makeSolver(Formulation::Tree, s.model, s.constraints),
                         IntegratorType::RK4, {}, o),
               std::invalid_argument);
}

// Protects the done-when scene: the 57 kg skid-steer robot turning on a
// step command with Coulomb tyres and no creep (examples/skid_steer_step)
// runs to its end under the default scheme; it turns left; the time-stepping
// windows are logged as events; and the work balance — motor work =
// ΔE + impact losses + friction work — closes to the scheme's O(h).
TEST(ContactTimeStepping, SkidSteerOnAStepCommandRunsToItsEnd) {
  const Scene scene = loadScene(std::string(APPELL_SOURCE_DIR) +
                                "/examples/skid_steer_step/skid_steer_step.urdf");
  RunOptions o = runOptions(scene.settings);
  EXPECT_EQ(o.contacts, ContactScheme::Auto) << "the scene asks for auto";
  o.duration = 3.0;
  const RunSummary s = runScene(scene, o, RunObserver{});
  ASSERT_TRUE(s.ok) << s.failure;
  EXPECT_NEAR(s.time, 3.0, 1e-12);
  int windows = 0;
  for (const RunEvent& e : s.events) windows += e.kind == ContactEventKind::TimeStepping;
  EXPECT_EQ(windows, s.counters.windows);
  EXPECT_GT(s.joint_work, 0.0);
  EXPECT_GT(s.friction_work, 0.0);
  EXPECT_LT(s.max_energy_deviation, 2e-2 * s.energy_scale)
      << "balance off by " << s.max_energy_deviation << " J of " << s.energy_scale;
}

// Protects the time-stepped skid-steer's turn (docs/contacts.md §10): four
// tyres sliding on μₖ = 0.7 under a step command. The loads of four tyres
// on a rigid chassis are undetermined along its warp; the events take the
// minimum-norm split, and so does the time-stepping finish, which solves
// the contact problem's equalities from zero. Warm-started from the last
// step's impulses instead, the split drifted (217/60/42/241 N at 6 s
// against the events' 125/151/129/155) and the turn slowed to 0.85 rad/s;
// on the static cone it was 0.74. Now the time-stepped yaw rate is the
// events' to 2e-3 from 2 s on, and steady.
TEST(ContactTimeStepping, SkidSteerTurnsAtTheEventsRate) {
  const Scene scene = loadScene(std::string(APPELL_SOURCE_DIR) +
                                "/examples/skid_steer_step/skid_steer_step.urdf");
  RunOptions o = runOptions(scene.settings);
  o.duration = 4.0;
  double yaw[2][2] = {{0, 0}, {0, 0}};  // [scheme][at 2 s, at 4 s]
  const ContactScheme schemes[2] = {ContactScheme::Auto, ContactScheme::TimeStepping};
  for (int i = 0; i < 2; ++i) {
    o.contacts = schemes[i];
    const RunSummary s = runScene(scene, o, RunObserver{}, [&](const Simulator& sim) {
      yaw[i][sim.time() < 2.0 ? 0 : 1] = sim.v()[2];  // (the root's ω_z: body frame, level chassis)
    });
    ASSERT_TRUE(s.ok) << toString(schemes[i]) << ": " << s.failure;
    if (i == 0) EXPECT_EQ(s.counters.windows, 0) << "the events decide every mode";
  }
  std::cout << "yaw rate: events " << yaw[0][0] << " → " << yaw[0][1] << " rad/s, time-stepping "
            << yaw[1][0] << " → " << yaw[1][1] << "\n";
  EXPECT_NEAR(yaw[0][1], 1.0053, 1e-3) << "the events' steady turn";
  EXPECT_NEAR(yaw[1][1], yaw[0][1], 2e-3 * yaw[0][1]) << "time-stepping turns as the events do";
  EXPECT_NEAR(yaw[1][1], yaw[1][0], 1e-3) << "and steadily";
}

// Protects the automatic scheme on the box on four corners pushed to
// sliding: the events are exact while it sticks, their steps collapse at the
// slip onset of four redundant corners (no mode decision fails there, no
// event piles up: the slip direction of four corners sliding at a speed
// near zero relaxes at ~μ m g r²/(I |v|), beyond any explicit step), and the
// step-size rule opens one time-stepping window at the onset — after 64
// steps within 10 µs (half of stall_steps = 128 in a hundredth of
// stall_time) since stop 52; after it the events slide the box on to the
// closed form v(t) = k (t − t*)²/(2m). The events alone take 12 000 –
// 22 000 steps for 0.7 s (docs/contacts.md §8, known limit (2)); issue 37
// asks ≤ 1 000 under auto (the work rule alone took ~3 400; with the step
// rule at 500 steps ~700, at 128 steps 219, with the 64-step rule 155 here).
TEST(ContactTimeStepping, BoxPushedUnderAutoTakesOneWindowAtItsOnset) {
  const double mu = 0.5, k = 30.0, T = 0.7, t_star = mu * kMass * kG / k;
  BoxScene s = box(0, ContactKind::Rolling, mu);
  Simulator sim(s.model, s.constraints, makeSolver(Formulation::Tree, s.model, s.constraints),
                IntegratorType::DormandPrince54, {}, scheme(ContactScheme::Auto));
  sim.setJointForces([&](double t, const VecX& q, const VecX&, VecX& tau) {
    tau.tail<3>() = floatingRotation(q, 0).transpose() * Vec3(k * t, 0, 0);
  });
  ASSERT_TRUE(sim.setState(0, s.q0, s.v0)) << sim.lastStateError();
  double h = 1e-3, t_window = -1;
  while (sim.time() < T - 1e-12) {
    const StepStatus st = sim.step(std::min(h, T - sim.time()));
    ASSERT_TRUE(st.ok) << st.message;
    h = st.h_next > 0 ? st.h_next : h;
    if (t_window < 0 && sim.counters().windows > 0) t_window = sim.time();
  }
  std::cout << sim.counters().steps << " steps (" << sim.counters().rejected << " rejected), "
            << sim.counters().timestepping_steps << " time-stepped, window at t = " << t_window << "\n";
  EXPECT_EQ(sim.counters().windows, 1);
  EXPECT_EQ(sim.windowReason().rfind("the step size collapsed: the last 64 steps", 0), 0u)
      << sim.windowReason();
  EXPECT_NEAR(t_window, t_star, 2e-3) << "at the slip onset";
  const double v = k * (T - t_star) * (T - t_star) / (2 * kMass);
  EXPECT_NEAR(worldLinear(sim).x(), v, 1e-3 * v) << "the window's O(h) error only";
  EXPECT_LE(sim.counters().steps, 1000) << "the events alone: 12 000 – 22 000";
}
