// FCL as the contact geometry's second opinion (collision.hpp): its gap,
// witness points and normal against the exact analytic geometry, along real
// trajectories, and the pairs it cannot represent refused by name.
#include <gtest/gtest.h>

#include <appell/collision.hpp>
#include <appell/kinematics.hpp>
#include <appell/simulator.hpp>

#include "ball.hpp"
#include "rolling_disk.hpp"
#include "simulation_helpers.hpp"

#include <cmath>

using namespace appell;
using namespace appell::scenes;

namespace {

struct Disagreement {
  double gap = 0, point = 0, normal = 0;  ///< largest differences over the samples
  int samples = 0;
};

// Steps the scene for 1 s with the analytic contact closed, and at every
// 10 ms compares FCL's distance query on the contact's shape and support with
// the analytic geometry of the same state.
Disagreement compareAlongTrajectory(const BuiltScene& s) {
  const auto& contact = static_cast<const ShapeContact&>(*s.constraints[0]);
  const auto body = makeCollisionGeometry(contact.shape());
  const auto support = makeCollisionGeometry(contact.support());
  Simulator sim(s.model, s.constraints, makeSolver(Formulation::Tree, s.model, s.constraints),
                IntegratorType::DormandPrince54, appell::test::tightIntegrator());
  EXPECT_TRUE(sim.setState(0, s.q0, s.v0)) << sim.lastStateError();
  Data data(s.model);
  Disagreement d;
  for (int k = 0; k <= 100; ++k) {
    if (k > 0) {
      const StepStatus st = sim.step(0.01);
      EXPECT_TRUE(st.ok) << st.message;
    }
    forwardKinematics(s.model, data, sim.q(), sim.v());
    ContactGeometry exact;
    contact.geometry(data.oMi[0], spatialVelocityWorld(data, 0), sim.time(), exact);
    EXPECT_FALSE(exact.singular);
    const Proximity fcl = proximity(*body, data.oMi[0], *support, SE3::Identity());
    d.gap = std::max(d.gap, std::abs(fcl.distance - exact.gap));
    d.point = std::max(d.point, (fcl.body_point - exact.point).norm());
    // At contact the witness points coincide and FCL's normal is undefined;
    // compare it only where FCL states one.
    if ((fcl.body_point - fcl.support_point).norm() > 1e-6)
      d.normal = std::max(d.normal, (fcl.normal - exact.normal).norm());
    ++d.samples;
  }
  return d;
}

}  // namespace

// Protects: FCL's geometry of a sphere on a plane (a slab standing for the
// plane) is the analytic one: gap and contact point to 1e-9 along 1 s of
// rolling with spin.
TEST(ContactCollision, SphereOnAPlaneAgreesWithTheAnalyticGeometry) {
  BuiltScene s = ball();
  const Disagreement d = compareAlongTrajectory(s);
  EXPECT_EQ(d.samples, 101);
  EXPECT_LT(d.gap, 1e-9);
  EXPECT_LT(d.point, 1e-9);
}

// Protects the recorded limit of GJK witness points (docs/contacts.md §9):
// on a leaning, precessing disk FCL's gap agrees to 1e-9, but its witness
// point slides along the rim tangent, where the distance is flat to second
// order (3.2e-7 m on this trajectory, 1e-5 m in other poses) — which is why a closed rolling contact keeps the
// analytic geometry. If FCL became exact the bound below would still hold; if
// its gap ever drifted, this fails.
TEST(ContactCollision, DiskOnAPlaneGapAgreesButTheWitnessPointIsOnlyApproximate) {
  RollingDiskParams p;
  p.lean = 0.3;
  p.precession = 1.0;
  p.axle_rate = 6.0;
  BuiltScene s = rollingDisk(p);
  const Disagreement d = compareAlongTrajectory(s);
  EXPECT_EQ(d.samples, 101);
  EXPECT_LT(d.gap, 1e-9);
  EXPECT_LT(d.point, 1e-4 * p.radius) << "witness point error grew past the recorded size";
  std::printf("disk on a plane over 1 s: |Δgap| ≤ %.2e m, |Δpoint| ≤ %.2e m\n", d.gap, d.point);
}

