// Unconstrained dynamics kernels: RNEA (inverse dynamics), CRBA (mass
// matrix), ABA (forward dynamics) on chains and balanced binary trees of
// 8 … 1024 bodies with revolute joints, each with a fixed or a floating base.
//
// The per_body counter is CPU time per call divided by the number of bodies
// (printed as e.g. "45.2ns"): flat for the O(n) RNEA and ABA, growing with depth
// for CRBA (O(n·depth): O(n²) on a chain, O(n log n) on a balanced tree).
#include <appell/appell.hpp>

#include <benchmark/benchmark.h>

#include <random>
#include <string>

using namespace appell;

namespace {

enum class Topology { Chain, BinaryTree };

/// n bodies with revolute joints (axes cycling x, y, z); body i hangs from
/// i − 1 (chain) or from (i − 1)/2 (binary tree). With `floating`, body 0 is
/// attached to the world by a free joint instead.
Model makeModel(Topology topo, int n, bool floating) {
  ModelBuilder b;
  const Vec3 axes[3] = {Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ()};
  for (int i = 0; i < n; ++i) {
    const int parent = i == 0 ? -1 : topo == Topology::Chain ? i - 1 : (i - 1) / 2;
    SE3 X;
    X.p = i == 0 ? Vec3::Zero() : Vec3(0.05, 0.02, -0.3);
    const Inertia I{1.0, Vec3(0.01, 0.0, -0.15), Vec3(0.02, 0.021, 0.005).asDiagonal()};
    const JointType type = i == 0 && floating ? JointType::Floating : JointType::Revolute;
    b.addBody("b" + std::to_string(i), parent, X, type, axes[i % 3], I);
  }
  return b.build();
}

struct Fixture {
  Model model;
  Data data;
  VecX q, v, a;
  Fixture(Topology topo, int n, bool floating)
      : model(makeModel(topo, n, floating)), data(model) {
    std::mt19937 rng(42);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    q = randomConfiguration(model, rng);
    v.resize(model.nv);
    a.resize(model.nv);
    for (int k = 0; k < model.nv; ++k) {
      v[k] = u(rng);
      a[k] = u(rng);
    }
  }
};

void setCounters(benchmark::State& state, int n) {
  // An inverted per-iteration rate of n bodies: CPU seconds per body, which the
  // console prints with an SI prefix, e.g. "45.2ns" (JSON: seconds).
  state.counters["per_body"] = benchmark::Counter(
      n, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["bodies"] = n;
}

template <Topology topo, bool floating>
void BM_RNEA(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  Fixture f(topo, n, floating);
  for (auto _ : state) {
    benchmark::DoNotOptimize(rnea(f.model, f.data, f.q, f.v, f.a).data());
    benchmark::ClobberMemory();
  }
  setCounters(state, n);
}

template <Topology topo, bool floating>
void BM_CRBA(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  Fixture f(topo, n, floating);
  for (auto _ : state) {
    benchmark::DoNotOptimize(crba(f.model, f.data, f.q).data());
    benchmark::ClobberMemory();
  }
  setCounters(state, n);
}

template <Topology topo, bool floating>
void BM_ABA(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  Fixture f(topo, n, floating);
  for (auto _ : state) {
    benchmark::DoNotOptimize(aba(f.model, f.data, f.q, f.v, f.a).data());
    benchmark::ClobberMemory();
  }
  setCounters(state, n);
}

constexpr auto Chain = Topology::Chain;
constexpr auto Tree = Topology::BinaryTree;

}  // namespace

#define APPELL_DYNAMICS_BENCH(fn)                                                           \
  BENCHMARK_TEMPLATE(fn, Chain, false)->Name(#fn "/chain")->RangeMultiplier(2)->Range(8, 1024); \
  BENCHMARK_TEMPLATE(fn, Tree, false)->Name(#fn "/tree")->RangeMultiplier(2)->Range(8, 1024);   \
  BENCHMARK_TEMPLATE(fn, Chain, true)->Name(#fn "/chain_floating")->RangeMultiplier(2)->Range(8, 1024); \
  BENCHMARK_TEMPLATE(fn, Tree, true)->Name(#fn "/tree_floating")->RangeMultiplier(2)->Range(8, 1024)

APPELL_DYNAMICS_BENCH(BM_RNEA);
APPELL_DYNAMICS_BENCH(BM_CRBA);
APPELL_DYNAMICS_BENCH(BM_ABA);
