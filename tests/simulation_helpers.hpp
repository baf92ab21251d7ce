// What the simulation tests share: the tight integrator settings that make
// a run's error negligible against the closed forms they check, and a loop
// that steps a simulator to a time collecting its contact events.
#pragma once

#include <appell/simulator.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace appell::test {

/// Dormand–Prince at rtol = atol = 1e-12, steps of at most 0.01 s.
inline IntegratorOptions tightIntegrator() {
  IntegratorOptions o;
  o.rtol = 1e-12;
  o.atol = 1e-12;
  o.h_max = 0.01;
  return o;
}

/// Steps of h (the last one shortened) until t_end; every step must succeed.
/// Returns the contact events of these steps, in order.
inline std::vector<ContactEvent> advanceCollecting(Simulator& sim, double t_end, double h = 1e-2) {
  std::vector<ContactEvent> all;
  while (sim.time() < t_end - 1e-12) {
    const StepStatus st = sim.step(std::min(h, t_end - sim.time()));
    EXPECT_TRUE(st.ok) << st.message;
    if (!st.ok) break;
    all.insert(all.end(), sim.events().begin(), sim.events().end());
  }
  return all;
}

/// What a watched run records: its contact events, the largest
/// |E + impact losses + friction work − E₀| at the ends of its steps, and a
/// value read at the first lift-off (NaN when nothing lifted off).
struct WatchedRun {
  std::vector<ContactEvent> events;
  double worst_energy = 0;
  double at_lift_off = std::nan("");
  std::vector<double> at_event;  ///< the value at each event's step end (as events)
  /// The events other than changes of terrain piece, and those changes.
  std::vector<ContactEvent> modeEvents() const { return filtered(false); }
  std::vector<ContactEvent> featureEvents() const { return filtered(true); }
  std::vector<ContactEvent> filtered(bool feature) const {
    std::vector<ContactEvent> out;
    for (const ContactEvent& e : events)
      if ((e.kind == ContactEventKind::Feature) == feature) out.push_back(e);
    return out;
  }
};

/// Steps of h until t_end (every step must succeed), watching the energy
/// balance; `at_lift_off(sim)` is read at the end of the step holding the
/// first lift-off (the step ends at the event).
template <class F>
WatchedRun runWatching(Simulator& sim, double t_end, F&& at_lift_off, double h = 1e-2) {
  WatchedRun run;
  const double E0 = sim.energy();
  while (sim.time() < t_end - 1e-12) {
    const StepStatus st = sim.step(std::min(h, t_end - sim.time()));
    EXPECT_TRUE(st.ok) << st.message;
    if (!st.ok) break;
    for (const ContactEvent& e : sim.events()) {
      run.events.push_back(e);
      run.at_event.push_back(at_lift_off(sim));
      if (e.kind == ContactEventKind::LiftOff && std::isnan(run.at_lift_off))
        run.at_lift_off = run.at_event.back();
    }
    run.worst_energy = std::max(
        run.worst_energy,
        std::abs(sim.energy() + sim.impactEnergyLoss() + sim.frictionWork() - E0));
  }
  return run;
}

/// The message of the std::invalid_argument that make() throws, or
/// "(accepted)" when it throws none.
template <class F>
std::string invalidArgumentMessage(F&& make) {
  try {
    make();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(accepted)";
}

}  // namespace appell::test
