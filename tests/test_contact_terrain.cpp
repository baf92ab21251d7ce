// Terrain meshes (terrain.hpp): inside a face the contact IS the plane
// contact, so
//   - a flat terrain of many triangles gives the Plane's rows, b, κ and gap,
//     bit for bit up to round-off, for spheres, disks and ellipsoids at
//     random states (a fixed and a tilting support);
//   - a terrain triangulating a tilted plane gives the tilted Plane's;
//   - a ball rolls down a ramp face with the analytic acceleration
//     (5/7) g sin α and conserves energy (dense KKT solve, RK4), and pivots
//     about the crease between two faces, lifting off where theory says;
//   - a URDF with <support type="terrain" filename="….stl"> loads and runs.
// Bad meshes (degenerate triangles, bad indices) are refused by name.
#include "simulation_helpers.hpp"
#include "test_contact_common.hpp"

#include <appell/appell.hpp>
#include <appell/collision.hpp>
#include <appell/constraint_set.hpp>
#include <appell/simulator.hpp>
#include <appell/terrain.hpp>
#include <appell/urdf.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <new>
#include <sstream>

// Counts operator new while g_counting (the terrain query must not allocate:
// no std::vector, std::string or FCL result buffers in evaluate()).
namespace {
std::atomic<long> g_news{0};
std::atomic<bool> g_counting{false};
}  // namespace
// GCC pairs std::free with the replaced operator new as a mismatch; they are
// the same allocator here.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t n) {
  if (g_counting) ++g_news;
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
#pragma GCC diagnostic pop

using namespace appell;
using namespace appell::testing;

