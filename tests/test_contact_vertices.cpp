// Non-smooth shapes on a support (vertex_contacts.hpp): a box, a mesh foot
// and a standing cylinder touch with their vertices, which make and break as
// unilateral point contacts.
#include <gtest/gtest.h>

#include <appell/run.hpp>
#include <appell/simulator.hpp>
#include <appell/urdf.hpp>
#include <appell/vertex_contacts.hpp>

#include "corner_box.hpp"
#include "scene.hpp"
#include "simulation_helpers.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

using namespace appell;
using namespace appell::scenes;

namespace {

constexpr double kG = 9.81;
const Vec3 kHalf(0.2, 0.1, 0.05);
constexpr double kMass = 2.0;

using DroppedBox = BuiltScene;

// A uniform box whose lowest corner starts `h` above the plane z = 0,
// rotated by R, all corners declared as point contacts of `kind`.
DroppedBox droppedBox(double h, const Mat3& R, ContactKind kind, double restitution = 0) {
  return cornerBox(
      {.half = kHalf, .mass = kMass, .h = h, .R = R, .kind = kind, .restitution = restitution});
}

double normalForceSum(const Simulator& sim) {
  double sum = 0;
  const ConstraintData& cd = sim.constraintData();
  for (int c = 0; c < static_cast<int>(sim.constraints().size()); ++c)
    if (sim.isClosed(c))
      sum += sim.lambda()[cd.offset[c] + sim.constraints()[c]->unilateralRow()];
  return sum;
}

}  // namespace

// Protects: a box dropped flat lands on its four lower corners at the
// free-fall time, in one mode decision (four touchdowns at one instant), and
// then rests: the four redundant normal rows carry its weight exactly, the
// upper corners stay open, nothing drifts — for frictionless (sliding) and
// sticking (rolling) corners, in every formulation.
TEST(ContactVertices, BoxDroppedFlatRestsOnItsFourCorners) {
  const double h = 0.1;
  const double t_star = std::sqrt(2 * h / kG);
  for (ContactKind kind : {ContactKind::Sliding, ContactKind::Rolling}) {
    for (Formulation f : {Formulation::Tree, Formulation::Multipliers}) {
      DroppedBox s = droppedBox(h, Mat3::Identity(), kind);
      ASSERT_EQ(s.constraints.size(), 8u);
      Simulator sim(s.model, s.constraints, makeSolver(f, s.model, s.constraints),
                    IntegratorType::DormandPrince54, appell::test::tightIntegrator());
      ASSERT_TRUE(sim.setState(0, s.q0, s.v0)) << sim.lastStateError();
      const auto events = appell::test::advanceCollecting(sim, 1.0);
      std::set<int> landed;
      for (const ContactEvent& e : events) {
        EXPECT_EQ(e.kind, ContactEventKind::Touchdown) << toString(kind) << " " << toString(f);
        EXPECT_NEAR(e.t, t_star, 1e-10);
        landed.insert(e.constraint);
      }
      EXPECT_EQ(landed.size(), 4u) << "the four lower corners land, once each";
      for (int c = 0; c < 8; ++c) {
        const bool lower = (contactVertices(Box{kHalf, SE3::Identity()})[c]).z() < 0;
        EXPECT_EQ(sim.isClosed(c), lower) << "corner " << c;
      }
      EXPECT_NEAR(sim.q()[2], kHalf.z(), 1e-9) << "resting on the plane";
      EXPECT_LT(sim.v().norm(), 1e-9) << "at rest";
      EXPECT_NEAR(normalForceSum(sim), kMass * kG, 1e-8) << "the corners carry the weight";
      EXPECT_NEAR(sim.impactEnergyLoss(), kMass * kG * h, 1e-8)
          << "a plastic landing takes all the kinetic energy";
    }
  }
}