// Protects: a box's FCL distance to a plane and to a terrain face is the
// height of its lowest corner, and a penetrating box reports a negative
// distance (what touchdown of a non-smooth shape needs).
TEST(ContactCollision, BoxDistanceIsItsLowestCornerHeight) {
  const Box box{Vec3(0.2, 0.1, 0.05), SE3::Identity()};
  const auto g = makeCollisionGeometry(box);
  const Mat3 R = axisAngle(Vec3(1, 2, 0.5).normalized(), 0.4);
  const Vec3 p(0.3, -0.2, 0.5);
  double lowest = INFINITY;
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner(c & 1 ? 0.2 : -0.2, c & 2 ? 0.1 : -0.1, c & 4 ? 0.05 : -0.05);
    lowest = std::min(lowest, (R * corner + p).z());
  }
  const auto plane = makeCollisionGeometry(Support{Plane{}, StaticMotion{}, "ground"});
  const Proximity above = proximity(*g, SE3{R, p}, *plane, SE3::Identity());
  EXPECT_NEAR(above.distance, lowest, 1e-10);
  EXPECT_NEAR(above.body_point.z(), lowest, 1e-10);
  EXPECT_NEAR(above.normal.z(), 1.0, 1e-9);

  const TerrainMesh flat = makeTerrain({{-5, -5, 0}, {5, -5, 0}, {5, 5, 0}, {-5, 5, 0}},
                                       {{0, 1, 2}, {0, 2, 3}});
  const auto terrain = makeCollisionGeometry(Support{flat, StaticMotion{}, "terrain"});
  EXPECT_NEAR(proximity(*g, SE3{R, p}, *terrain, SE3::Identity()).distance, lowest, 1e-10);

  const SE3 sunk{R, p - Vec3(0, 0, lowest + 0.01)};
  Vec3 where;
  EXPECT_TRUE(collide(*g, sunk, *plane, SE3::Identity(), &where));
  EXPECT_NEAR(proximity(*g, sunk, *plane, SE3::Identity()).distance, -0.01, 1e-8);
  EXPECT_LT(where.z(), 1e-9);
  EXPECT_FALSE(collide(*g, SE3{R, p}, *plane, SE3::Identity()));
}

// Protects: what FCL cannot represent is refused with the shape or support
// named and the reason — never a crash inside FCL (its Halfspace distance
// dereferences a null support function).
TEST(ContactCollision, UnrepresentablePairsAreRefusedByName) {
  auto message = [](auto&& make) { return appell::test::invalidArgumentMessage(make); };
  EXPECT_NE(message([] { makeCollisionGeometry(Torus{0.3, 0.05, Vec3::Zero(), Vec3::UnitY()}); })
                .find("torus: FCL cannot represent it"),
            std::string::npos);
  EXPECT_NE(message([] { makeCollisionGeometry(SphericalCap{}); }).find("spherical"),
            std::string::npos);
  EXPECT_NE(message([] {
              makeCollisionGeometry(Mesh{"foot.stl", Vec3::Ones(), {}, {}, {}});
            }).find("mesh 'foot.stl'"),
            std::string::npos);
  SphereSurface bowl;
  bowl.radius = 1;
  EXPECT_NE(message([&] { makeCollisionGeometry(Support{bowl, StaticMotion{}, "bowl"}); })
                .find("support 'bowl': FCL cannot represent it (the inside of a sphere"),
            std::string::npos);
}

