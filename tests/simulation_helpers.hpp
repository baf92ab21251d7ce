// What the simulation tests share: the tight integrator settings that make
// a run's error negligible against the closed forms they check, and a loop
// that steps a simulator to a time collecting its contact events.
#pragma once

#include <appell/simulator.hpp>

#include <gtest/gtest.h>

#include <algorithm>
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

}  // namespace appell::test