// Protects: a tilted box lands on one edge first (two corners at the
// free-fall time of that edge), pivots, and its other edge lands later; the
// energy never grows (E + impact losses is conserved between and through
// events), and it ends at rest on four corners.
TEST(ContactVertices, TiltedBoxLandsOnAnEdgeThenFallsFlat) {
  const double h = 0.05;
  const Mat3 R = axisAngle(Vec3::UnitX(), 0.2);
  DroppedBox s = droppedBox(h, R, ContactKind::Rolling);
  Simulator sim(s.model, s.constraints, makeSolver(Formulation::Tree, s.model, s.constraints),
                IntegratorType::DormandPrince54, appell::test::tightIntegrator());
  ASSERT_TRUE(sim.setState(0, s.q0, s.v0)) << sim.lastStateError();
  const double E0 = sim.energy();
  std::vector<ContactEvent> all;
  double worst = 0;
  while (sim.time() < 2.0 - 1e-12) {
    const StepStatus st = sim.step(1e-2);
    ASSERT_TRUE(st.ok) << st.message;
    all.insert(all.end(), sim.events().begin(), sim.events().end());
    worst = std::max(worst, std::abs(sim.energy() + sim.impactEnergyLoss() - E0));
  }
  ASSERT_GE(all.size(), 4u);
  EXPECT_EQ(all[0].kind, ContactEventKind::Touchdown);
  EXPECT_NEAR(all[0].t, std::sqrt(2 * h / kG), 1e-10) << "the lower edge lands first";
  EXPECT_NEAR(all[1].t, all[0].t, 1e-12) << "both corners of that edge at once";
  bool later = false;
  for (const ContactEvent& e : all) later |= e.t > all[0].t + 1e-3;
  EXPECT_TRUE(later) << "the other edge lands after the box pivots";
  EXPECT_LT(worst, 1e-7) << "E + impact losses is conserved";
  EXPECT_NEAR(sim.q()[2], kHalf.z(), 1e-8);
  EXPECT_LT(sim.v().norm(), 1e-8);
  EXPECT_NEAR(normalForceSum(sim), kMass * kG, 1e-7);
}

// Protects the candidate vertices: a box's 8 corners, a cylinder's two rim
// polygons, the hull vertices of a mesh (an interior vertex is dropped), and
// refusals that name the shape.
TEST(ContactVertices, CandidateVerticesOfEachShape) {
  EXPECT_EQ(contactVertices(Box{kHalf, SE3::Identity()}).size(), 8u);
  const auto rim = contactVertices(Cylinder{0.1, 0.04, SE3::Identity()}, 12);
  ASSERT_EQ(rim.size(), 24u);
  for (const Vec3& v : rim) {
    EXPECT_NEAR(v.head<2>().norm(), 0.1, 1e-15);
    EXPECT_NEAR(std::abs(v.z()), 0.02, 1e-15);
  }
  // A tetrahedron's faces with a fifth, interior vertex used by extra faces.
  Mesh m{"foot.stl", Vec3::Ones(), SE3::Identity(), {}, {}};
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.1, 0.1, 0.1}};
  m.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}, {0, 1, 4}};
  const auto hull = contactVertices(m);
  EXPECT_EQ(hull.size(), 4u) << "the interior vertex is not a candidate";
  for (const Vec3& v : hull) EXPECT_GT((v - Vec3(0.1, 0.1, 0.1)).norm(), 0.1);
  Mesh flat = m;
  flat.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0.5, 0.5, 0}};
  flat.triangles = {{0, 1, 2}, {1, 3, 2}};
  auto message = [](auto&& make) { return appell::test::invalidArgumentMessage(make); };
  EXPECT_NE(message([&] { contactVertices(flat); }).find("mesh 'foot.stl': its vertices span no volume"),
            std::string::npos);
  EXPECT_NE(message([] { contactVertices(Sphere{0.1, Vec3::Zero()}); }).find("sphere:"),
            std::string::npos);
  ContactSpec knife;
  knife.kind = ContactKind::KnifeEdge;
  knife.body = 0;
  knife.shape = Box{kHalf, SE3::Identity()};
  knife.options.name = "crate";
  EXPECT_NE(message([&] { makeVertexContacts(knife); }).find("contact 'crate': a box touches with its vertices"),
            std::string::npos);
}

namespace {

// Runs a loaded scene for `duration` with tight settings; returns the worst
// |E + impact losses − E0| seen at the ends of steps.
double runToRest(Simulator& sim, const Scene& scene, double duration) {
  EXPECT_TRUE(sim.setState(0, scene.q0, scene.v0)) << sim.lastStateError();
  const double E0 = sim.energy();
  double worst = 0;
  while (sim.time() < duration - 1e-12) {
    const StepStatus st = sim.step(1e-2);
    EXPECT_TRUE(st.ok) << st.message;
    if (!st.ok) break;
    worst = std::max(worst, std::abs(sim.energy() + sim.impactEnergyLoss() - E0));
  }
  return worst;
}

}  // namespace