namespace {

// A square of side 2·half centred at `origin`, spanned by the orthonormal u, w,
// cut into cells × cells squares of two triangles each, wound so that the
// normals are u × w.
TerrainMesh gridTerrain(const Vec3& origin, const Vec3& u, const Vec3& w, double half, int cells) {
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;
  const double step = 2 * half / cells;
  for (int j = 0; j <= cells; ++j)
    for (int i = 0; i <= cells; ++i)
      vertices.push_back(origin + (-half + i * step) * u + (-half + j * step) * w);
  auto id = [&](int i, int j) { return j * (cells + 1) + i; };
  for (int j = 0; j < cells; ++j)
    for (int i = 0; i < cells; ++i) {
      triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return makeTerrain(std::move(vertices), std::move(triangles));
}

// Rows of the plane contact and the terrain contact at random states near
// contact; counts the states compared.
void compareWithPlane(const Plane& plane, const TerrainMesh& terrain, const SupportMotion& motion,
                      unsigned seed, int& compared) {
  std::mt19937 rng(seed);
  compared = 0;
  double worst = 0;
  for (const ShapeCase& sc : shapeCases()) {
    if (!std::holds_alternative<Sphere>(sc.shape) && !std::holds_alternative<Disk>(sc.shape) &&
        !std::holds_alternative<Ellipsoid>(sc.shape))
      continue;
    for (ContactKind kind : {ContactKind::RollingWithoutSpin, ContactKind::Sliding}) {
      const auto on_plane = makeContact(kind, 0, sc.shape, Support{plane, motion, "plane"});
      const auto on_terrain = makeContact(kind, 0, sc.shape, Support{terrain, motion, "terrain"});
      for (int trial = 0; trial < 40; ++trial) {
        const double t = uniform(rng, 0.0, 2.0);
        const SupportState S = supportState(motion, t);
        SE3 pose;
        ASSERT_TRUE(placeNearContact(sc.shape, plane, S, rng, uniform(rng, -0.05, 0.1), pose));
        Vec6 V;
        V << randomVec(rng, 2.0), randomVec(rng, 1.0);
        RowBlock a, b;
        on_plane->evaluateAt(pose, V, t, a);
        on_terrain->evaluateAt(pose, V, t, b);
        SCOPED_TRACE(sc.name + " " + toString(kind) + " trial " + std::to_string(trial));
        ASSERT_FALSE(b.singular) << b.singular_reason;
        ASSERT_EQ(a.m, b.m);
        EXPECT_LT((a.Wa - b.Wa).cwiseAbs().maxCoeff(), 1e-12);
        EXPECT_LT((a.b - b.b).cwiseAbs().maxCoeff(), 1e-12);
        EXPECT_LT((a.kappa - b.kappa).cwiseAbs().maxCoeff(), 1e-12);
        EXPECT_LT((a.gap - b.gap).cwiseAbs().maxCoeff(), 1e-12);
        EXPECT_LT((a.frame.point - b.frame.point).norm(), 1e-12);
        EXPECT_LT((a.frame.normal - b.frame.normal).norm(), 1e-12);
        EXPECT_NEAR(a.frame.gap, b.frame.gap, 1e-12);
        worst = std::max({worst, (a.Wa - b.Wa).cwiseAbs().maxCoeff(),
                          (a.b - b.b).cwiseAbs().maxCoeff(),
                          (a.kappa - b.kappa).cwiseAbs().maxCoeff(),
                          (a.gap - b.gap).cwiseAbs().maxCoeff()});
        ++compared;
      }
    }
  }
  std::printf("  %d states, max |Δ| over Wa, b, κ, gap = %.3g\n", compared, worst);
}

SinusoidalTiltMotion tilting() {
  SinusoidalTiltMotion m;
  m.point = Vec3(0.3, 0.0, 0.0);
  m.axis = Vec3::UnitX();
  m.amplitude = 0.4;
  m.frequency = 2.1;
  m.phase = 0.3;
  return m;
}

}  // namespace

TEST(ContactTerrain, FlatTerrainGivesThePlaneRows) {
  const TerrainMesh flat = gridTerrain(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 3.0, 12);
  EXPECT_EQ(flat.triangles.size(), 288u);
  {
    int count = 0;
    compareWithPlane(Plane{}, flat, StaticMotion{}, 1, count);
    EXPECT_EQ(count, 3 * 2 * 40);
  }
  {
    int count = 0;
    compareWithPlane(Plane{}, flat, tilting(), 2, count);
    EXPECT_EQ(count, 3 * 2 * 40);
  }
}

TEST(ContactTerrain, TiltedTerrainGivesTheTiltedPlaneRows) {
  const Vec3 n = Vec3(0.1, -0.2, 1.0).normalized(), p0(0.1, 0.2, -0.3);
  const Vec3 u = n.unitOrthogonal(), w = n.cross(u);
  const TerrainMesh tilted = gridTerrain(p0, u, w, 3.0, 9);
  EXPECT_LT((terrainFaceNormal(tilted, 7) - n).norm(), 1e-15);
  {
    int count = 0;
    compareWithPlane(Plane{p0, n}, tilted, StaticMotion{}, 3, count);
    EXPECT_EQ(count, 3 * 2 * 40);
  }
  {
    int count = 0;
    compareWithPlane(Plane{p0, n}, tilted, wobblingMotion(), 4, count);
    EXPECT_EQ(count, 3 * 2 * 40);
  }
}

namespace {

// A flat triangle (face 0, x ≤ 0) and a ramp descending along +x (face 1)
// sharing the edge x = 0: a convex crease.
// tan α = 1/4: the vertices are exact in single precision (assimp's STL reader).
const double kSlope = std::atan(0.25);
TerrainMesh flatAndRamp() {
  return makeTerrain({Vec3(-4, 0, 0), Vec3(0, -3, 0), Vec3(0, 3, 0), Vec3(3, 0, -0.75)},
                     {{0, 1, 2}, {1, 3, 2}});
}

Model ballModel(double mass, double r) {
  ModelBuilder b;
  b.addBody("ball", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(),
            {mass, Vec3::Zero(), Mat3::Identity() * 0.4 * mass * r * r});
  return b.build();
}

// Dense KKT (M v̇ + h = Aᵀλ, A v̇ + abias = 0) and RK4 in local coordinates.
struct DenseSim {
  const Model& model;
  ConstraintList list;
  Data data;
  ConstraintData cd;
  bool saw_singular = false;
  std::string reason;
  DenseSim(const Model& m, ConstraintList l) : model(m), list(std::move(l)), data(m), cd(m, list) {}

