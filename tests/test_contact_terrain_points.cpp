// Where a body meets a terrain at more than one place (ContactSpec::points):
// a ball in a valley rests on both slopes. And where it meets an edge.
#include <gtest/gtest.h>

#include <appell/contacts.hpp>
#include <appell/simulator.hpp>
#include <appell/terrain.hpp>
#include <appell/urdf.hpp>

#include "scene.hpp"
#include "simulation_helpers.hpp"

#include <cmath>

using namespace appell;
using namespace appell::scenes;

namespace {

constexpr double kG = 9.81;

// Two planes meeting along the y axis at slope α: a valley (z = |x| tan α)
// or, with ridge, a roof (z = −|x| tan α). Faces wound to point up.
TerrainMesh trough(double alpha, bool ridge = false) {
  const double w = 2, l = 2, h = (ridge ? -1 : 1) * w * std::tan(alpha);
  return makeTerrain({{-w, -l, h}, {0, -l, 0}, {0, l, 0}, {-w, l, h}, {w, -l, h}, {w, l, h}},
                     {{0, 1, 2}, {0, 2, 3}, {1, 4, 5}, {1, 5, 2}});
}

// A grid of sines, 0.5 m by 0.75 m cells, heights within ±5 cm: valleys,
// ridges and saddles in every direction.
TerrainMesh bumpy() {
  std::vector<Vec3> v;
  std::vector<std::array<int, 3>> f;
  const int nx = 60, ny = 8;
  for (int i = 0; i <= nx; ++i)
    for (int j = 0; j <= ny; ++j) {
      const double x = -5 + 0.5 * i, y = -3 + 0.75 * j;
      v.emplace_back(x, y, 0.03 * std::sin(1.7 * x) * std::cos(1.1 * y) + 0.02 * std::sin(0.9 * x + 2.3 * y));
    }
  auto at = [&](int i, int j) { return i * (ny + 1) + j; };
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j) {
      f.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      f.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  return makeTerrain(v, f);
}

// A contact of body 0 (the ball) with `support`.
ContactSpec ballContact(ContactKind kind, const Shape& shape, const Support& support,
                        int points = 1) {
  ContactSpec spec;
  spec.kind = kind;
  spec.body = 0;
  spec.shape = shape;
  spec.support = support;
  spec.points = points;
  return spec;
}

Model ballModel(double mass, double rho) {
  ModelBuilder b;
  b.addBody("ball", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(),
            principalInertia(mass, Vec3::Constant(0.4 * mass * rho * rho)), "free");
  return b.build();
}

}  // namespace

// A square pit: four faces falling at slope α to a bottom vertex at the
// origin (an inverted pyramid, half-width w).
TerrainMesh pit(double alpha) {
  const double w = 2, h = w * std::tan(alpha);
  return makeTerrain({{0, 0, 0}, {w, -w, h}, {w, w, h}, {-w, w, h}, {-w, -w, h}},
                     {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 4, 1}});
}

// Protects the sign of the gap at a terrain vertex. A 1 cm ball dropped from 5 m
// over a pit falls ~1 m per step of free flight at landing (0.1 s steps). A
// step that carries its centre below the pit's bottom vertex leaves it
// nearest to that vertex — from below, where the distance is positive too:
// it used to fall through the terrain unseen. The gap there is signed by the
// vertex's angle-weighted pseudonormal, so the step is seen to cross and the
// landing is located: on the face it is nearest, at
//   t = √(2 (z₀ − z₁)/g),  z₁ = (ρ + x₀ sin α)/cos α,
// to 1e-10 (x₀ > |y₀| puts it over the +x face).
TEST(ContactTerrainPoints, ABallFallingIntoAPitLandsInsteadOfPassingThroughItsBottom) {
  const double rho = 0.01, mass = 0.05, alpha = 0.3, x0 = 0.001, y0 = 0.0004, z0 = 5;
  const Support ground{pit(alpha), StaticMotion{}, "pit"};
  const Model model = ballModel(mass, rho);
  ContactSpec spec = ballContact(ContactKind::Rolling, Shape{Sphere{rho}}, ground);
  const ConstraintList list{makeContact(spec)};
  VecX q = neutralConfiguration(model);
  q.head<3>() = Vec3(x0, y0, z0);
  IntegratorOptions long_steps = appell::test::tightIntegrator();
  long_steps.h_max = 0.1;
  Simulator sim(model, list, makeSolver(Formulation::Tree, model, list),
                IntegratorType::DormandPrince54, long_steps);
  ASSERT_TRUE(sim.setState(0, q, VecX::Zero(model.nv))) << sim.lastStateError();
  const auto run = appell::test::runWatching(
      sim, 1.5, [](const Simulator& s) { return s.q()[2]; }, 0.5);
  const auto events = run.modeEvents();
  ASSERT_GE(events.size(), 1u);
  EXPECT_EQ(events[0].kind, ContactEventKind::Touchdown);
  const double z1 = (rho + x0 * std::sin(alpha)) / std::cos(alpha);
  EXPECT_NEAR(events[0].t, std::sqrt(2 * (z0 - z1) / kG), 1e-10) << "lands on the +x face";
  EXPECT_NEAR(run.at_event[0], z1, 1e-9);
  EXPECT_GT(sim.q()[2], rho) << "still in the pit, above its bottom";
}