// Protects the terrain's candidate searches (each widens its box until the
// best feature must be inside): over a bumpy 32 × 32 grid, at 400 random
// positions from touching to 2 m above,
//  - a sphere's gap is FCL's exact sphere–mesh distance (FCL's own traversal
//    of the hierarchy, sphere–triangle in closed form), its support point
//    FCL's nearest point — on a face, an edge or a vertex (terrain_sphere.cpp);
//  - an ellipsoid's gap is FCL's GJK distance (to 1e-6, GJK's accuracy) —
//    faces, edges and vertices all count — and never above the face model's
//    brute-force gap (every face tried as a plane, the smallest gap among
//    faces whose triangle holds the foot of the contact point).
TEST(ContactCollision, TerrainSearchFindsTheNearestFeatureAtAnyHeight) {
  std::vector<Vec3> v;
  std::vector<std::array<int, 3>> t;
  const int n = 32;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      v.emplace_back(-4 + 8.0 * i / n, -4 + 8.0 * j / n, 0.2 * std::sin(0.9 * i) * std::cos(0.7 * j));
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i;
      t.push_back({a, a + 1, a + n + 2});
      t.push_back({a, a + n + 2, a + n + 1});
    }
  const TerrainMesh mesh = makeTerrain(v, t);
  const Support bumps{mesh, StaticMotion{}, "bumps"};
  const Sphere ball{0.1, Vec3::Zero()};
  const Ellipsoid egg{Vec3(0.1, 0.07, 0.05), Vec3::Zero(), axisAngle(Vec3(1, 1, 0).normalized(), 0.3)};
  const auto on_ball = makeContact(ContactKind::Rolling, 0, ball, bumps);
  const auto on_egg = makeContact(ContactKind::Rolling, 0, egg, bumps);
  std::vector<std::shared_ptr<ShapeContact>> faces;
  for (int f = 0; f < static_cast<int>(t.size()); ++f)
    faces.push_back(makeContact(ContactKind::Rolling, 0, egg,
                                Support{Plane{v[t[f][0]], terrainFaceNormal(mesh, f)},
                                        StaticMotion{}, "face"}));
  auto holds = [&](int f, const Vec3& p) {
    const Vec3 &a = v[t[f][0]], &b = v[t[f][1]], &c = v[t[f][2]];
    const Vec3 nf = terrainFaceNormal(mesh, f);
    return nf.dot((b - a).cross(p - a)) >= -1e-12 && nf.dot((c - b).cross(p - b)) >= -1e-12 &&
           nf.dot((a - c).cross(p - c)) >= -1e-12;
  };
  const auto body = makeCollisionGeometry(Shape{ball});
  const auto egg_fcl = makeCollisionGeometry(Shape{egg});
  const auto terrain = makeCollisionGeometry(bumps);
  std::srand(7);
  auto uniform = [] { return std::rand() / double(RAND_MAX); };
  int held = 0;
  for (int k = 0; k < 400; ++k) {
    const SE3 pose{Mat3::Identity(), Vec3(-3.5 + 7 * uniform(), -3.5 + 7 * uniform(),
                                          0.35 + 2 * uniform())};
    ContactGeometry g;
    on_ball->geometry(pose, Vec6::Zero(), 0.0, g);
    ASSERT_FALSE(g.singular) << "at " << pose.p.transpose();
    const Proximity p = proximity(*body, pose, *terrain, SE3::Identity());
    EXPECT_NEAR(g.gap, p.distance, 1e-9) << "at " << pose.p.transpose();
    EXPECT_LT((g.support_point - p.support_point).norm(), 1e-6) << "at " << pose.p.transpose();
    EXPECT_LT((g.point - p.body_point).norm(), 1e-6) << "at " << pose.p.transpose();

    on_egg->geometry(pose, Vec6::Zero(), 0.0, g);
    ASSERT_FALSE(g.singular) << "at " << pose.p.transpose();
    double brute = INFINITY;  // the face model alone: an upper bound
    for (int f = 0; f < static_cast<int>(faces.size()); ++f) {
      ContactGeometry h;
      faces[f]->geometry(pose, Vec6::Zero(), 0.0, h);
      if (holds(f, h.support_point)) brute = std::min(brute, h.gap);
    }
    EXPECT_LE(g.gap, brute + 1e-12) << "at " << pose.p.transpose();
    const double gjk = proximity(*egg_fcl, pose, *terrain, SE3::Identity()).distance;
    EXPECT_NEAR(g.gap, gjk, 1e-6) << "at " << pose.p.transpose();
    held += g.gap < brute - 1e-9;  // an edge or vertex nearer than every holding face
  }
  EXPECT_GT(held, 50) << "edges and vertices matter on this mesh";
  std::printf("  %d of 400 ellipsoid contacts on an edge or vertex\n", held);
}