  VecX acceleration(double t, const VecX& q, const VecX& v) {
    evaluateConstraints(model, data, list, cd, t, q, v);
    if (cd.singular && !saw_singular) {
      saw_singular = true;
      reason = cd.singular_reason;
      EXPECT_TRUE(cd.A.allFinite() && cd.abias.allFinite() && cd.b.allFinite());
    }
    const MatX M = crba(model, data, q);
    const VecX h = nonLinearEffects(model, data, q, v);
    const int n = model.nv, m = cd.m;
    MatX K = MatX::Zero(n + m, n + m);
    K.topLeftCorner(n, n) = M;
    K.topRightCorner(n, m) = cd.A.transpose();
    K.bottomLeftCorner(m, n) = cd.A;
    VecX rhs(n + m);
    rhs << -h, -cd.abias;
    return Eigen::ColPivHouseholderQR<MatX>(K).solve(rhs).head(n);
  }
  void step(double& t, VecX& q, VecX& v, double dt) {
    const int n = model.nv;
    VecX qs(model.nq), kq[4], kv[4];
    const double c[4] = {0, 0.5, 0.5, 1};
    for (int s = 0; s < 4; ++s) {
      const VecX ths = s == 0 ? VecX(VecX::Zero(n)) : VecX(c[s] * dt * kq[s - 1]);
      const VecX vs = s == 0 ? v : VecX(v + c[s] * dt * kv[s - 1]);
      retract(model, q, ths, qs);
      kq[s].resize(n);
      localRate(model, q, ths, vs, kq[s]);
      kv[s] = acceleration(t + c[s] * dt, qs, vs);
    }
    const VecX th = dt / 6 * (kq[0] + 2 * kq[1] + 2 * kq[2] + kq[3]);
    v += dt / 6 * (kv[0] + 2 * kv[1] + 2 * kv[2] + kv[3]);
    VecX q1(model.nq);
    retract(model, q, th, q1);
    q = q1;
    t += dt;
  }
  double energy(const VecX& q, const VecX& v) {
    return kineticEnergy(model, data, q, v) + potentialEnergy(model, data, q);
  }
};

// Floating state: centre c, identity attitude, centre velocity vc, world ω.
void ballState(const Vec3& c, const Vec3& vc, const Vec3& w, VecX& q, VecX& v) {
  q.resize(7);
  q << c, 0, 0, 0, 1;
  v.resize(6);
  v << w, vc;  // body frame = world frame at identity attitude
}

}  // namespace

TEST(ContactTerrain, BallRollsDownARampFaceWithTheAnalyticAcceleration) {
  const double r = 0.1, mass = 1.0, g = 9.81;
  const Model model = ballModel(mass, r);
  const Support terrain{flatAndRamp(), StaticMotion{}, "terrain"};
  DenseSim sim(model, {makeContact(ContactKind::Rolling, 0, Sphere{r, Vec3::Zero()}, terrain)});
  const Vec3 n(std::sin(kSlope), 0, std::cos(kSlope)), down(std::cos(kSlope), 0, -std::sin(kSlope));
  const Vec3 c0 = Vec3(1.0, 0.2, -std::tan(kSlope)) + r * n;
  VecX q, v;
  ballState(c0, Vec3::Zero(), Vec3::Zero(), q, v);
  double t = 0;
  const double E0 = sim.energy(q, v), dt = 1e-3, T = 0.4;
  for (int k = 0; k < static_cast<int>(T / dt + 0.5); ++k) sim.step(t, q, v, dt);
  EXPECT_FALSE(sim.saw_singular) << sim.reason;
  // Solid ball rolling down a slope: s̈ = (5/7) g sin α.
  const double s = 0.5 * (5.0 / 7.0) * g * std::sin(kSlope) * T * T;
  EXPECT_LT((q.head<3>() - (c0 + s * down)).norm(), 1e-9) << q.head<3>().transpose();
  EXPECT_LT(std::abs(sim.energy(q, v) - E0), 1e-10 * std::abs(E0) + 1e-12);
  std::printf("  ramp: |c − c_analytic| = %.3g m, |ΔE| = %.3g J after %.1f s\n",
              (q.head<3>() - (c0 + s * down)).norm(), std::abs(sim.energy(q, v) - E0), T);
  RowBlock rows;
  const auto& contact = static_cast<const ShapeContact&>(*sim.list[0]);
  SE3 pose;
  pose.R = Quat(q[6], q[3], q[4], q[5]).toRotationMatrix();
  pose.p = q.head<3>();
  contact.evaluateAt(pose, Vec6::Zero(), t, rows);
  EXPECT_LT((rows.frame.normal - n).norm(), 1e-12);  // still on the ramp face
  EXPECT_LT(std::abs(rows.frame.gap), 1e-9);
}

// Protects rolling across a terrain edge (terrain_sphere.cpp): a ball rolling
// at v₀ onto the convex crease between the flat face and the ramp (slope α)
// pivots about the edge — no slip at the edge point, so with I_P = (7/5) m r²
//     φ̇² = (v₀/r)² + (10/7)(g/r)(1 − cos φ),   N = m (g cos φ − r φ̇²),
// and N reaches zero at cos φ* = (7 v₀²/(g r) + 10)/17. Fast enough, it lifts
// off there (the event located to 1e-9 in φ), flies and lands on the ramp;
// slowly, it pivots through α and rolls on down the ramp, with energy
// conserved and no mode event — only its changes of piece, located.
TEST(ContactTerrain, BallPivotsAboutTheCreaseAndLiftsOffWhereTheoryPredicts) {
  const double r = 0.1, mass = 1.0, g = 9.81;
  const Model model = ballModel(mass, r);
  const Support terrain{flatAndRamp(), StaticMotion{}, "terrain"};
  const ConstraintList list{makeContact(ContactKind::Rolling, 0, Sphere{r, Vec3::Zero()}, terrain)};
  for (double v0 : {0.975, 0.5}) {
    SCOPED_TRACE("v0 = " + std::to_string(v0));
    Simulator sim(model, list, makeSolver(Formulation::Tree, model, list),
                  IntegratorType::DormandPrince54, appell::test::tightIntegrator());
    VecX q, v;
    ballState(Vec3(-0.2, 0.1, r), Vec3(v0, 0, 0), Vec3(0, v0 / r, 0), q, v);
    ASSERT_TRUE(sim.setState(0, q, v)) << sim.lastStateError();
    const auto run = appell::test::runWatching(
        sim, 1.0, [](const Simulator& s) { return std::atan2(s.q()[0], s.q()[2]); });
    const auto events = run.modeEvents();
    const double phi_lift = run.at_lift_off;
    EXPECT_LT(run.worst_energy, 1e-8) << "E + impact losses is conserved";
    const Vec3 ramp(std::sin(kSlope), 0, std::cos(kSlope));
    EXPECT_LT((sim.contactFrame(0).normal - ramp).norm(), 1e-9) << "on the ramp at the end";
    if (v0 > 0.9) {
      ASSERT_GE(events.size(), 2u);
      EXPECT_EQ(events[0].kind, ContactEventKind::LiftOff);
      const double phi_star = std::acos((7 * v0 * v0 / (g * r) + 10) / 17);
      EXPECT_NEAR(phi_lift, phi_star, 1e-9) << "lift-off where the normal force vanishes";
      EXPECT_LT(phi_star, kSlope) << "before the ramp could take over";
      EXPECT_EQ(events[1].kind, ContactEventKind::Touchdown) << "lands on the ramp";
    } else {
      // In contact throughout: no lift-off, and no impact beyond the
      // precision of the change of piece onto the ramp (located where the
      // normal leans past the face by ~1e-9, so the ball may meet the face
      // at ~v₀·1e-8 m/s: a touchdown with nothing to absorb).
      for (const ContactEvent& e : events)
        EXPECT_TRUE(e.kind == ContactEventKind::Touchdown && std::abs(e.speed_before) < 1e-8)
            << "a slow ball pivots through the crease in contact (event at t = " << e.t << ")";
      EXPECT_GT(sim.q()[0], 0.3) << "and rolls on down the ramp";
    }
    // Its changes of piece are located events: onto the edge when its
    // centre passes over it (t = 0.2/v₀, φ = 0), and slowly, onto the ramp's
    // face when it has pivoted through the slope (φ = α).
    const auto pieces = run.featureEvents();
    ASSERT_EQ(pieces.size(), v0 > 0.9 ? 1u : 2u);
    EXPECT_NEAR(pieces[0].t, 0.2 / v0, 1e-11) << "onto the edge";
    EXPECT_NEAR(run.at_event[0], 0, 1e-11);
    if (v0 < 0.9) {
      EXPECT_NEAR(run.at_event.back(), kSlope, 2e-8) << "onto the ramp";
    }
  }
}

// Protects edges and vertices as contact features: beyond the terrain's
// boundary edge a sphere and an ellipsoid touch that edge, past its corner
// they touch the corner vertex — at the nearest point (the ellipsoid's gap
// is FCL's GJK distance to 1e-6) — and a disk lying flat on a face, which has
// no unique contact point, is still singular, with finite values.
TEST(ContactTerrain, BoundaryEdgeAndCornerVertexCarryTheContact) {
  const Support terrain{flatAndRamp(), StaticMotion{}, "terrain"};
  const Vec3 a(0, 3, 0), dir = Vec3(-4, -3, 0) / 5;  // the boundary edge (0, 3)–(−4, 0)
  const Ellipsoid egg{Vec3(0.1, 0.08, 0.06), Vec3::Zero(), axisAngle(Vec3(1, 2, 3).normalized(), 0.4)};
  const auto fcl_egg = makeCollisionGeometry(Shape{egg});
  const auto fcl_terrain = makeCollisionGeometry(terrain);
  for (const Shape& shape : {Shape{Sphere{0.1, Vec3::Zero()}}, Shape{egg}}) {
    SCOPED_TRACE(shapeName(shape));
    const auto c = makeContact(ContactKind::Rolling, 0, shape, terrain);
    ContactGeometry g;
    SE3 pose;
    pose.R = axisAngle(Vec3(1, 2, 3).normalized(), 0.4);
    pose.p = Vec3(-0.5, 3.2, 0.1);  // beyond the flat face's boundary edge
    c->geometry(pose, Vec6::Zero(), 0.0, g);
    ASSERT_FALSE(g.singular) << g.reason;
    const Vec3 x = g.support_point;
    EXPECT_LT(((x - a) - dir * dir.dot(x - a)).norm(), 1e-12) << "on the edge's line";
    EXPECT_LT(std::abs(g.normal.dot(dir)), 1e-12) << "normal ⊥ edge";
    if (std::holds_alternative<Ellipsoid>(shape)) {
      EXPECT_NEAR(g.gap, proximity(*fcl_egg, pose, *fcl_terrain, SE3::Identity()).distance, 1e-6);
    }
    pose.p = Vec3(-4.3, 0.0, 0.1);  // past the flat face's corner (−4, 0, 0)
    c->geometry(pose, Vec6::Zero(), 0.0, g);
    ASSERT_FALSE(g.singular) << g.reason;
    EXPECT_LT((g.support_point - Vec3(-4, 0, 0)).norm(), 1e-12) << "at the vertex";
  }
  const auto flat = makeContact(ContactKind::Rolling, 0, Disk{0.1, Vec3::Zero(), Vec3::UnitZ()}, terrain);
  ContactGeometry g;
  SE3 pose;
  pose.p = Vec3(-1.0, 0.5, 0.0);
  flat->geometry(pose, Vec6::Zero(), 0.0, g);
  ASSERT_TRUE(g.singular);
  EXPECT_NE(std::string(g.reason).find("flat"), std::string::npos) << g.reason;
  EXPECT_TRUE(g.point.allFinite() && g.normal.allFinite() && std::isfinite(g.gap));
}

TEST(ContactTerrain, BadMeshesAreRefusedByName) {
  auto message = [](std::vector<Vec3> v, std::vector<std::array<int, 3>> t) {
    try {
      makeTerrain(std::move(v), std::move(t));
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::vector<Vec3> v{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(2, 0, 0)};
  EXPECT_NE(message(v, {{0, 1, 2}, {0, 1, 3}}).find("triangle 1 (vertices 0, 1, 3) is degenerate"),
            std::string::npos);
  EXPECT_NE(message(v, {{0, 1, 7}}).find("triangle 0 has vertex index 7 out of range"),
            std::string::npos);
  EXPECT_NE(message(v, {}).find("has no triangles"), std::string::npos);
  // Through a contact: the support's name and the reason.
  TerrainMesh raw;
  raw.vertices = v;
  raw.triangles = {{0, 1, 1}};
  try {
    makeContact(ContactKind::Rolling, 0, Sphere{0.1, Vec3::Zero()}, Support{raw, StaticMotion{}, "hills"});
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("support 'hills'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("degenerate"), std::string::npos) << e.what();
  }
}

TEST(ContactTerrain, UrdfTerrainFromAnStlLoadsAndRuns) {
  // The flat-and-ramp terrain as an ASCII STL (each facet repeats its vertices).
  const std::string dir = std::string(APPELL_BINARY_DIR) + "/";
  const std::string stl = dir + "terrain_ramp_test.stl";
  {
    const TerrainMesh t = flatAndRamp();
    std::ofstream out(stl);
    out.precision(17);
    out << "solid ramp\n";
    for (int f = 0; f < 2; ++f) {
      const Vec3 n = terrainFaceNormal(t, f);
      out << " facet normal " << n.x() << ' ' << n.y() << ' ' << n.z() << "\n  outer loop\n";
      for (int k : t.triangles[f]) {
        const Vec3& x = t.vertices[k];
        out << "   vertex " << x.x() << ' ' << x.y() << ' ' << x.z() << '\n';
      }
      out << "  endloop\n endfacet\n";
    }
    out << "endsolid ramp\n";
  }
  const double r = 0.1;
  const Vec3 n(std::sin(kSlope), 0, std::cos(kSlope)), down(std::cos(kSlope), 0, -std::sin(kSlope));
  const Vec3 c0 = Vec3(1.0, -0.2, -std::tan(kSlope)) + r * n;
  std::ostringstream xml;
  xml.precision(17);
  xml << R"(<?xml version="1.0"?>
<robot name="ball_on_terrain">
  <link name="ball">
    <inertial><mass value="1"/><inertia ixx="0.004" ixy="0" ixz="0" iyy="0.004" iyz="0" izz="0.004"/></inertial>
    <collision><geometry><sphere radius="0.1"/></geometry></collision>
  </link>
  <appell>
    <support name="hills" type="terrain" filename="terrain_ramp_test.stl"/>
    <contact name="foot" link="ball" kind="rolling" support="hills"/>
    <initial><joint name="root_joint" xyz=")"
      << c0.x() << ' ' << c0.y() << ' ' << c0.z() << R"(" rpy="0 0 0"/></initial>
  </appell>
</robot>
)";
  Scene scene = loadSceneFromString(xml.str(), dir);
  ASSERT_EQ(scene.supports.size(), 1u);
  ASSERT_TRUE(std::holds_alternative<TerrainMesh>(scene.supports[0].surface));
  EXPECT_EQ(std::get<TerrainMesh>(scene.supports[0].surface).triangles.size(), 2u);
  Simulator sim(scene.model, scene.constraints,
                makeSolver(Formulation::Multipliers, scene.model, scene.constraints),
                IntegratorType::RK4);
  sim.setState(0.0, scene.q0, scene.v0);
  const double E0 = sim.energy(), T = 0.3;
  const StepStatus st = sim.advanceTo(T, 1e-3);
  ASSERT_TRUE(st.ok) << st.message;
  const double s = 0.5 * (5.0 / 7.0) * 9.81 * std::sin(kSlope) * T * T;
  EXPECT_LT((sim.q().head<3>() - (c0 + s * down)).norm(), 1e-8) << sim.q().head<3>().transpose();
  EXPECT_LT(std::abs(sim.energy() - E0), 1e-9);
  std::printf("  urdf: |c − c_analytic| = %.3g m, |ΔE| = %.3g J after %.1f s\n",
              (sim.q().head<3>() - (c0 + s * down)).norm(), std::abs(sim.energy() - E0), T);
  EXPECT_LT((sim.contactFrame(0).normal - n).norm(), 1e-12);
}

TEST(ContactTerrain, EvaluationDoesNotAllocate) {
  const Model model = ballModel(1.0, 0.1);
  const TerrainMesh flat = gridTerrain(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 3.0, 40);
  const auto on_grid =
      makeContact(ContactKind::RollingWithoutSpin, 0, Sphere{0.1, Vec3::Zero()},
                  Support{flat, StaticMotion{}, "grid"});
  const auto on_ramp = makeContact(ContactKind::Rolling, 0, Sphere{0.1, Vec3::Zero()},
                                   Support{flatAndRamp(), StaticMotion{}, "ramp"});
  const auto egg_on_ramp = makeContact(
      ContactKind::Rolling, 0, Ellipsoid{Vec3(0.1, 0.08, 0.06), Vec3::Zero(), Mat3::Identity()},
      Support{flatAndRamp(), StaticMotion{}, "ramp"});
  RowBlock a, b, c;
  on_grid->reserve(model, a);
  on_ramp->reserve(model, b);
  egg_on_ramp->reserve(model, c);
  Vec6 V;
  V << 0.3, -1, 0.2, 1, 0.5, 0;
  SE3 inside, edge, high;
  inside.p = Vec3(0.37, -1.21, 0.1);
  edge.p = Vec3(0.015, 0.1, 0.1);  // over the crease: on the edge
  high.p = Vec3(0.2, 0.3, 5.0);    // far above: the search box widens
  g_news = 0;
  g_counting = true;
  on_grid->evaluateAt(inside, V, 0.0, a);
  on_grid->evaluateAt(high, V, 0.0, a);
  on_ramp->evaluateAt(edge, V, 0.0, b);
  on_ramp->evaluateAt(inside, V, 0.0, b);
  SE3 egg_edge;
  egg_edge.p = Vec3(0.01, 0.1, 0.07);  // an ellipsoid over the crease: the edge solve
  egg_on_ramp->evaluateAt(egg_edge, V, 0.0, c);
  g_counting = false;
  EXPECT_EQ(g_news.load(), 0);
  EXPECT_FALSE(c.singular) << c.singular_reason;
  EXPECT_FALSE(a.singular);
  EXPECT_NEAR(a.frame.gap, 4.9, 1e-12);
  on_ramp->evaluateAt(edge, V, 0.0, b);
  EXPECT_FALSE(b.singular);
  EXPECT_LT((b.frame.normal - Vec3(0.015, 0, 0.1).normalized()).norm(), 1e-12)
      << "the normal points from the crease to the centre";
  // The counter itself works.
  g_counting = true;
  auto* probe = new std::vector<double>(10);
  g_counting = false;
  delete probe;
  EXPECT_GE(g_news.load(), 1);
}
