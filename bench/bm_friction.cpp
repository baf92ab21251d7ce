// What sliding friction costs (docs/contacts.md §8).
//
// BM_SlidingStep/<N>/<k>: one Simulator step (RK4, h = 1e-4) of the fleet
// scaling scene — N bodies, N/3 differential-drive robots, wheel tyres with
// μ = 0.5 — with k wheel contacts sliding (k/2 robots started sideways at
// 0.5 m/s, so both their tyres slip laterally) against the same step with
// every tyre sticking (all robots at rest), the two interleaved in one loop.
// Counters: `sliding_over_sticking` (time ratio) and `per_k_n`, the extra
// time per sliding contact per body (ns): flat across N and k when the
// sliding solve is O(k n). The sliding forces are superposed on the
// scene's own solver (friction.cpp): k + 2 tree solves per evaluation
// instead of one. Both restart every 100 steps (the slips shrink by μ g h
// per step, 5 % over 100 steps: still sliding).
#include <appell/contacts.hpp>
#include <appell/simulator.hpp>

#include <benchmark/benchmark.h>

#include "fleet.hpp"

#include <chrono>

namespace {

using namespace appell;
using Clock = std::chrono::steady_clock;

struct FrictionFleet {
  scenes::ScalingScene scene;
  VecX v_sliding, v_sticking;
};

FrictionFleet frictionFleet(int bodies, int sliding) {
  FrictionFleet f;
  f.scene = scenes::fleet(std::max(1, bodies / 3));
  for (auto& c : f.scene.constraints) {
    const auto& contact = static_cast<const ShapeContact&>(*c);
    if (contact.spec().kind != ContactKind::Rolling) continue;
    ContactSpec spec = contact.spec();
    spec.mu = 0.5;
    c = makeContact(spec);
  }
  f.v_sticking = VecX::Zero(f.scene.model.nv);
  f.v_sliding = f.v_sticking;
  int robots = 0;
  for (int i = 0; i < f.scene.model.nbodies && 2 * robots < sliding; ++i) {
    const Joint& j = f.scene.model.joints[i];
    if (j.type != JointType::Floating) continue;
    f.v_sliding[j.idx_v + 4] = 0.5;  // body y: sideways, both tyres slip
    ++robots;
  }
  return f;
}

std::unique_ptr<Simulator> simulator(const FrictionFleet& f, const VecX& v) {
  auto sim = std::make_unique<Simulator>(
      f.scene.model, f.scene.constraints,
      makeSolver(Formulation::Tree, f.scene.model, f.scene.constraints), IntegratorType::RK4);
  sim->setState(0, f.scene.q, v);
  return sim;
}

void BM_SlidingStep(benchmark::State& st) {
  const int n = static_cast<int>(st.range(0)), k = static_cast<int>(st.range(1));
  const FrictionFleet f = frictionFleet(n, k);
  auto sliding = simulator(f, f.v_sliding), sticking = simulator(f, f.v_sticking);
  int slides = 0;
  for (int c = 0; c < static_cast<int>(f.scene.constraints.size()); ++c)
    slides += sliding->constraintData().isSliding(c);
  if (slides != k) {
    st.SkipWithError("the fleet does not start with k sliding tyres");
    return;
  }
  const double h = 1e-4;
  double t_slide = 0, t_stick = 0;
  long steps = 0;
  for (auto _ : st) {
    if (++steps % 100 == 0) {
      sliding->setState(0, f.scene.q, f.v_sliding);
      sticking->setState(0, f.scene.q, f.v_sticking);
    }
    const auto t0 = Clock::now();
    const StepStatus a = sliding->step(h);
    const auto t1 = Clock::now();
    const StepStatus b = sticking->step(h);
    const auto t2 = Clock::now();
    if (!a.ok || !b.ok || a.events || b.events) {
      st.SkipWithError("a step failed or an event happened");
      return;
    }
    t_slide += std::chrono::duration<double>(t1 - t0).count();
    t_stick += std::chrono::duration<double>(t2 - t1).count();
  }
  st.counters["sliding_over_sticking"] = t_slide / t_stick;
  st.counters["per_k_n"] = 1e9 * (t_slide - t_stick) / steps / (static_cast<double>(k) * n);
}
BENCHMARK(BM_SlidingStep)
    ->ArgsProduct({{64, 256, 1024}, {2, 8, 32}})
    ->ArgNames({"N", "k"})
    ->Unit(benchmark::kMicrosecond);

}  // namespace