// Protects the scene-file path: a box collision under <contact> becomes its
// eight corners (named, with their origin), and the tossed, tumbling crate of
// examples/tumbling_crate — a cascade of corner impacts, each lifting the
// corner before — comes to rest flat on four corners that carry its weight,
// with E + impact losses conserved throughout.
TEST(ContactVertices, TumblingCrateExampleComesToRestOnAFace) {
  Scene scene = loadScene(std::string(APPELL_SOURCE_DIR) + "/examples/tumbling_crate/tumbling_crate.urdf");
  ASSERT_EQ(scene.contacts.size(), 8u);
  EXPECT_EQ(scene.contacts[5]->name(), "corners/v5");
  EXPECT_NE(scene.contact_origins[5].shape_source.find("collision[0] (box), vertex 5"),
            std::string::npos);
  Simulator sim(scene.model, scene.constraints,
                makeSolver(Formulation::Tree, scene.model, scene.constraints),
                IntegratorType::DormandPrince54, appell::test::tightIntegrator());
  const double drift = runToRest(sim, scene, 2.0);
  EXPECT_LT(drift, 1e-8) << "E + impact losses is conserved";
  EXPECT_LT(sim.v().norm(), 1e-9) << "at rest";
  int closed = 0;
  for (int c = 0; c < 8; ++c) closed += sim.isClosed(c);
  EXPECT_EQ(closed, 4) << "flat on one face";
  const double z = sim.q()[2];
  EXPECT_TRUE(std::abs(z - 0.1) < 1e-9 || std::abs(z - 0.15) < 1e-9 || std::abs(z - 0.2) < 1e-9)
      << "the centre rests at a half-extent above the floor, z = " << z;
  EXPECT_NEAR(normalForceSum(sim), 3 * kG, 1e-7);
}

// Protects rim_points: a cylinder collision declared to stand on its face
// touches with its rim polygons; dropped flat it lands on all of its lower
// rim's vertices at the free-fall time and rests at half its length.
TEST(ContactVertices, CylinderStandingOnItsFaceLandsOnItsRim) {
  const std::string urdf = R"(<?xml version="1.0"?>
<robot name="puck">
  <link name="puck">
    <inertial><mass value="0.5"/><inertia ixx="0.002" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.003"/></inertial>
    <collision><geometry><cylinder radius="0.1" length="0.04"/></geometry></collision>
  </link>
  <appell>
    <support name="floor" type="plane"/>
    <contact name="base" link="puck" kind="sliding" support="floor" rim_points="6"/>
    <initial><joint name="root_joint" xyz="0 0 0.12"/></initial>
  </appell>
</robot>)";
  Scene scene = loadSceneFromString(urdf, ".");
  ASSERT_EQ(scene.contacts.size(), 12u);
  Simulator sim(scene.model, scene.constraints,
                makeSolver(Formulation::Multipliers, scene.model, scene.constraints),
                IntegratorType::DormandPrince54, appell::test::tightIntegrator());
  ASSERT_TRUE(sim.setState(0, scene.q0, scene.v0)) << sim.lastStateError();
  const auto events = appell::test::advanceCollecting(sim, 0.5);
  ASSERT_EQ(events.size(), 6u) << "the six vertices of the lower rim";
  for (const ContactEvent& e : events) EXPECT_NEAR(e.t, std::sqrt(2 * 0.1 / kG), 1e-10);
  EXPECT_NEAR(sim.q()[2], 0.02, 1e-9);
  EXPECT_NEAR(normalForceSum(sim), 0.5 * kG, 1e-8);
  try {
    loadSceneFromString(std::string(urdf).replace(urdf.find("rim_points=\"6\""), 14,
                                                  "rim_points=\"2\""),
                        ".");
    ADD_FAILURE() << "two rim points accepted";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("'rim_points' must be a whole number from 3"),
              std::string::npos)
        << e.what();
  }
}

