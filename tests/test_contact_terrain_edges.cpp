// Wheels across terrain edges (terrain_features.cpp): a disk or a torus
// rolling off a raised platform pivots about the platform's edge, lifts off
// where its normal force vanishes, flies and lands on the ground below.
#include <gtest/gtest.h>

#include <appell/simulator.hpp>
#include <appell/contacts.hpp>
#include <appell/terrain.hpp>

#include "scene.hpp"
#include "simulation_helpers.hpp"

#include <cmath>

using namespace appell;
using namespace appell::scenes;

namespace {

constexpr double kG = 9.81;
const double kDrop = 0.3 * std::tan(M_PI / 3);  // a 60° cliff 0.3 m wide

// A plateau (z = 0, x ≤ 0), a 60° cliff down to x = 0.3 and the ground below.
TerrainMesh platform() {
  const double h = kDrop;
  return makeTerrain({{-3, -1, 0}, {0, -1, 0}, {0, 1, 0}, {-3, 1, 0},
                      {0.3, -1, -h}, {0.3, 1, -h}, {4, -1, -h}, {4, 1, -h}},
                     {{0, 1, 2}, {0, 2, 3}, {1, 4, 5}, {1, 5, 2}, {4, 6, 7}, {4, 7, 5}});
}

}  // namespace

// Protects the edge contact of wheels. Rolling without slip over the edge,
// a wheel of outer radius R and axial moment k m R² pivots about the edge
// point: (k + 1) m R² φ̈ = m g R sin φ from φ̇₀ = v₀/R, and its normal force
// m (g cos φ − R φ̇²) vanishes at
//     cos φ* = ((k + 1) v₀²/(g R) + 2) / (k + 3)
// (k = ½ for a thin disk: (3v₀²/(gR) + 4)/7). The lift-off is located there
// to 1e-9 in φ — which checks the edge geometry's normal rate and the rows'
// κ through the dynamics — before the cliff face could take over; the wheel
// flies, lands on the cliff face, rolls down into the concave crease at its
// foot — an impact with the ground's face — and rolls on below, E + impact
// losses conserved throughout. Disk (rim) and torus (tyre) alike.
TEST(ContactTerrainEdges, WheelRollsOffAPlatformAndLiftsOffWhereTheoryPredicts) {
  const double R = 0.3, mass = 1.2, v0 = 1.0, k = 0.5;
  const Support ground{platform(), StaticMotion{}, "platform"};
  const Mat3 upright = axisAngle(Vec3::UnitX(), -M_PI / 2);  // axle (body z) along world y
  for (const Shape& wheel : {Shape{Disk{R, Vec3::Zero(), Vec3::UnitZ()}},
                             Shape{Torus{R - 0.04, 0.04, Vec3::Zero(), Vec3::UnitZ()}}}) {
    SCOPED_TRACE(shapeName(wheel));
    ModelBuilder b;
    b.addBody("wheel", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(),
              principalInertia(mass, Vec3(mass * R * R / 4, mass * R * R / 4, k * mass * R * R)),
              "free");
    const Model model = b.build();
    const ConstraintList list{makeContact(ContactKind::Rolling, 0, wheel, ground)};
    VecX q = neutralConfiguration(model);
    setFloatingPose(q, 0, Vec3(-0.3, 0, R), upright);
    const VecX v = floatingVelocity(upright, Vec3(0, v0 / R, 0), Vec3(v0, 0, 0));
    Simulator sim(model, list, makeSolver(Formulation::Tree, model, list),
                  IntegratorType::DormandPrince54, appell::test::tightIntegrator());
    ASSERT_TRUE(sim.setState(0, q, v)) << sim.lastStateError();
    ASSERT_TRUE(sim.isClosed(0));
    const auto run = appell::test::runWatching(
        sim, 1.0, [](const Simulator& s) { return std::atan2(s.q()[0], s.q()[2]); });
    const auto events = run.modeEvents();
    const double phi_lift = run.at_lift_off;
    const double worst = run.worst_energy;
    ASSERT_GE(events.size(), 2u);
    EXPECT_EQ(events[0].kind, ContactEventKind::LiftOff);
    const double phi_star = std::acos(((k + 1) * v0 * v0 / (kG * R) + 2) / (k + 3));
    EXPECT_NEAR(phi_lift, phi_star, 1e-9) << "lift-off where the normal force vanishes";
    EXPECT_LT(phi_star, M_PI / 3) << "before the cliff face could take over";
    EXPECT_EQ(events[1].kind, ContactEventKind::Touchdown) << "lands on the cliff face";
    // It rolls down the cliff into the concave crease at its foot, where the
    // ground's rising face meets it: an impact, its loss counted in the
    // energy balance below.
    ASSERT_EQ(events.size(), 3u);
    EXPECT_EQ(events[2].kind, ContactEventKind::Touchdown);
    EXPECT_LT(events[2].speed_before, -1.0) << "hits the ground at the crease";
    // The changes of piece are located events: onto the platform's edge
    // where the wheel's centre passes over it (t = 0.3/v₀), and onto the
    // ground's face at the crease, with the impact there.
    const auto pieces = run.featureEvents();
    ASSERT_EQ(pieces.size(), 2u);
    EXPECT_NEAR(pieces[0].t, 0.3 / v0, 1e-10) << "onto the edge";
    EXPECT_EQ(pieces[1].t, events[2].t) << "onto the ground's face, with the impact";
    EXPECT_NEAR(sim.q()[2], R - kDrop, 1e-8) << "rolling on the ground below";
    EXPECT_LT((sim.contactFrame(0).normal - Vec3::UnitZ()).norm(), 1e-9);
    EXPECT_LT(worst, 1e-8) << "E + impact losses is conserved";
  }
}
