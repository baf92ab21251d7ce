// The automatic scheme's switches between events and time-stepping windows
// (docs/contacts.md §10) on the done-when scene, the Ackermann CAD car
// (examples/cad_car: one rear wheel 0.2 mm out of line, a steering step at
// t = 2 s that makes every tyre slip): the work balance stays closed across
// a window's close (the hand-back must not jump the state), the switch into
// a window is decided by counts (two runs give the same CSV byte for byte),
// and the wall-clock watchdog only stops runs.
#include <gtest/gtest.h>

#include <appell/output.hpp>
#include <appell/overrides.hpp>
#include <appell/run.hpp>
#include <appell/simulator.hpp>
#include <appell/urdf.hpp>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>

using namespace appell;

namespace {

const std::string kCadCar = std::string(APPELL_SOURCE_DIR) + "/examples/cad_car/cad_car.urdf";

/// The work balance D = E + losses − work in, less its value at t = 0.
struct Balance {
  double d0 = 0;
  bool started = false;
  double operator()(const Simulator& s) const {
    return s.energy() + s.impactEnergyLoss() + s.frictionWork() - s.jointWork() - s.supportWork() - d0;
  }
};

}  // namespace

// Protects the done-when scene under default settings through its steering
// step. At 474a5ed the window's close at t = 2.1015 s was followed by an
// event step that put the balance off by 11.18 J (the car's kinetic energy:
// exit 3 at t = 2.10 s). Now a window closes only at a state the decided
// modes hold; here no close is accepted within 3 s (the car keeps
// steering), and across every step the balance moves by no more than the
// scheme's O(h) per step, and the run reaches its end.
TEST(WindowSwitch, CadCarKeepsItsWorkBalanceThroughItsWindow) {
  const Scene scene = loadScene(kCadCar);
  RunOptions o = runOptions(scene.settings);
  EXPECT_EQ(o.contacts, ContactScheme::Auto);
  o.duration = 3.0;
  o.watchdog_fraction = 0;  // (a loaded machine's wall clock must not stop it)
  Balance balance;
  double last = 0, largest_jump = 0, jump_t = -1;
  ContactScheme previous = ContactScheme::Events;
  int closes = 0;
  const RunSummary s = runScene(scene, o, RunObserver{}, [&](const Simulator& sim) {
    if (!balance.started) {
      balance.d0 = balance(sim);
      balance.started = true;
    }
    const double d = balance(sim);
    if (std::abs(d - last) > largest_jump) {
      largest_jump = std::abs(d - last);
      jump_t = sim.time();
    }
    last = d;
    closes += previous == ContactScheme::TimeStepping && sim.stepScheme() == ContactScheme::Events;
    previous = sim.stepScheme();
  });
  ASSERT_TRUE(s.ok) << s.failure;
  EXPECT_NEAR(s.time, 3.0, 1e-12);
  EXPECT_GE(s.counters.windows, 1) << "the steering step opens a window";
  EXPECT_GT(s.joint_work, 10.0) << "the motors drive the car";
  // Measured: 1.5e-5 of the energy that moved over a window (O(h)); the
  // hand-back's jump was 11.2 J, 0.99 of it.
  EXPECT_LT(s.relativeEnergyDeviation(), 1e-3) << s.max_energy_deviation << " J";
  EXPECT_LT(largest_jump, 1e-3 * s.energy_scale) << "at t = " << jump_t << " (" << closes
                                                 << " window closes)";
}

