// One constrained evaluation of the one-body rolling disk (issue: speed at
// the limit) and its parts: the rows (geometry, spatial Jacobian, forward
// kinematics), the tree solve for v̇, both together as an integrator's stage
// does them (the kinematics once, with the rows), and plain ABA of the same
// free body — what the constrained evaluation is measured against. The disk: m = 1 kg, R = 0.5 m on z = 0,
// g = 9.81, tilted 0.3 rad, spinning 5 rad/s about its axle (the peers'
// spin case, bench/peers).
//
//   build/bench/bm_evaluation --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <appell/appell.hpp>

#include "rolling_disk.hpp"

using namespace appell;
using namespace appell::scenes;

namespace {

const BuiltScene& disk() {
  static const BuiltScene s = [] {
    RollingDiskParams p;
    p.radius = 0.5;
    p.mass = 1.0;
    p.lean = 0.3;
    p.axle_rate = 5.0;
    return rollingDisk(p);
  }();
  return s;
}

struct Evaluation {
  const BuiltScene& s = disk();
  ConstraintData cd{s.model, s.constraints, DenseRows::None};
  Data data{s.model};
  std::unique_ptr<ConstrainedSolver> solver = makeSolver(Formulation::Tree, s.model, s.constraints);
  VecX tau = VecX::Zero(s.model.nv);
  ConstrainedResult res;
  void rows() { evaluateConstraintRows(s.model, data, s.constraints, cd, 0.0, s.q0, s.v0); }
  void solve() {
    solver->solve(s.model, data, s.constraints, cd, s.q0, s.v0, tau, res, SolveOutputs::Accelerations);
  }
};

void BM_DiskRows(benchmark::State& state) {
  Evaluation e;
  for (auto _ : state) {
    e.rows();
    benchmark::DoNotOptimize(e.cd.b.data());
  }
}

// The solve alone, with its forward kinematics (the record cleared, so it
// does not skip them as it does after the rows: BM_DiskEvaluation).
void BM_DiskTreeSolve(benchmark::State& state) {
  Evaluation e;
  e.rows();
  for (auto _ : state) {
    e.data.kinematics_has_v = false;
    e.solve();
    benchmark::DoNotOptimize(e.res.vdot.data());
  }
}

void BM_DiskEvaluation(benchmark::State& state) {
  Evaluation e;
  for (auto _ : state) {
    e.rows();
    e.solve();
    benchmark::DoNotOptimize(e.res.vdot.data());
  }
}

void BM_FreeBodyAba(benchmark::State& state) {
  const BuiltScene& s = disk();
  Data data(s.model);
  const VecX tau = VecX::Zero(s.model.nv);
  for (auto _ : state) benchmark::DoNotOptimize(aba(s.model, data, s.q0, s.v0, tau).data());
}

BENCHMARK(BM_DiskRows);
BENCHMARK(BM_DiskTreeSolve);
BENCHMARK(BM_DiskEvaluation);
BENCHMARK(BM_FreeBodyAba);

}  // namespace
