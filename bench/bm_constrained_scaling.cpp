// Constrained-dynamics solve per step on the scaling scenes (tests/fixtures):
// the O(n + m) tree solver against an unconstrained ABA on the same tree and
// the dense KKT and Appell/Maggi references, for N = 8 … 1024 bodies.
// Counters: ns_per_body (time per solve / bodies), bodies, rows.
// BM_TreeOverAba interleaves one tree solve and one aba() on the same state in
// every iteration and reports the ratio of their summed times: both see the
// same machine state (clock, neighbours, caches), so the ratio stays stable
// when the absolute times of separate runs drift. It times the solve an
// integrator stage makes (SolveOutputs::Accelerations: v̇, as ABA gives);
// BM_TreeLambdaOverAba the same with the minimum-norm λ and Aᵀλ (what a report
// or a step's end state asks for).
// BM_TreeLoops: the cost of k loop-closing rows over the same tree solve.
// The dense solvers stop at 256 bodies (O(n³); the comparison point is 256).
// Each iteration evaluates nothing: the rows are evaluated once at a state
// whose velocity satisfies them, and the solve alone is timed — with its
// forward kinematics: the kinematics record is cleared before each solve, so
// the solve does not skip them as it does after the rows of an integrator
// stage (forwardKinematicsIfStale), and the ratio to aba() is like for like.
#include <appell/appell_maggi.hpp>
#include <appell/custom_constraint.hpp>
#include <appell/kkt.hpp>
#include <appell/tree_solver.hpp>

#include "car_row.hpp"
#include "fleet.hpp"
#include "ntrailer.hpp"
#include "wheeled_snake.hpp"

#include <benchmark/benchmark.h>

#include <chrono>

using namespace appell;