// Protects touchdown on an edge. A ball falling onto a ridge touches the
// ridge's edge first (its centre is in the edge's wedge): it lands at the
// fall time t = √(2 (z₀ − √(ρ² − x₀²)) / g) to 1e-10, then pivots about the
// ridge and rolls down the slope. The sphere (nearest point) and an
// equal-axes ellipsoid (every other shape's face and edge search) alike;
// the ellipsoid's edge contact, refused once it sank 1e-6 m past the edge,
// used to be found only on the faces' extended planes, 8 ms late.
TEST(ContactTerrainPoints, ABallFallingOntoARidgeLandsOnItsEdge) {
  const double rho = 0.1, mass = 0.5, x0 = 0.02, z0 = 1.5, alpha = 0.35;
  const Support roof{trough(alpha, true), StaticMotion{}, "roof"};
  for (const Shape& shape : {Shape{Sphere{rho}}, Shape{Ellipsoid{Vec3::Constant(rho)}}}) {
    SCOPED_TRACE(shapeName(shape));
    const Model model = ballModel(mass, rho);
    ContactSpec spec = ballContact(ContactKind::Rolling, shape, roof);
    const ConstraintList list{makeContact(spec)};
    VecX q = neutralConfiguration(model);
    q.head<3>() = Vec3(x0, 0, z0);
    IntegratorOptions long_steps = appell::test::tightIntegrator();
    long_steps.h_max = 0.1;  // the default: free flight is one step per 0.1 s
    Simulator sim(model, list, makeSolver(Formulation::Tree, model, list),
                  IntegratorType::DormandPrince54, long_steps);
    ASSERT_TRUE(sim.setState(0, q, VecX::Zero(model.nv))) << sim.lastStateError();
    ASSERT_FALSE(sim.isClosed(0));
    const auto run = appell::test::runWatching(
        sim, 1.0, [](const Simulator& s) { return s.q()[2]; }, 0.5);
    const auto events = run.modeEvents();
    ASSERT_GE(events.size(), 1u);
    EXPECT_EQ(events[0].kind, ContactEventKind::Touchdown);
    EXPECT_NEAR(events[0].t, std::sqrt(2 * (z0 - std::sqrt(rho * rho - x0 * x0)) / kG), 1e-10)
        << "lands on the ridge";
    EXPECT_NEAR(run.at_event[0], std::sqrt(rho * rho - x0 * x0), 1e-9);
    // Off the ridge and down the slope: on the +x face, above it.
    EXPECT_GT(sim.q()[0], x0);
    const double gap = sim.q()[0] * std::sin(alpha) + sim.q()[2] * std::cos(alpha) - rho;
    EXPECT_GT(gap, -1e-9) << "never below the terrain";
    EXPECT_LT(run.worst_energy, 1e-9 * mass * kG * z0);
  }
}