// Protects Coulomb friction on a non-smooth body and the work balance with
// friction: a block on an incline of angle α on four sticking corners (μ)
// stays put when tan α < μ; when tan α > μ all four corners slide together
// and the block accelerates down the slope at g (sin α − μ cos α), the
// friction taking μ m g cos α per metre — Simulator::frictionWork(), and
// E + friction work conserved to the integration tolerance. The four
// normal rows are redundant (a block has 3 freedoms off the plane): the
// sliding solve must still find the loads, and the onset of the slip must
// give every corner its downhill direction at once.
TEST(ContactVertices, BlockOnAnInclineSticksOrSlidesByTheFrictionAngle) {
  const double alpha = 0.4;  // tan α = 0.423
  const Vec3 n(-std::sin(alpha), 0, std::cos(alpha));
  const Vec3 down(-std::cos(alpha), 0, -std::sin(alpha));
  for (double mu : {0.5, 0.3}) {
    SCOPED_TRACE("mu = " + std::to_string(mu));
    DroppedBox s = droppedBox(0, Mat3::Identity(), ContactKind::Rolling);
    s.constraints.clear();
    ContactSpec spec;
    spec.kind = ContactKind::Rolling;
    spec.body = 0;
    spec.shape = Box{kHalf, SE3::Identity()};
    spec.support = Support{Plane{Vec3::Zero(), n}, StaticMotion{}, "slope"};
    spec.mu = mu;
    spec.options.name = "block";
    for (auto& c : makeVertexContacts(spec)) s.constraints.push_back(c);
    const Mat3 R = axisAngle(Vec3::UnitY(), -alpha);
    const Vec3 p0 = R * Vec3(0, 0, kHalf.z());
    setFloatingPose(s.q0, 0, p0, R);
    Simulator sim(s.model, s.constraints, makeSolver(Formulation::Tree, s.model, s.constraints),
                  IntegratorType::DormandPrince54, appell::test::tightIntegrator());
    ASSERT_TRUE(sim.setState(0, s.q0, s.v0)) << sim.lastStateError();
    const double E0 = sim.energy();
    double worst = 0, v_half = 0, t_half = -1;
    while (sim.time() < 1.0 - 1e-12) {
      const StepStatus st = sim.step(1e-2);
      ASSERT_TRUE(st.ok) << st.message;
      worst = std::max(worst, std::abs(sim.energy() + sim.frictionWork() + sim.impactEnergyLoss() - E0));
      if (t_half < 0 && sim.time() >= 0.5) {
        t_half = sim.time();
        v_half = -sim.v()[3];
      }
    }
    const double travelled = (sim.q().head<3>() - p0).dot(down);
    int closed = 0;
    for (int c = 0; c < 8; ++c) closed += sim.isClosed(c);
    EXPECT_EQ(closed, 4) << "on its four lower corners";
    if (mu > std::tan(alpha)) {
      EXPECT_LT(sim.v().norm(), 1e-9) << "sticks";
      EXPECT_LT(std::abs(travelled), 1e-9);
      EXPECT_EQ(sim.frictionWork(), 0.0);
    } else {
      const double a = kG * (std::sin(alpha) - mu * std::cos(alpha));
      EXPECT_NEAR((-sim.v()[3] - v_half) / (sim.time() - t_half), a, 1e-9)
          << "slides at g (sin α − μ cos α)";
      // From the first instant: the four corners' slip directions are
      // decided together (frictionOnset), all downhill — decided one at a
      // time they carried lateral parts and the block ran 0.76 % too far.
      EXPECT_NEAR(travelled, 0.5 * a * sim.time() * sim.time(), 1e-9)
          << "½ a t² from t = 0";
      EXPECT_LT(std::abs(sim.q()[1]), 1e-12) << "no sideways drift";
      EXPECT_NEAR(sim.frictionWork(), mu * kMass * kG * std::cos(alpha) * travelled, 1e-9)
          << "friction takes μ m g cos α per metre";
      EXPECT_LT(worst, 1e-9) << "E + friction work is conserved";
    }
  }
}

