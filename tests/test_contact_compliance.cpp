// Compliant contacts (ContactLaw::normal_stiffness, normal_damping; docs/
// contacts.md §10): a table on four compliant feet, one of them 0.1 mm
// long, carries the loads its warp demands — the closed form of a rigid body
// on four springs, where rigid feet leave the split indeterminate, and its
// heave the mean static deflection m g/(4k); a drop onto them keeps its
// balance; the event scheme refuses them; the scene file checks the
// attributes. And a drop started in time-stepping keeps its energy in
// flight (the trapezoidal position of a contact-free step) or, driven,
// books the θ-method's own term ½ m g² h² a step.
#include <gtest/gtest.h>

#include <appell/run.hpp>
#include <appell/simulator.hpp>
#include <appell/urdf.hpp>

#include "scene_helpers.hpp"

#include <cmath>
#include <sstream>
#include <string>

using namespace appell;

namespace {

constexpr double kG = 9.81, kMass = 2.0, kStiffness = 1e5;

// A 2 kg table top, its centre of mass over the middle of four point feet at
// (±0.2, ±0.1, foot_z) m; foot c4 is `longer` m longer. `law` is each foot's
// extra attributes; the top starts at `height`.
std::string table(double longer, const std::string& law, double height = 0.05,
                  double foot_z = -0.05) {
  std::ostringstream x;
  x.precision(17);
  x << R"(<robot name="table"><link name="top">
<inertial><mass value="2"/><inertia ixx="0.008" ixy="0" ixz="0" iyy="0.027" iyz="0" izz="0.033"/></inertial></link>
<appell><support name="floor" type="plane" normal="0 0 1" offset="0"/>
)";
  const double xy[4][2] = {{0.2, 0.1}, {-0.2, 0.1}, {-0.2, -0.1}, {0.2, -0.1}};
  for (int i = 0; i < 4; ++i)
    x << "<contact name=\"c" << i + 1 << "\" link=\"top\" kind=\"sliding\" support=\"floor\" point=\""
      << xy[i][0] << ' ' << xy[i][1] << ' ' << foot_z - (i == 3 ? longer : 0.0) << "\" " << law << "/>\n";
  x << "<initial><joint name=\"root_joint\" xyz=\"0 0 " << height << "\"/></initial></appell></robot>";
  return x.str();
}

RunOptions options(double duration, ContactScheme scheme = ContactScheme::Auto) {
  RunOptions o;
  o.duration = duration;
  o.contacts = scheme;
  o.integrator = IntegratorType::RK4;
  o.dt = 1e-3;
  return o;
}

double normalForce(const Scene& s, const Simulator& sim, int c) {
  return sim.lambda()[sim.constraintData().offset[c] + s.constraints[c]->unilateralRow()];
}

}  // namespace

// A rigid body on four springs of stiffness k at (±a, ±b), one foot longer by
// e: heave, roll and pitch take up all of e but its warp part, (e/4)(1, −1,
// 1, −1) in the order c1 … c4 with c4 the long foot, so the long foot and
// its diagonal carry m g/4 + k e/4 and the other two m g/4 − k e/4 —
// whatever a and b. (The feet lie in the plane of the centre of mass, so
// that the table's tilt, e/(4b) = 2.5e-4 rad, moves them sideways only to
// second order: feet 5 cm below it shift the loads by 8e-4 N, the tilt's
// lever.) Dropped from 1 cm above touching, the table settles on its
// dampers (the auto scheme time-steps a compliant scene throughout) to
// those loads within 1e-6 of the weight.
TEST(ContactCompliance, FourCompliantFeetCarryTheLoadsTheirWarpDemands) {
  const double e = 1e-4;
  const Scene s = loadSceneFromString(
      table(e, R"(normal_stiffness="100000" normal_damping="200")", 0.01, 0.0), ".", "table.urdf");
  auto sim = makeSimulator(s, options(2));
  while (sim->time() < 2 - 1e-12) ASSERT_TRUE(sim->step(1e-3).ok);
  EXPECT_EQ(sim->counters().timestepping_steps, sim->counters().steps) << "time-stepped throughout";
  const double quarter = kMass * kG / 4, warp = kStiffness * e / 4;
  const double expected[4] = {quarter - warp, quarter + warp, quarter - warp, quarter + warp};
  double sum = 0;
  for (int c = 0; c < 4; ++c) {
    EXPECT_NEAR(normalForce(s, *sim, c), expected[c], 1e-6 * kMass * kG) << "foot c" << c + 1;
    sum += normalForce(s, *sim, c);
  }
  EXPECT_NEAR(sum, kMass * kG, 1e-9 * kMass * kG);
  // Heave: the feet's mean gap, z − e/4, is the mean deflection −m g/(4k).
  EXPECT_NEAR(sim->q()[2], e / 4 - quarter / kStiffness, 1e-9);
}