// Protects the hand-back at the state where it went wrong: the window
// opened where the wall-clock watchdog opened it before 2026-11-27
// (t = 2.00150346173 s, in the stall of the steering step), and the car
// driven on to t = 2.3 s. Every step — a window's close included — moves the
// balance by less than 1e-3 of the energy that moved (the jump was 11.2 J).
TEST(WindowSwitch, CadCarHandBackAfterAWindowOpenedInTheStall) {
  const Scene scene = loadScene(kCadCar);
  RunOptions o = runOptions(scene.settings);
  std::unique_ptr<Simulator> sim = makeSimulator(scene, o);
  Balance balance;
  balance.d0 = balance(*sim);
  double h = o.dt, last = 0, largest_jump = 0, jump_t = -1, scale = 1e-12;
  bool ok = true;
  int closes = 0;
  std::string failure;
  auto stepTo = [&](double T) {
    while (ok && sim->time() < T - 1e-12) {
      const ContactScheme before = sim->stepScheme();
      const StepStatus st = sim->step(std::min(h, T - sim->time()));
      if (!st.ok) {
        ok = false;
        failure = st.message;
        return;
      }
      h = st.h_next > 0 ? st.h_next : h;
      closes += before == ContactScheme::TimeStepping && sim->stepScheme() == ContactScheme::Events;
      const double d = balance(*sim);
      if (std::abs(d - last) > largest_jump) {
        largest_jump = std::abs(d - last);
        jump_t = sim->time();
      }
      last = d;
      scale = std::max({scale, sim->kineticEnergy(), std::abs(sim->jointWork())});
    }
  };
  stepTo(2.00150346173);
  ASSERT_TRUE(ok) << failure;
  if (sim->stepScheme() == ContactScheme::Events)  // (else the stall rule opened one already)
    ASSERT_TRUE(sim->openTimeSteppingWindow("opened by the test where the watchdog opened it"));
  stepTo(2.3);
  ASSERT_TRUE(ok) << failure;
  std::cout << closes << " window closes, largest step in the balance " << largest_jump << " J at t = "
            << jump_t << " s of " << scale << " J\n";
  EXPECT_LT(largest_jump, 1e-3 * scale) << "at t = " << jump_t << " (" << closes << " window closes)";
  EXPECT_LT(std::abs(last), 1e-3 * scale) << "balance off at t = 2.3 s";
}

// Protects the automatic scheme's stall rule: at the CAD car's steering
// step (t = 2 s) every tyre slips, rear_right_tyre chatters and the event
// steps collapse with no further event (no Zeno) — and the automatic scheme
// opens a window there once stall_steps accepted steps (since stop 51; the
// last 128 advanced 0.29 ms) or stall_work units of work (solves and
// friction block updates) advance less than stall_time, whatever the
// machine's load: two runs of one binary write the same CSV byte for byte.
TEST(WindowSwitch, StallRuleOpensAWindowDeterministically) {
  const Scene scene = loadScene(kCadCar);
  RunOptions o = runOptions(scene.settings);
  o.duration = 2.05;
  o.watchdog_fraction = 0;  // (a loaded machine's wall clock must not stop it first)
  std::string csv[2], reason[2];
  RunSummary s[2];
  for (int i = 0; i < 2; ++i) {
    std::ostringstream out;
    TrajectoryWriter writer(out, scene);
    long windows = 0;
    s[i] = runScene(scene, o, writer, [&](const Simulator& sim) {
      if (sim.counters().windows > windows && reason[i].empty()) reason[i] = sim.windowReason();
      windows = sim.counters().windows;
    });
    csv[i] = out.str();
  }
  ASSERT_TRUE(s[0].ok) << s[0].failure;
  EXPECT_GE(s[0].counters.windows, 1);
  EXPECT_TRUE(reason[0].rfind("the step size collapsed: ", 0) == 0 ||
              reason[0].rfind("the steps stalled: ", 0) == 0)
      << reason[0];
  EXPECT_EQ(reason[0], reason[1]);
  EXPECT_GT(csv[0].size(), 1000u);
  EXPECT_TRUE(csv[0] == csv[1]) << "two runs of one binary differ";
}

