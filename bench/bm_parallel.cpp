// Throughput of many independent simulations on 1 and 2 threads.
//
// A Model is immutable and shared; each simulation owns its Data, workspace and
// state (docs/architecture.md: an immutable Model, all mutable data in Data), so independent scenes step in parallel with no locks.
// Each benchmark steps 64 rolling disks by 50 RK4 steps each, split over the
// threads; items/s counts simulation steps. The scaling is the ratio of the
// two items/s figures measured in the same run. Five repetitions by default
// (medians and their coefficient of variation), and the machine's load
// average before the run (in the report's context) and after it (on
// stderr): two threads pay only when both cores are free, so a figure
// without its load says little (bench/results/parallel.md).
#include "rolling_disk.hpp"

#include <appell/simulator.hpp>

#include <benchmark/benchmark.h>

#include <cstdio>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

using namespace appell;

namespace {

constexpr int kSimulations = 64;
constexpr int kSteps = 50;

struct Fleet {
  scenes::BuiltScene scene = scenes::rollingDisk();
  std::vector<std::unique_ptr<Simulator>> sims;
  Fleet() {
    for (int i = 0; i < kSimulations; ++i) {
      sims.push_back(std::make_unique<Simulator>(
          scene.model, scene.constraints,
          makeSolver(Formulation::Tree, scene.model, scene.constraints), IntegratorType::RK4));
    }
  }
  void reset() {
    for (auto& s : sims) s->setState(0, scene.q0, scene.v0);
  }
};

void stepRange(Fleet& fleet, int begin, int end) {
  for (int i = begin; i < end; ++i)
    for (int k = 0; k < kSteps; ++k)
      if (!fleet.sims[i]->step(1e-3).ok) return;
}

void BM_IndependentSimulations(benchmark::State& state) {
  const int threads = static_cast<int>(state.range(0));
  Fleet fleet;
  for (auto _ : state) {
    state.PauseTiming();
    fleet.reset();
    state.ResumeTiming();
    std::vector<std::thread> pool;
    const int per = kSimulations / threads;
    for (int t = 0; t < threads; ++t)
      pool.emplace_back(stepRange, std::ref(fleet), t * per, t == threads - 1 ? kSimulations : (t + 1) * per);
    for (auto& th : pool) th.join();
  }
  state.SetItemsProcessed(state.iterations() * kSimulations * kSteps);
  state.counters["threads"] = threads;
}

}  // namespace

// /proc/loadavg's 1, 5 and 15 minute averages.
std::string loadAverage() {
  std::ifstream f("/proc/loadavg");
  std::string one, five, fifteen;
  f >> one >> five >> fifteen;
  return one + " " + five + " " + fifteen;
}

BENCHMARK(BM_IndependentSimulations)
    ->Arg(1)
    ->Arg(2)
    ->UseRealTime()
    ->Repetitions(5)
    ->Unit(benchmark::kMillisecond);

int main(int argc, char** argv) {
  benchmark::AddCustomContext("load_average_before", loadAverage());
  benchmark::AddCustomContext("hardware_threads", std::to_string(std::thread::hardware_concurrency()));
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  std::fprintf(stderr, "load_average_after: %s\n", loadAverage().c_str());
  return 0;
}