// Protects the second point of a pair. A frictionless ball dropped into a
// V-shaped valley (slopes ±α = 30°) lands on slope A and slides down it to
// the bottom, where it meets slope B: a second place of contact, which one
// contact per pair cannot hold (its piece would flip between the slopes at
// every step). With points = 2 the second point watches the nearest piece
// separate from the first's and touches down on B at the analytic time. The
// plastic impact there removes the velocity along B's normal and keeps the
// rest, s cos 2α up slope B: the first point lifts off A. The ball slides up
// B and back, meets A at the bottom, and so on — each crossing keeps cos 2α
// of the speed and takes 2 s cos 2α/(g sin α), a Zeno sequence ending at
//   t∞ = t₂ + 2 s₀ cos 2α / ((1 − cos 2α) g sin α).
// Below the rest speed the contact an impact would unload is held: the ball
// rests on both slopes, at the bottom, with normal loads m g / (2 cos α). The
// sphere (nearest-point geometry) and an equal-axes ellipsoid (the face and
// edge search of every other shape) alike, with every formulation:
//   t₁ = √(2 (z₀ − z₁)/g),  z₁ = (ρ − x₀ sin α)/cos α;
//   on A: ẍ = g sin α cos α from ẋ = g t₁ sin α cos α (the first impact
//   keeps the velocity along A), at x = 0 after τ = (−ẋ + √(ẋ² − 2ẍx₀))/ẍ,
//   with speed s₀ = (ẋ + ẍτ)/cos α.
TEST(ContactTerrainPoints, ABallDroppedIntoAValleyComesToRestOnBothSlopes) {
  const double rho = 0.1, mass = 0.5, alpha = M_PI / 6, x0 = -0.3, z0 = 2.0;
  const Support valley{trough(alpha), StaticMotion{}, "valley"};
  const double z1 = (rho - x0 * std::sin(alpha)) / std::cos(alpha);
  const double t1 = std::sqrt(2 * (z0 - z1) / kG);
  const double a = kG * std::sin(alpha) * std::cos(alpha), u = a * t1;
  const double tau = (-u + std::sqrt(u * u - 2 * a * x0)) / a;
  const double t2 = t1 + tau, s0 = (u + a * tau) / std::cos(alpha), keep = std::cos(2 * alpha);
  const double t_end = t2 + 2 * s0 * keep / ((1 - keep) * kG * std::sin(alpha));
  for (const Shape& shape : {Shape{Sphere{rho}}, Shape{Ellipsoid{Vec3::Constant(rho)}}}) {
    SCOPED_TRACE(shapeName(shape));
    const Model model = ballModel(mass, rho);
    ContactSpec spec = ballContact(ContactKind::Sliding, shape, valley, 2);
    spec.options.name = "ball";
    const auto points = makeContactPoints(spec);
    ASSERT_EQ(points.size(), 2u);
    EXPECT_EQ(points[1]->name(), "ball/p1");
    const ConstraintList list{points[0], points[1]};
    VecX q = neutralConfiguration(model);
    q.head<3>() = Vec3(x0, 0, z0);
    for (Formulation form : {Formulation::Tree, Formulation::Multipliers, Formulation::Appell}) {
      SCOPED_TRACE(toString(form));
      IntegratorOptions long_steps = appell::test::tightIntegrator();
      long_steps.h_max = 0.1;  // a step of free flight carries it past the crease
      Simulator sim(model, list, makeSolver(form, model, list), IntegratorType::DormandPrince54,
                    long_steps);
      ASSERT_TRUE(sim.setState(0, q, VecX::Zero(model.nv))) << sim.lastStateError();
      const auto run = appell::test::runWatching(
          sim, t_end + 0.5, [](const Simulator& s) { return s.q()[0]; });
      std::vector<ContactEvent> touchdowns;
      for (const ContactEvent& e : run.modeEvents())
        if (e.kind == ContactEventKind::Touchdown) touchdowns.push_back(e);
      ASSERT_GE(touchdowns.size(), 10u);
      EXPECT_LT(touchdowns.size(), 30u) << "the sequence ends";
      EXPECT_EQ(touchdowns[0].constraint, 0);
      EXPECT_NEAR(touchdowns[0].t, t1, 1e-10) << "lands on slope A";
      // The k-th crossing of the bottom: the points take turns, at speed
      // s₀ cos^k 2α, after the flights up and down the slopes.
      double t = t2, s = s0;
      for (size_t k = 1; k < touchdowns.size(); ++k) {
        SCOPED_TRACE(k);
        const ContactEvent& e = touchdowns[k];
        EXPECT_EQ(e.constraint, static_cast<int>(k % 2)) << "the points take turns";
        EXPECT_NEAR(e.t, t, 1e-9);
        if (s > 2 * ContactEventOptions{}.rest_speed) {
          EXPECT_NEAR(e.speed_before, -s * std::sin(2 * alpha), 1e-9 * s0);
        }
        t += 2 * s * keep / (kG * std::sin(alpha));
        s *= keep;
      }
      EXPECT_LT(touchdowns.back().t, t_end) << "before the accumulation point";
      ASSERT_TRUE(sim.isClosed(0));
      ASSERT_TRUE(sim.isClosed(1));
      EXPECT_LT(sim.v().norm(), 1e-9) << "at rest";
      EXPECT_NEAR(sim.q()[0], 0, 1e-9);
      EXPECT_NEAR(sim.q()[2], rho / std::cos(alpha), 1e-9);
      const double load = mass * kG / (2 * std::cos(alpha));
      EXPECT_NEAR(sim.lambda()[0], load, 1e-8);
      EXPECT_NEAR(sim.lambda()[1], load, 1e-8);
      EXPECT_LT(run.worst_energy, 1e-9 * mass * kG * z0);
    }
  }
}