// Protects the stall rule's measure of work on a stall that an evaluation
// count missed: a car from a random sweep (examples/car, the rear-left tyre
// driven at 6.7 N·m on μ 0.84, the others at their drawn μ), whose driven
// tyre slides at a slip of at most 1.2e-7 m/s from t = 0 and whose event
// steps collapse — dopri5 took 4 320 steps in 0.46 ms, 1.6·10⁸ solves per
// simulated second, below the old rule's 5 000 evaluations per 10 µs, and the
// wall-clock watchdog stopped it (exit 3). Under events it still stalls
// (checked: over 500 steps in 0.1 ms); under auto the rule opens a window
// within its work budget of the stall's start (low progress sustained over
// 2.75 × 10⁵ units of work) — since stop 51 the step-size rule's 128 steps
// come first, within 1.4e-5 s — and the run goes on with its work balance
// closed.
TEST(WindowSwitch, SweptCarWhoseSlipStallsSwitchesWithinItsWorkBudget) {
  Scene scene = loadScene(std::string(APPELL_SOURCE_DIR) + "/examples/car/car.urdf");
  OverrideReport report;
  const std::pair<const char*, double> set[] = {
      {"speed", 2.4985710961287424},           {"front_left_tyre.mu", 0.5553586752304251},
      {"front_right_tyre.mu", 0.6390676315722099}, {"rear_left_tyre.mu", 0.8439139685945805},
      {"rear_right_tyre.mu", 0.5938810795351981},  {"rear_left_joint.effort", 6.692642203185458},
      {"rear_right_joint.effort", -0.7559314787229798}};
  for (const auto& [name, value] : set) applyOverride(scene, name, {value}, report);
  completeVelocities(scene, report);
  RunOptions o = runOptions(scene.settings);
  o.watchdog_fraction = 0;  // (the rule, not the wall clock)
  o.contacts = ContactScheme::Events;
  o.duration = 1e-4;
  const RunSummary events = runScene(scene, o, RunObserver{});
  ASSERT_TRUE(events.ok) << events.failure;
  // (A car at 2.5 m/s takes one step of 1 ms there; this one takes ~900.)
  EXPECT_GT(events.counters.steps, 500) << "the event steps collapse";
  o.contacts = ContactScheme::Auto;
  o.duration = 0.5;
  std::string reason;
  long work_at_switch = -1;
  double t_switch = -1;
  const RunSummary s = runScene(scene, o, RunObserver{}, [&](const Simulator& sim) {
    if (sim.counters().windows == 1 && work_at_switch < 0) {
      reason = sim.windowReason();
      work_at_switch = sim.counters().solves + sim.counters().block_updates;
      t_switch = sim.time();
    }
  });
  ASSERT_TRUE(s.ok) << s.failure;
  EXPECT_NEAR(s.time, 0.5, 1e-12);
  EXPECT_TRUE(reason.rfind("the step size collapsed: ", 0) == 0 ||
              reason.rfind("the steps stalled: ", 0) == 0)
      << reason;
  const TimeSteppingOptions rule;
  // (Low progress over stall_work at 8 marks a quarter of it apart, from
  // the first full stretch: 2.75 stall_work, plus a step's overshoot.)
  EXPECT_LE(work_at_switch, 3 * rule.stall_work) << "the switch within its budget";
  EXPECT_LT(t_switch, rule.stall_time);
  EXPECT_LT(s.relativeEnergyDeviation(), 1e-6) << s.max_energy_deviation << " J";
  EXPECT_GT(s.joint_work, 10.0) << "the driven tyre works on";
}

// Protects the stall watchdog of the run loop: a watchdog that demands more
// simulated time than any run gives (a fraction of 10⁹ of the wall time,
// checked after every step) stops the run with the report — "the run
// stalled", the events per simulated second — under every scheme: the wall
// clock never switches the scheme (a trajectory must not depend on the
// machine's load), the simulator's own stall rule does (above).
TEST(WindowSwitch, StallWatchdogStopsTheRun) {
  const Scene scene = loadScene(std::string(APPELL_SOURCE_DIR) +
                                "/examples/skid_steer_step/skid_steer_step.urdf");
  RunOptions o = runOptions(scene.settings);
  o.duration = 0.05;
  o.watchdog_fraction = 1e9;
  o.watchdog_interval = 1e-12;
  for (ContactScheme c : {ContactScheme::Events, ContactScheme::Auto}) {
    SCOPED_TRACE(toString(c));
    o.contacts = c;
    const RunSummary stopped = runScene(scene, o, RunObserver{});
    ASSERT_FALSE(stopped.ok);
    EXPECT_EQ(stopped.failure.rfind("the run stalled: it advanced ", 0), 0u) << stopped.failure;
    EXPECT_NE(stopped.failure.find("contact events per simulated second"), std::string::npos)
        << stopped.failure;
    EXPECT_EQ(stopped.counters.windows, 0) << "the wall clock opens no window";
    EXPECT_EQ(stopped.counters.steps, 1) << "stopped at the first check";
  }
}