namespace {

/// Scene of about `bodies` bodies.
scenes::ScalingScene makeScene(int kind, int bodies) {
  switch (kind) {
    case 0: return scenes::nTrailer(std::max(1, bodies - 1));
    case 1: return scenes::wheeledSnake(std::max(1, bodies / 3));
    case 2: return scenes::fleet(std::max(1, bodies / 3));
    default: return scenes::carRow(std::max(1, bodies / 5));
  }
}

enum class Which { Tree, Aba, Kkt, Appell, TreeOverAba, TreeLambdaOverAba };

void run(benchmark::State& st, Which which) {
  auto s = makeScene(static_cast<int>(st.range(0)), static_cast<int>(st.range(1)));
  Data data(s.model);
  ConstraintData cd(s.model, s.constraints);
  std::unique_ptr<ConstrainedSolver> solver;
  switch (which) {
    case Which::Tree:
    case Which::Aba:
    case Which::TreeOverAba:
    case Which::TreeLambdaOverAba: solver = makeTreeSolver(s.model, s.constraints); break;
    case Which::Kkt: solver = std::make_unique<KktSolver>(s.model, s.constraints); break;
    case Which::Appell: solver = std::make_unique<AppellSolver>(s.model, s.constraints); break;
  }
  evaluateConstraints(s.model, data, s.constraints, cd, 0.0, s.q, s.v);
  VecX v = s.v, mu;
  if (!solver->projectVelocity(s.model, data, s.constraints, cd, s.q, v, mu)) {
    st.SkipWithError("projection failed");
    return;
  }
  evaluateConstraints(s.model, data, s.constraints, cd, 0.0, s.q, v);
  const VecX tau = VecX::Constant(s.model.nv, 0.1);
  ConstrainedResult out;
  // Each timed solve forms its kinematics and factor anew, as at a new state
  // (otherwise the record of the last solve would let it skip both).
  auto* tree = dynamic_cast<TreeSolver*>(solver.get());
  auto fresh = [&] {
    data.kinematics_has_v = false;
    if (tree) tree->forgetFactor();
  };
  if (which == Which::Aba) {
    for (auto _ : st) benchmark::DoNotOptimize(aba(s.model, data, s.q, v, tau).data());
  } else if (which == Which::TreeOverAba || which == Which::TreeLambdaOverAba) {
    const SolveOutputs outputs =
        which == Which::TreeOverAba ? SolveOutputs::Accelerations : SolveOutputs::All;
    using Clock = std::chrono::steady_clock;
    double tree_s = 0, aba_s = 0;
    for (auto _ : st) {
      fresh();
      const auto t0 = Clock::now();
      solver->solve(s.model, data, s.constraints, cd, s.q, v, tau, out, outputs);
      benchmark::DoNotOptimize(out.vdot.data());
      const auto t1 = Clock::now();
      benchmark::DoNotOptimize(aba(s.model, data, s.q, v, tau).data());
      const auto t2 = Clock::now();
      tree_s += std::chrono::duration<double>(t1 - t0).count();
      aba_s += std::chrono::duration<double>(t2 - t1).count();
    }
    st.counters["tree_over_aba"] = tree_s / aba_s;
  } else {
    solver->solve(s.model, data, s.constraints, cd, s.q, v, tau, out);
    if (!out.ok) {
      st.SkipWithError(out.error.c_str());
      return;
    }
    for (auto _ : st) {
      fresh();
      solver->solve(s.model, data, s.constraints, cd, s.q, v, tau, out);
      benchmark::DoNotOptimize(out.vdot.data());
    }
  }
  st.counters["bodies"] = s.model.nbodies;
  st.counters["rows"] = cd.m;
  st.counters["ns_per_body"] = benchmark::Counter(
      static_cast<double>(st.iterations()) * s.model.nbodies * 1e-9,
      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void sizes(benchmark::internal::Benchmark* b, int max_bodies) {
  for (int kind = 0; kind < 4; ++kind)
    for (int n = 8; n <= max_bodies; n *= 2) b->Args({kind, n});
  b->ArgNames({"scene", "N"});
  b->Unit(benchmark::kMicrosecond);
}

void BM_Tree(benchmark::State& st) { run(st, Which::Tree); }
void BM_Aba(benchmark::State& st) { run(st, Which::Aba); }
void BM_Kkt(benchmark::State& st) { run(st, Which::Kkt); }
void BM_Appell(benchmark::State& st) { run(st, Which::Appell); }
void BM_TreeOverAba(benchmark::State& st) { run(st, Which::TreeOverAba); }
void BM_TreeLambdaOverAba(benchmark::State& st) { run(st, Which::TreeLambdaOverAba); }

/// Loop rows: the fleet (N bodies) with the left wheels of robots 0 … k
/// geared together (joint-space rows q̇_L(r) − q̇_L(r+1) = 0, an electronic
/// line shaft) — k rows that close loops through the world, solved by k unit
/// replays and the square root of their Schur complement (O(k n)). Each
/// iteration interleaves a solve with these rows and one of the same fleet
/// without them; the counter is the ratio of their summed times.
void BM_TreeLoops(benchmark::State& st) {
  const int k = static_cast<int>(st.range(1));
  auto s = scenes::fleet(std::max(k + 1, static_cast<int>(st.range(0)) / 3));
  std::vector<int> left;
  for (int i = 0; i < s.model.nbodies; ++i)
    if (s.model.body_names[i].back() == 'L') left.push_back(s.model.joints[i].idx_v);
  ConstraintList loops = s.constraints;
  for (int r0 = 0; r0 < k; r0 += 6) {  // custom constraints hold at most 6 rows
    const int m = std::min(6, k - r0);
    CustomRows spec;
    spec.name = "line_shaft" + std::to_string(r0 / 6);
    spec.rows = m;
    spec.A_b = [left, r0, m](const Model&, const VecX&, double, Eigen::Ref<MatX> A,
                             Eigen::Ref<VecX> b) {
      A.setZero();
      b.setZero();
      for (int r = 0; r < m; ++r) A(r, left[r0 + r]) = 1, A(r, left[r0 + r + 1]) = -1;
    };
    spec.bias = [](const Model&, const VecX&, const VecX&, double, Eigen::Ref<VecX> ab) {
      ab.setZero();
    };
    loops.push_back(std::make_shared<CustomConstraint>(spec));
  }

  Data data(s.model);
  ConstraintData cd(s.model, s.constraints), cdl(s.model, loops);
  TreeSolver plain(s.model, s.constraints), closed(s.model, loops);
  evaluateConstraints(s.model, data, loops, cdl, 0.0, s.q, s.v);
  VecX v = s.v, mu;
  if (!closed.projectVelocity(s.model, data, loops, cdl, s.q, v, mu)) {
    st.SkipWithError(closed.lastError().c_str());
    return;
  }
  evaluateConstraints(s.model, data, s.constraints, cd, 0.0, s.q, v);
  evaluateConstraints(s.model, data, loops, cdl, 0.0, s.q, v);
  const VecX tau = VecX::Constant(s.model.nv, 0.1);
  ConstrainedResult out;
  closed.solve(s.model, data, loops, cdl, s.q, v, tau, out);
  if (!out.ok) {
    st.SkipWithError(out.error.c_str());
    return;
  }
  using Clock = std::chrono::steady_clock;
  double loop_s = 0, plain_s = 0;
  for (auto _ : st) {
    closed.forgetFactor();  // each solve forms its factor anew, as at a new state
    plain.forgetFactor();
    const auto t0 = Clock::now();
    closed.solve(s.model, data, loops, cdl, s.q, v, tau, out);
    benchmark::DoNotOptimize(out.vdot.data());
    const auto t1 = Clock::now();
    plain.solve(s.model, data, s.constraints, cd, s.q, v, tau, out);
    benchmark::DoNotOptimize(out.vdot.data());
    const auto t2 = Clock::now();
    loop_s += std::chrono::duration<double>(t1 - t0).count();
    plain_s += std::chrono::duration<double>(t2 - t1).count();
  }
  st.counters["loops_over_tree"] = loop_s / plain_s;
  st.counters["bodies"] = s.model.nbodies;
  st.counters["loop_rows"] = k;
}

}  // namespace

// scene: 0 N-trailer, 1 wheeled snake, 2 fleet, 3 car row.
BENCHMARK(BM_Tree)->Apply([](auto* b) { sizes(b, 1024); });
BENCHMARK(BM_Aba)->Apply([](auto* b) { sizes(b, 1024); });
BENCHMARK(BM_Kkt)->Apply([](auto* b) { sizes(b, 256); });
BENCHMARK(BM_Appell)->Apply([](auto* b) { sizes(b, 256); });
BENCHMARK(BM_TreeOverAba)->Apply([](auto* b) { sizes(b, 1024); });
BENCHMARK(BM_TreeLambdaOverAba)->Apply([](auto* b) { sizes(b, 1024); });
BENCHMARK(BM_TreeLoops)
    ->ArgsProduct({{64, 256, 1024}, {1, 4, 16}})
    ->ArgNames({"N", "k"})
    ->Unit(benchmark::kMicrosecond);