// Protects contact on a mesh of ridges, saddles and creases. A rolling ball
// (μ = 0.8, e = 0.6) dropped on a bumpy mesh bounces and rolls 8 s over it,
// across ridges, saddles and concave creases (each a change of piece, an
// impact at a crease), in long steps of free flight between bounces. It
// runs to the end on the mesh with E + impact losses + friction work
// conserved to 1e-8 J, through more than 50 events, and two formulations
// agree on the end state.
TEST(ContactTerrainPoints, ABallBouncesAndRollsOverABumpyMeshWithoutFallingThrough) {
  const double rho = 0.1, mass = 0.5;
  const Support ground{bumpy(), StaticMotion{}, "bumpy"};
  const Model model = ballModel(mass, rho);
  VecX q = neutralConfiguration(model);
  q.head<3>() = Vec3(0, 0, 1.1);  // over the grid line y = 0: a ridge below
  VecX v = VecX::Zero(model.nv);
  v[3] = 2;
  ContactSpec spec = ballContact(ContactKind::Rolling, Shape{Sphere{rho}}, ground);
  spec.mu = 0.8;
  spec.restitution = 0.6;
  const ConstraintList list{makeContact(spec)};
  VecX end[2];
  int k = 0;
  for (Formulation form : {Formulation::Tree, Formulation::Appell}) {
    SCOPED_TRACE(toString(form));
    IntegratorOptions long_steps = appell::test::tightIntegrator();
    long_steps.h_max = 0.1;  // the default: long steps of free flight
    Simulator sim(model, list, makeSolver(form, model, list), IntegratorType::DormandPrince54,
                  long_steps);
    ASSERT_TRUE(sim.setState(0, q, v)) << sim.lastStateError();
    double lowest = INFINITY;
    const auto run = appell::test::runWatching(
        sim, 8.0, [&](const Simulator& s) { return s.q()[2]; }, 0.05);
    for (double z : run.at_event) lowest = std::min(lowest, z);
    EXPECT_GT(run.modeEvents().size(), 50u);
    EXPECT_GT(lowest, rho - 0.06) << "on the mesh (heights within ±5 cm) at every event";
    EXPECT_GT(sim.q()[2], rho - 0.06);
    EXPECT_LT(run.worst_energy, 1e-8);
    end[k++] = sim.q();
  }
  EXPECT_LT((end[0] - end[1]).norm(), 1e-6);
}