namespace {

// A box (0.4 × 0.3 × 0.1 m) above a terrain mesh written next to the scene.
Scene boxOverTerrain(const std::string& obj, const std::string& name, double x) {
  const auto dir = std::filesystem::temp_directory_path() / "appell_vertex_watch";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / (name + ".obj")) << obj;
  std::ostringstream urdf;
  urdf << R"(<?xml version="1.0"?>
<robot name="crate">
  <link name="crate">
    <inertial><mass value="3"/><inertia ixx="0.025" ixy="0" ixz="0" iyy="0.0425" iyz="0" izz="0.0625"/></inertial>
    <collision><geometry><box size="0.4 0.3 0.1"/></geometry></collision>
  </link>
  <appell>
    <support name="ground" type="terrain" filename=")"
       << name << R"(.obj"/>
    <contact name="corners" link="crate" kind="sliding" support="ground"/>
    <initial><joint name="root_joint" xyz=")"
       << x << R"( 0 0.1"/></initial>
  </appell>
</robot>)";
  return loadSceneFromString(urdf.str(), dir.string());
}

}  // namespace

// Protects the watch over what vertex contacts cannot see (run/src/
// vertex_watch.cpp): a box dropped onto a roof's ridge lands on the ridge
// with its bottom face, between its corners — FCL's distance between the
// whole box and the mesh goes negative while every corner is still in the
// air — and the run stops there naming the contact, the depth and the point,
// instead of letting the box sink through the ridge. The same box dropped on
// a flat mesh lands on its corners and the watch stays silent.
TEST(ContactVertices, ARidgeBetweenTheCornersStopsTheRunByName) {
  // A roof: ridge along y at x = 0, z = 0; slopes of 0.5 down to ±2 m.
  const std::string roof = "v -2 -3 -1\nv 0 -3 0\nv 0 3 0\nv -2 3 -1\nv 2 -3 -1\nv 2 3 -1\n"
                           "f 1 2 3\nf 1 3 4\nf 2 5 6\nf 2 6 3\n";
  const std::string flat = "v -3 -3 -0.1\nv 3 -3 -0.1\nv 3 3 -0.1\nv -3 3 -0.1\nf 1 2 3\nf 1 3 4\n";
  RunOptions o;
  o.duration = 0.5;
  o.integrator = IntegratorType::DormandPrince54;
  o.tol = 1e-10;
  o.dt = 1e-2;
  const RunSummary ridge = runScene(boxOverTerrain(roof, "roof", 0.0), o);
  EXPECT_FALSE(ridge.ok);
  std::printf("  %s\n", ridge.failure.c_str());
  EXPECT_NE(ridge.failure.find("contact 'corners' (a box on link 'crate'): the terrain presses "
                               "into it by"),
            std::string::npos)
      << ridge.failure;
  EXPECT_NEAR(ridge.time, std::sqrt(2 * 0.05 / kG), 0.02) << "where the ridge meets the face";
  const RunSummary onto_flat = runScene(boxOverTerrain(flat, "flat", 0.0), o);
  EXPECT_TRUE(onto_flat.ok) << onto_flat.failure;
  EXPECT_EQ(onto_flat.events.size(), 4u) << "four corners land";
}

