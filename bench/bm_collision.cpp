// What FCL's geometry costs against the analytic contact geometry, per
// contact evaluation (docs/contacts.md §9), what a resting box's eight
// vertex contacts cost per step, and what a second point of a pair on a
// terrain (ContactSpec::points, §4) costs per step.
//
//   build/bench/bm_collision --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <appell/collision.hpp>
#include <appell/simulator.hpp>
#include <appell/vertex_contacts.hpp>

#include "ball.hpp"
#include "rolling_disk.hpp"

using namespace appell;
using namespace appell::scenes;

namespace {

const SE3 kDiskPose{axisAngle(Vec3::UnitX(), 1.2), Vec3(0.1, 0.2, 0.5)};
const Vec6 kTwist = (Vec6() << 0.3, -1.0, 2.0, 0.5, 0.1, 0.0).finished();

const Support& ground() {
  static const Support s{Plane{}, StaticMotion{}, "ground"};
  return s;
}

// A 64 × 64 grid over [−8, 8]², 2 triangles per cell, heights z(i, j).
template <class Height>
TerrainMesh grid(Height z) {
  std::vector<Vec3> v;
  std::vector<std::array<int, 3>> t;
  const int n = 64;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) v.emplace_back(-8 + 16.0 * i / n, -8 + 16.0 * j / n, z(i, j));
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i;
      t.push_back({a, a + 1, a + n + 2});
      t.push_back({a, a + n + 2, a + n + 1});
    }
  return makeTerrain(v, t);
}

const Support& terrain() {  // gently rolling
  static const Support s{
      grid([](int i, int j) { return 0.05 * std::sin(0.7 * i) * std::cos(0.5 * j); }),
      StaticMotion{}, "terrain"};
  return s;
}

void analytic(benchmark::State& state, const Shape& shape, const SE3& pose,
              const Support& support = ground()) {
  const auto contact = makeContact(ContactKind::Rolling, 0, shape, support);
  ContactGeometry g;
  for (auto _ : state) {
    contact->geometry(pose, kTwist, 0.0, g);
    benchmark::DoNotOptimize(g.gap);
  }
}

void fcl(benchmark::State& state, const Shape& shape, const Support& support, const SE3& pose) {
  const auto body = makeCollisionGeometry(shape);
  const auto surface = makeCollisionGeometry(support);
  for (auto _ : state) {
    const Proximity p = proximity(*body, pose, *surface, SE3::Identity());
    benchmark::DoNotOptimize(p.distance);
  }
}

void BM_AnalyticSphereOnPlane(benchmark::State& s) {
  analytic(s, Sphere{0.1, Vec3::Zero()}, SE3{Mat3::Identity(), Vec3(0.1, 0.2, 0.3)});
}
void BM_FclSphereOnPlane(benchmark::State& s) {
  fcl(s, Sphere{0.1, Vec3::Zero()}, ground(), SE3{Mat3::Identity(), Vec3(0.1, 0.2, 0.3)});
}
void BM_AnalyticDiskOnPlane(benchmark::State& s) {
  analytic(s, Disk{0.5, Vec3::Zero(), Vec3::UnitZ()}, kDiskPose);
}
void BM_FclDiskOnPlane(benchmark::State& s) {
  fcl(s, Disk{0.5, Vec3::Zero(), Vec3::UnitZ()}, ground(), kDiskPose);
}
void BM_FclBoxOnPlane(benchmark::State& s) {
  fcl(s, Box{Vec3(0.2, 0.1, 0.05), SE3::Identity()}, ground(), kDiskPose);
}
void BM_AnalyticSphereOnTerrain(benchmark::State& s) {
  analytic(s, Sphere{0.1, Vec3::Zero()}, SE3{Mat3::Identity(), Vec3(0.31, 0.22, 0.3)}, terrain());
}
void BM_AnalyticEllipsoidOnTerrain(benchmark::State& s) {
  // Faces, then edges and vertices (every shape but the sphere), 0.2 m above.
  analytic(s, Ellipsoid{Vec3(0.1, 0.08, 0.06), Vec3::Zero(), Mat3::Identity()},
           SE3{Mat3::Identity(), Vec3(0.31, 0.22, 0.3)}, terrain());
}
void BM_FclSphereOnTerrain(benchmark::State& s) {
  fcl(s, Sphere{0.1, Vec3::Zero()}, terrain(), SE3{Mat3::Identity(), Vec3(0.31, 0.22, 0.3)});
}
void BM_FclBoxOnTerrain(benchmark::State& s) {
  fcl(s, Box{Vec3(0.2, 0.1, 0.05), SE3::Identity()}, terrain(),
      SE3{Mat3::Identity(), Vec3(0.31, 0.22, 0.3)});
}