// Protects the agreement of the two descriptions where one place of contact
// suffices. The same ball over the same mesh, with one point and with two:
// with one point a concave crease is a change of piece with an impact; with
// two it may instead be the second point's touchdown on the rising face and
// the first point's lift-off from the old one, and at a convex edge the
// second point must not take the face beyond the edge the first is crossing
// (the same place of contact). The same motion either way: the end states
// agree to 1e-6 (round-off, amplified through ~100 impacts: 1e-8 is
// typical; a wrong handover moves them by metres) and the impact losses to
// 1e-9 of m g·1 m.
TEST(ContactTerrainPoints, OneAndTwoPointsRollTheSameBallOverABumpyMesh) {
  const double rho = 0.1, mass = 0.5;
  const Support ground{bumpy(), StaticMotion{}, "bumpy"};
  const Model model = ballModel(mass, rho);
  VecX q = neutralConfiguration(model);
  q.head<3>() = Vec3(0, 0.1, 1.1);
  VecX v = VecX::Zero(model.nv);
  v[3] = 2;
  VecX end[2];
  double loss[2];
  for (int points : {1, 2}) {
    SCOPED_TRACE(points);
    ContactSpec spec = ballContact(ContactKind::Rolling, Shape{Sphere{rho}}, ground);
    spec.mu = 0.8;
    spec.restitution = 0.6;
    spec.points = points;
    ConstraintList list;
    for (auto& c : makeContactPoints(spec)) list.push_back(c);
    Simulator sim(model, list, makeSolver(Formulation::Tree, model, list),
                  IntegratorType::DormandPrince54, appell::test::tightIntegrator());
    ASSERT_TRUE(sim.setState(0, q, v)) << sim.lastStateError();
    const auto run = appell::test::runWatching(sim, 8.0, [](const Simulator&) { return 0.0; }, 0.05);
    EXPECT_GT(run.modeEvents().size(), 50u);
    EXPECT_LT(run.worst_energy, 1e-8);
    end[points - 1] = sim.q();
    loss[points - 1] = sim.impactEnergyLoss();
  }
  EXPECT_LT((end[0] - end[1]).norm(), 1e-6);
  EXPECT_NEAR(loss[0], loss[1], 1e-9 * mass * kG);
}

// Protects the description's checks: points outside 1 … 4, several points
// on a support other than a terrain, or on a bilateral contact, are errors
// naming the contact.
TEST(ContactTerrainPoints, BadPointCountsAreRefusedNamingTheContact) {
  ContactSpec spec = ballContact(ContactKind::Rolling, Shape{Sphere{0.1}},
                                 Support{trough(0.3), StaticMotion{}, "valley"});
  spec.options.name = "wheel";
  using appell::test::invalidArgumentMessage;
  spec.points = 5;
  EXPECT_NE(invalidArgumentMessage([&] { makeContactPoints(spec); })
                .find("contact 'wheel': 'points' must be 1 … 4"),
            std::string::npos);
  spec.points = 2;
  EXPECT_NE(invalidArgumentMessage([&] { makeContact(spec); }).find("makeContactPoints"),
            std::string::npos);
  spec.unilateral = false;
  EXPECT_NE(invalidArgumentMessage([&] { makeContactPoints(spec); })
                .find("contact 'wheel': more than one point needs a unilateral contact"),
            std::string::npos);
  spec.unilateral = true;
  spec.support = Support{Plane{}, StaticMotion{}, "floor"};
  EXPECT_NE(invalidArgumentMessage([&] { makeContactPoints(spec); })
                .find("contact 'wheel': more than one point needs a terrain support"),
            std::string::npos);
}

// Protects the scene format's `points`: a ball declared with points="2" on a
// terrain loads as two contacts ball/p0 and ball/p1 (their origin names the
// point); points on a plane, or outside 1 … 4, are errors naming the file,
// the <contact> element and the reason.
TEST(ContactTerrainPoints, TheSceneFormatDeclaresPointsAndRefusesBadOnes) {
  const std::string urdf = R"(<?xml version="1.0"?>
<robot name="ball">
  <link name="ball">
    <inertial><mass value="0.5"/><inertia ixx="0.002" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.002"/></inertial>
    <collision><geometry><sphere radius="0.1"/></geometry></collision>
  </link>
  <appell>
    <support name="hills" type="terrain" filename=")" APPELL_SOURCE_DIR R"(/examples/car_bump/bump.obj"/>
    <support name="floor" type="plane"/>
    <contact name="ball" link="ball" kind="rolling" support="hills" points="2"/>
    <initial><joint name="root_joint" xyz="0 0 0.5"/></initial>
  </appell>
</robot>)";
  const Scene scene = loadSceneFromString(urdf, ".");
  ASSERT_EQ(scene.contacts.size(), 2u);
  EXPECT_EQ(scene.contacts[0]->name(), "ball/p0");
  EXPECT_EQ(scene.contacts[1]->name(), "ball/p1");
  EXPECT_NE(scene.contact_origins[1].shape_source.find("point 1"), std::string::npos);
  auto message = [&](const std::string& from, const std::string& to) {
    std::string bad = urdf;
    bad.replace(bad.find(from), from.size(), to);
    try {
      loadSceneFromString(bad, ".");
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string("(accepted)");
  };
  const std::string on_plane = message("support=\"hills\" points", "support=\"floor\" points");
  EXPECT_NE(on_plane.find("<contact name=\"ball\">"), std::string::npos) << on_plane;
  EXPECT_NE(on_plane.find("more than one point needs a terrain support"), std::string::npos)
      << on_plane;
  const std::string five = message("points=\"2\"", "points=\"5\"");
  EXPECT_NE(five.find("'points' must be a whole number from 1 to 4"), std::string::npos) << five;
}

