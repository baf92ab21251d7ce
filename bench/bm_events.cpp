// What unilateral contacts cost (docs/contacts.md §7).
//
// BM_EventCheckOverhead/<example>: one Simulator step of an example scene with
// its contacts unilateral (events watched: a sign test per contact on the end
// state the step evaluates anyway) against the same scene with event handling
// off (SimulatorOptions::contacts.enabled = false), the two steps interleaved
// in one loop; counter `unilateral_over_bilateral` is the time ratio. Nothing
// happens in these runs (the contacts stay closed), so the ratio is the price
// of watching. Each loop restarts from the initial state every 200 steps so
// both simulators see the same states.
//
// BM_EventStep/<scene>: the cost of a step that holds an event (location on
// the dense output, the step to it, impact and force problems) against an
// ordinary step of the same scene: counter `event_over_step`. Scenes: the
// rimless wheel, and the rigid car over a bump mesh (examples/car_bump).
#include <appell/run.hpp>
#include <appell/urdf.hpp>

#include <benchmark/benchmark.h>

#include <chrono>
#include <string>

namespace {

using namespace appell;
using Clock = std::chrono::steady_clock;

const char* const kExamples[] = {"rolling_disk/rolling_disk.urdf", "diff_drive/diff_drive.urdf",
                                 "car/car.urdf", "ball_turntable/ball_turntable.urdf",
                                 "car_bump/car_bump.urdf"};

std::string examplePath(const char* rel) { return std::string(APPELL_SOURCE_DIR) + "/examples/" + rel; }

std::unique_ptr<Simulator> simulator(const Scene& scene, bool events) {
  RunOptions o = runOptions(scene.settings);
  IntegratorOptions iopt;
  iopt.rtol = o.tol;
  iopt.atol = o.tol * 1e-2;
  SimulatorOptions sopt;
  sopt.contacts.enabled = events;
  auto sim = std::make_unique<Simulator>(scene.model, scene.constraints,
                                         makeSolver(o.formulation, scene.model, scene.constraints),
                                         IntegratorType::RK4, iopt, sopt);
  if (scene.tau.size() == scene.model.nv) {
    const VecX tau = scene.tau;
    sim->setJointForces([tau](double, const VecX&, const VecX&, VecX& out) { out = tau; });
  }
  sim->setState(0, scene.q0, scene.v0);
  return sim;
}

void BM_EventCheckOverhead(benchmark::State& st) {
  const Scene scene = loadScene(examplePath(kExamples[st.range(0)]));
  auto on = simulator(scene, true), off = simulator(scene, false);
  const double h = 1e-3;
  double t_on = 0, t_off = 0;
  long k = 0;
  for (auto _ : st) {
    if (++k % 200 == 0) {
      on->setState(0, scene.q0, scene.v0);
      off->setState(0, scene.q0, scene.v0);
    }
    const auto t0 = Clock::now();
    const StepStatus a = on->step(h);
    const auto t1 = Clock::now();
    const StepStatus b = off->step(h);
    const auto t2 = Clock::now();
    if (!a.ok || !b.ok || a.events) {
      st.SkipWithError("a step failed or an event happened");
      return;
    }
    t_on += std::chrono::duration<double>(t1 - t0).count();
    t_off += std::chrono::duration<double>(t2 - t1).count();
  }
  st.counters["unilateral_over_bilateral"] = t_on / t_off;
  st.SetLabel(kExamples[st.range(0)]);
}
BENCHMARK(BM_EventCheckOverhead)->DenseRange(0, 4)->Unit(benchmark::kMicrosecond);

// The scenes with events, and how long to run each: the rimless wheel (one
// impact at t ≈ 0.21 s); the car over the bump (its tyres' changes of
// terrain piece, impacts at the ramps' feet, lift-offs at the top edges).
struct EventScene {
  const char* path;
  double duration;
};
const EventScene kEventScenes[] = {{"rimless_wheel/rimless_wheel.urdf", 0.6},
                                   {"car_bump/car_bump.urdf", 2.0}};

void BM_EventStep(benchmark::State& st) {
  const EventScene& which = kEventScenes[st.range(0)];
  const Scene scene = loadScene(examplePath(which.path));
  IntegratorOptions iopt;
  iopt.rtol = 1e-10;
  iopt.atol = 1e-12;
  auto sim = std::make_unique<Simulator>(
      scene.model, scene.constraints, makeSolver(Formulation::Tree, scene.model, scene.constraints),
      IntegratorType::DormandPrince54, iopt);
  double t_event = 0, t_plain = 0;
  long n_event = 0, n_plain = 0;
  for (auto _ : st) {
    sim->setState(0, scene.q0, scene.v0);
    while (sim->time() < which.duration) {
      const auto t0 = Clock::now();
      const StepStatus s = sim->step(1e-2);
      const double dt = std::chrono::duration<double>(Clock::now() - t0).count();
      if (!s.ok) {
        st.SkipWithError(s.message.c_str());
        return;
      }
      if (s.events) {
        t_event += dt;
        ++n_event;
      } else {
        t_plain += dt;
        ++n_plain;
      }
    }
  }
  st.counters["event_over_step"] = (t_event / n_event) / (t_plain / n_plain);
  st.counters["events_per_run"] = static_cast<double>(n_event) / st.iterations();
  st.SetLabel(which.path);
}
BENCHMARK(BM_EventStep)->DenseRange(0, 1)->Unit(benchmark::kMillisecond);

}  // namespace