// The run's balance with the spring's work counted as the contacts' (its
// stored energy leaves E): a drop onto compliant feet closes to the scheme's
// O(h); in flight, before the feet touch at t = √(2 · 0.01/g) = 0.045 s,
// the energy is exact (the trapezoidal position of a contact-free step).
TEST(ContactCompliance, ADropOntoCompliantFeetKeepsItsBalance) {
  const Scene s = loadSceneFromString(
      table(0, R"(normal_stiffness="100000" normal_damping="200")", 0.06), ".", "table.urdf");
  auto sim = makeSimulator(s, options(1));
  const double e0 = sim->energy();
  while (sim->time() < 0.04) {
    ASSERT_TRUE(sim->step(1e-3).ok);
    EXPECT_NEAR(sim->energy(), e0, 1e-13 * e0) << "t = " << sim->time();
  }
  const RunSummary r = runScene(s, options(1));
  ASSERT_TRUE(r.ok) << r.failure;
  EXPECT_LT(r.relativeEnergyDeviation(), 0.05);
  EXPECT_GT(r.impact_energy_loss, 0.5 * kMass * kG * 0.01) << "the dampers took the fall";
}

// A rigid drop started in time-stepping passes its first steps in flight
// (θ = 1 there lost half the exchanged potential energy at the first step,
// and the run stopped as diverging) and lands plastically, its balance
// closed to 1e-4 (0.025 before the scheme's own term was counted).
TEST(ContactCompliance, ARigidDropStartedInTimeSteppingRuns) {
  const Scene s = loadSceneFromString(table(0, "", 0.06), ".", "table.urdf");
  const RunSummary r = runScene(s, options(0.5, ContactScheme::TimeStepping));
  ASSERT_TRUE(r.ok) << r.failure;
  EXPECT_LT(r.relativeEnergyDeviation(), 1e-4);
  EXPECT_GT(r.impact_energy_loss, 0.9 * kMass * kG * 0.01) << "the landing took the fall's energy";
}

// With a joint force (any: here zero) a step keeps θ = 1, whose position
// q + h v⁺ lies below the trapezoidal one by h² g/2: in free fall the
// scheme's own term is exactly ½ m g² h² a step, and with it the balance
// closes to round-off.
TEST(ContactCompliance, TheThetaMethodsOwnTermIsHalfMGSquaredHSquaredAStepInFreeFall) {
  const Scene s = loadSceneFromString(table(0, "", 0.5), ".", "table.urdf");
  auto sim = makeSimulator(s, options(1, ContactScheme::TimeStepping));
  sim->setJointForces([](double, const VecX&, const VecX&, VecX& tau) { tau.setZero(); });
  const double h = 1e-3, e0 = sim->energy();
  for (int k = 1; k <= 100; ++k) {
    ASSERT_TRUE(sim->step(h).ok);
    EXPECT_NEAR(sim->schemeEnergyLoss(), k * 0.5 * kMass * kG * kG * h * h, 1e-12) << "step " << k;
    EXPECT_NEAR(sim->energy() + sim->schemeEnergyLoss(), e0, 1e-12 * e0) << "step " << k;
  }
}

TEST(ContactCompliance, TheEventSchemeRefusesACompliantContact) {
  const Scene s = loadSceneFromString(table(0, R"(normal_stiffness="100000")"), ".", "table.urdf");
  try {
    makeSimulator(s, options(1, ContactScheme::Events));
    FAIL() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("contact 'c1' is compliant"), std::string::npos) << e.what();
  }
}

TEST(ContactCompliance, BadAttributesAreNamed) {
  auto message = [](const std::string& law) { return test::loadMessage(table(0, law), "table.urdf"); };
  EXPECT_NE(message(R"(normal_damping="5")").find("'normal_damping' needs a 'normal_stiffness'"),
            std::string::npos);
  EXPECT_NE(message(R"(normal_stiffness="-1")").find("'normal_stiffness' must be a positive"),
            std::string::npos);
  EXPECT_NE(message(R"(normal_stiffness="1e5" normal_damping="-2")").find("'normal_damping' must be ≥ 0"),
            std::string::npos);
  EXPECT_NE(message(R"(normal_stiffness="1e5" restitution="0.5")").find("takes no 'restitution'"),
            std::string::npos);
  EXPECT_NE(message(R"(normal_damping="5")").find("table.urdf:"), std::string::npos)
      << "the message names the file and line";
  EXPECT_EQ(message(R"(normal_stiffness="1e5" normal_damping="20")"), "(loaded)");
}