BENCHMARK(BM_AnalyticSphereOnPlane);
BENCHMARK(BM_FclSphereOnPlane);
BENCHMARK(BM_AnalyticDiskOnPlane);
BENCHMARK(BM_FclDiskOnPlane);
BENCHMARK(BM_FclBoxOnPlane);
BENCHMARK(BM_AnalyticSphereOnTerrain);
BENCHMARK(BM_AnalyticEllipsoidOnTerrain);
BENCHMARK(BM_FclSphereOnTerrain);
BENCHMARK(BM_FclBoxOnTerrain);

// One RK4 step (h = 1e-3, tree solver) per iteration of a body started at
// rest at q.
void timeRestingSteps(benchmark::State& state, const Model& model,
                      const ConstraintList& constraints, const VecX& q) {
  Simulator sim(model, constraints, makeSolver(Formulation::Tree, model, constraints),
                IntegratorType::RK4);
  if (!sim.setState(0, q, VecX::Zero(model.nv))) state.SkipWithError(sim.lastStateError().c_str());
  for (auto _ : state) {
    const StepStatus st = sim.step(1e-3);
    if (!st.ok) state.SkipWithError(st.message.c_str());
  }
}

// A box resting on its four lower corners (8 vertex contacts, 4 closed with
// 3 rows each, redundant): one RK4 step, against a sphere resting on one
// rolling contact — what a non-smooth body at rest costs per step.
void restingStep(benchmark::State& state, bool box) {
  ModelBuilder b;
  b.addBody("body", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(),
            principalInertia(2.0, Vec3(0.01, 0.03, 0.03)), "free");
  const Model model = b.build();
  ConstraintList constraints;
  ContactSpec spec;
  spec.kind = ContactKind::Rolling;
  spec.body = 0;
  spec.support = ground();
  spec.options.name = "c";
  double z = 0.05;
  if (box) {
    spec.shape = Box{Vec3(0.2, 0.1, 0.05), SE3::Identity()};
    for (auto& c : makeVertexContacts(spec)) constraints.push_back(c);
  } else {
    spec.shape = Sphere{0.05, Vec3::Zero()};
    constraints.push_back(makeContact(spec));
  }
  VecX q = neutralConfiguration(model);
  q[2] = z;
  timeRestingSteps(state, model, constraints, q);
}
// A ball (or an ellipsoid: the face model) resting on a flat 64 × 64-cell
// terrain, declared with 1 or 2 points: one RK4 step. The second point is
// open and watches for a separate piece within its reach every step end
// (none: the flat patch is one region, which the first point holds).
void terrainPointsStep(benchmark::State& state) {
  const bool ellipsoid = state.range(0) == 1;
  const int points = static_cast<int>(state.range(1));
  static const Support flat{grid([](int, int) { return 0.0; }), StaticMotion{}, "flat"};
  ModelBuilder b;
  b.addBody("ball", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(),
            principalInertia(1.0, Vec3::Constant(0.004)), "free");
  const Model model = b.build();
  ContactSpec spec;
  spec.kind = ContactKind::Rolling;
  spec.body = 0;
  spec.support = flat;
  spec.points = points;
  spec.options.name = "c";
  if (ellipsoid) spec.shape = Ellipsoid{Vec3::Constant(0.1), Vec3::Zero(), Mat3::Identity()};
  else spec.shape = Sphere{0.1, Vec3::Zero()};
  ConstraintList constraints;
  for (auto& c : makeContactPoints(spec)) constraints.push_back(c);
  VecX q = neutralConfiguration(model);
  q.head<3>() = Vec3(0.31, 0.22, 0.1);
  timeRestingSteps(state, model, constraints, q);
  state.SetLabel(std::string(ellipsoid ? "ellipsoid" : "sphere") + ", " + std::to_string(points) +
                 (points > 1 ? " points" : " point"));
}
BENCHMARK(terrainPointsStep)->Name("BM_TerrainPointsStep")->ArgsProduct({{0, 1}, {1, 2}});

void BM_RestingSphereStep(benchmark::State& s) { restingStep(s, false); }
void BM_RestingBoxStep(benchmark::State& s) { restingStep(s, true); }
BENCHMARK(BM_RestingSphereStep);
BENCHMARK(BM_RestingBoxStep);

}  // namespace