// Protects a rolling ball's handovers between two points (examples/
// ball_gutter). A ball rolling along a V gutter (slopes ±α, α = atan 3/8)
// from rest across it on one slope rolls down with acceleration
// (5/7) g sin α, reaches the bottom after √(2 d/((5/7) g sin α)), d = 0.5/cos α,
// and the second point touches down on the other slope. The plastic rolling
// impact keeps the angular momentum about the new contact point:
//   I u/ρ + m ρ u cos 2α = I u′/ρ + m ρ u′   ⇒   u′/u = (2/5 + cos 2α)/(7/5)
// of the speed across (the first point lifts off), and the ball rolls up
// the other slope and back in 2u′/((5/7) g sin α). The points take turns;
// the touchdown speeds (−u sin 2α) follow to 1e-9 and the times to 1e-8
// (after ~40 events), the sequence ends, and the ball rolls on along the
// bottom on both walls, centred.
TEST(ContactTerrainPoints, TheGutterExampleHandsOverBetweenItsPointsAsAngularMomentumSays) {
  const Scene scene = loadScene(APPELL_SOURCE_DIR "/examples/ball_gutter/ball_gutter.urdf");
  ASSERT_EQ(scene.contacts.size(), 2u);
  const double alpha = std::atan(0.375), rho = 0.1;
  const double acc = 5.0 / 7.0 * kG * std::sin(alpha);
  const double keep = (0.4 + std::cos(2 * alpha)) / 1.4;
  Simulator sim(scene.model, scene.constraints,
                makeSolver(Formulation::Tree, scene.model, scene.constraints),
                IntegratorType::DormandPrince54, appell::test::tightIntegrator());
  ASSERT_TRUE(sim.setState(0, scene.q0, scene.v0)) << sim.lastStateError();
  ASSERT_TRUE(sim.isClosed(0));
  ASSERT_FALSE(sim.isClosed(1));
  const auto run = appell::test::runWatching(sim, 9.0, [](const Simulator&) { return 0.0; }, 0.05);
  std::vector<ContactEvent> touchdowns;
  for (const ContactEvent& e : run.modeEvents())
    if (e.kind == ContactEventKind::Touchdown) touchdowns.push_back(e);
  ASSERT_GE(touchdowns.size(), 20u);
  EXPECT_LT(touchdowns.size(), 60u) << "the sequence ends";
  double t = std::sqrt(2 * (0.5 / std::cos(alpha)) / acc), u = acc * t;
  for (size_t k = 0; k < touchdowns.size(); ++k) {
    SCOPED_TRACE(k);
    EXPECT_EQ(touchdowns[k].constraint, static_cast<int>((k + 1) % 2)) << "the points take turns";
    EXPECT_NEAR(touchdowns[k].t, t, 1e-8);
    if (u * std::sin(2 * alpha) > 2e-3) {
      EXPECT_NEAR(touchdowns[k].speed_before, -u * std::sin(2 * alpha), 1e-9);
    }
    u *= keep;
    t += 2 * u / acc;
  }
  EXPECT_TRUE(sim.isClosed(0) && sim.isClosed(1)) << "rolling on both walls";
  EXPECT_NEAR(sim.q()[0], 0, 1e-9);
  EXPECT_NEAR(sim.q()[2], rho / std::cos(alpha), 1e-9);
  EXPECT_GT(sim.q()[1], 5.0) << "still rolling along the gutter";
  EXPECT_LT(run.worst_energy, 1e-8);
}