namespace {

// A UV sphere of radius r with `rings` × `segments` vertices (plus poles):
// every vertex is on its convex hull.
Mesh uvSphere(double r, int rings, int segments) {
  Mesh m{"scan.stl", Vec3::Ones(), SE3::Identity(), {}, {}};
  m.vertices.push_back({0, 0, r});
  for (int i = 1; i <= rings; ++i) {
    const double th = M_PI * i / (rings + 1);
    for (int j = 0; j < segments; ++j) {
      const double ph = 2 * M_PI * j / segments;
      m.vertices.push_back({r * std::sin(th) * std::cos(ph), r * std::sin(th) * std::sin(ph), r * std::cos(th)});
    }
  }
  m.vertices.push_back({0, 0, -r});
  const int south = static_cast<int>(m.vertices.size()) - 1;
  auto at = [&](int i, int j) { return 1 + (i - 1) * segments + (j % segments); };
  for (int j = 0; j < segments; ++j) {
    m.triangles.push_back({0, at(1, j), at(1, j + 1)});
    m.triangles.push_back({south, at(rings, j + 1), at(rings, j)});
    for (int i = 1; i < rings; ++i) {
      m.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      m.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  }
  return m;
}

}  // namespace

// Issue 41, reproducer 9: every hull vertex of a mesh was a contact —
// 179 402 of them took `appell info` 304 s and 2 GB. A hull of more than
// kMaxHullContacts vertices is reduced to its support points in that many
// evenly spread directions: at most 128 contacts, exact in those directions
// (the farthest vertex along each is kept), and a box-like hull keeps its 8
// corners however finely its faces are meshed.
TEST(ContactVertices, AHugeHullIsReducedToItsSupportPointsWithAWarning) {
  const Mesh sphere = uvSphere(0.1, 299, 600);  // 179 402 vertices
  ASSERT_EQ(sphere.vertices.size(), 179402u);
  int hull_vertices = 0;
  const std::vector<Vec3> kept = contactVertices(sphere, 16, &hull_vertices);
  EXPECT_EQ(hull_vertices, 179402);
  EXPECT_LE(kept.size(), static_cast<std::size_t>(kMaxHullContacts));
  EXPECT_GE(kept.size(), 100u) << "a round hull has a distinct support point in nearly every direction";
  // Exact in the lattice's directions: the kept set reaches as far as the hull.
  const double golden = M_PI * (3 - std::sqrt(5.0));
  for (int k = 0; k < kMaxHullContacts; ++k) {
    const double z = 1 - (2.0 * k + 1) / kMaxHullContacts, r = std::sqrt(1 - z * z);
    const Vec3 d(r * std::cos(k * golden), r * std::sin(k * golden), z);
    double all = -1, reduced = -1;
    for (const Vec3& v : sphere.vertices) all = std::max(all, d.dot(v));
    for (const Vec3& v : kept) reduced = std::max(reduced, d.dot(v));
    EXPECT_EQ(reduced, all) << "direction " << k;
  }
  // Every direction: the reduced polytope reaches within R(1 − cos(δ/2)) of
  // the sphere, δ the lattice's spacing √(4π/K) (1.2 % of R for K = 128).
  const double spacing = std::sqrt(4 * M_PI / kMaxHullContacts);
  for (int k = 0; k < 500; ++k) {
    const Vec3 d = Vec3(std::sin(k * 0.37) * std::cos(k * 1.3), std::sin(k * 0.37) * std::sin(k * 1.3), std::cos(k * 0.37));
    double reduced = -1;
    for (const Vec3& v : kept) reduced = std::max(reduced, d.normalized().dot(v));
    EXPECT_GT(reduced, 0.1 * std::cos(spacing)) << "direction " << k;
  }
  // A cube whose faces are meshed with 21 × 21 points each: its 8 corners.
  Mesh cube{"cube.stl", Vec3::Ones(), SE3::Identity(), {}, {}};
  for (int axis = 0; axis < 3; ++axis)
    for (double side : {-1.0, 1.0})
      for (int i = 0; i <= 20; ++i)
        for (int j = 0; j <= 20; ++j) {
          // Each face bulges out as a paraboloid 10⁻³ high (zero at the
          // corners), so that all its points are hull vertices.
          const double u = -1 + 0.1 * i, w = -1 + 0.1 * j;
          Vec3 p;
          p[axis] = side * (1 + 1e-3 * (2 - u * u - w * w));
          p[(axis + 1) % 3] = u;
          p[(axis + 2) % 3] = w;
          cube.vertices.push_back(p);
        }
  cube.triangles = {{0, 1, 2}};
  int cube_hull = 0;
  const std::vector<Vec3> corners = contactVertices(cube, 16, &cube_hull);
  ASSERT_GT(cube_hull, kMaxHullContacts) << "the bulged face points are on the hull";
  std::set<std::array<int, 3>> seen;
  for (const Vec3& v : corners)
    if (std::abs(std::abs(v.x()) - 1) < 1e-12 && std::abs(std::abs(v.y()) - 1) < 1e-12 &&
        std::abs(std::abs(v.z()) - 1) < 1e-12)
      seen.insert({v.x() > 0, v.y() > 0, v.z() > 0});
  EXPECT_EQ(seen.size(), 8u);
  // The loader's warning, once per contact, through makeVertexContacts.
  ContactSpec spec;
  spec.kind = ContactKind::Sliding;
  spec.body = 0;
  spec.shape = sphere;
  spec.options.name = "foot";
  std::string warning;
  EXPECT_EQ(makeVertexContacts(spec, 16, &warning).size(), kept.size());
  EXPECT_EQ(warning, "contact 'foot': the mesh's convex hull has more than 128 of its 179402 vertices; its " +
                         std::to_string(kept.size()) + " support points in 128 evenly spread directions are the contacts");
}
