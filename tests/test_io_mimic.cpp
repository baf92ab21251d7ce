// URDF <mimic> joints as holonomic joint-space rows q_f = m q_l + o
// (joint_coupling.hpp): a parallel gripper and a gear train against their
// closed-form motion and reaction, a coupled double pendulum conserving energy
// in all three formulations, the follower's initial state taken from its
// leader, and every malformed coupling refused with file, line and reason.
#include <appell/appell.hpp>
#include <appell/run.hpp>
#include <appell/urdf.hpp>

#include "scene_helpers.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

using namespace appell;

namespace {

std::string link(const std::string& name, double mass, double ixx, double iyy, double izz) {
  return "<link name=\"" + name + "\"><inertial><mass value=\"" + std::to_string(mass) +
         "\"/><inertia ixx=\"" + std::to_string(ixx) + "\" ixy=\"0\" ixz=\"0\" iyy=\"" +
         std::to_string(iyy) + "\" iyz=\"0\" izz=\"" + std::to_string(izz) + "\"/></inertial></link>\n";
}

// A parallel gripper on a fixed palm: two fingers sliding along y, the right
// one mimicking the left with multiplier −1 and offset 0.02 (the fingers
// start 2 cm apart). Gravity is along z, across the fingers' motion; the left
// finger is pushed by `effort` N.
std::string gripper(const std::string& mimic, const std::string& initial = "",
                    double effort = 2.0) {
  return "<robot name=\"gripper\">\n<link name=\"world\"/>\n" + link("palm", 1, 0.01, 0.01, 0.01) +
         link("left_finger", 0.3, 1e-4, 1e-4, 1e-4) + link("right_finger", 0.5, 1e-4, 1e-4, 1e-4) +
         R"(<joint name="palm_joint" type="fixed"><parent link="world"/><child link="palm"/></joint>
<joint name="left_joint" type="prismatic"><parent link="palm"/><child link="left_finger"/>
  <axis xyz="0 1 0"/><limit lower="-10" upper="10" effort="100" velocity="1"/></joint>
<joint name="right_joint" type="prismatic"><parent link="palm"/><child link="right_finger"/>
  <axis xyz="0 1 0"/><limit lower="-10" upper="10" effort="100" velocity="1"/>)" +
         mimic + R"(</joint>
<appell><gravity xyz="0 0 -9.81"/>)" +
         initial + "<effort joint=\"left_joint\" value=\"" + std::to_string(effort) +
         "\"/></appell>\n</robot>";
}

const std::string kGripperMimic = R"(<mimic joint="left_joint" multiplier="-1" offset="0.02"/>)";

std::string loadError(const std::string& xml, const LoadOptions& options = {}) {
  return test::loadMessage(xml, "mimic.urdf", options);
}

RunOptions tight(Formulation f) { return test::tightRun(1.0, f); }

}  // namespace

// Left finger m₁, right m₂ = follower with q₂ = −q₁ + o: the pair moves as one
// mass m₁ + m₂ (m² = 1) under F, so q₁ = ½ F/(m₁ + m₂) t², and the coupling
// pushes the right finger with λ = m₂ q̈₂ = −m₂ F/(m₁ + m₂) (the row is
// ġ = v₂ − m v₁, its force +λ on the follower and −m λ on the leader).
TEST(Mimic, ParallelGripperMovesAsOneMassAndTheCouplingForceIsExact) {
  const Scene s = loadSceneFromString(gripper(kGripperMimic), ".", "gripper.urdf");
  ASSERT_EQ(s.couplings.size(), 1u);
  EXPECT_EQ(s.couplings[0]->name(), "right_joint_mimic");
  const int iq1 = s.model.joints[s.model.jointIndex("left_joint")].idx_q;
  const int iq2 = s.model.joints[s.model.jointIndex("right_joint")].idx_q;
  EXPECT_DOUBLE_EQ(s.q0[iq2], 0.02);  // started where the leader puts it
  const double m1 = 0.3, m2 = 0.5, F = 2.0, a = F / (m1 + m2);
  for (Formulation f : {Formulation::Tree, Formulation::Multipliers, Formulation::Appell}) {
    SCOPED_TRACE(toString(f));
    auto sim = makeSimulator(s, tight(f));
    const StepStatus st = sim->advanceTo(1.0, 1e-3);
    ASSERT_TRUE(st.ok) << st.message;
    EXPECT_NEAR(sim->q()[iq1], 0.5 * a, 1e-11);
    EXPECT_NEAR(sim->q()[iq2], -0.5 * a + 0.02, 1e-11);
    EXPECT_EQ(s.constraints.back(), s.couplings[0]);
    const int row = s.constraintRows() - 1;  // the coupling's row is the last
    EXPECT_NEAR(sim->lambda()[row], -m2 * a, 1e-10);
  }
}

// A gear train: a hand wheel (I_h about x) drives two knuckles through
// ratios r_l and r_r (different signs and sizes): α_h = τ/(I_h + r_l² I_l +
// r_r² I_r), and each coupling carries the torque I r α_h its knuckle needs.
// The run summary reports those reactions, and the energy balance closes
// (the couplings do no work: ΔE = ∫ τ·v).
TEST(Mimic, GearTrainAccelerationReactionsAndWorkBalance) {
  const double Ih = 0.02, Il = 0.05, Ir = 0.08, rl = 0.25, rr = -0.4, tau = 0.3;
  const std::string xml = "<robot name=\"steering\">\n<link name=\"world\"/>\n" +
                          link("hand", 1, Ih, 0.015, 0.015) + link("knuckle_l", 1, 0.03, 0.03, Il) +
                          link("knuckle_r", 1, 0.05, 0.05, Ir) + R"(
<joint name="hand_joint" type="continuous"><parent link="world"/><child link="hand"/>
  <origin xyz="0 0 1"/><axis xyz="1 0 0"/></joint>
<joint name="left_steer" type="continuous"><parent link="world"/><child link="knuckle_l"/>
  <origin xyz="1 0.5 0"/><axis xyz="0 0 1"/>
  <mimic joint="hand_joint" multiplier="0.25"/></joint>
<joint name="right_steer" type="continuous"><parent link="world"/><child link="knuckle_r"/>
  <origin xyz="1 -0.5 0"/><axis xyz="0 0 1"/>
  <mimic joint="hand_joint" multiplier="-0.4" offset="0.1"/></joint>
<appell><effort joint="hand_joint" value="0.3"/></appell>
</robot>)";
  const Scene s = loadSceneFromString(xml, ".", "steering.urdf");
  ASSERT_EQ(s.couplings.size(), 2u);
  const double alpha = tau / (Ih + rl * rl * Il + rr * rr * Ir);
  RunOptions o = tight(Formulation::Tree);
  o.duration = 2.0;
  const RunSummary r = runScene(s, o);
  ASSERT_TRUE(r.ok) << r.failure;
  ASSERT_EQ(r.contacts.size(), 2u);
  EXPECT_NEAR(r.contacts[0].min_reaction, Il * rl * alpha, 1e-10);
  EXPECT_NEAR(r.contacts[0].max_reaction, Il * rl * alpha, 1e-10);
  EXPECT_NEAR(r.contacts[1].min_reaction, Ir * rr * alpha, 1e-10);
  EXPECT_NEAR(r.joint_work, 0.5 * (Ih + rl * rl * Il + rr * rr * Ir) * std::pow(alpha * 2.0, 2), 1e-9);
  EXPECT_LT(r.max_gap_residual, 1e-12);
  auto sim = makeSimulator(s, o);
  ASSERT_TRUE(sim->advanceTo(2.0, 1e-3).ok);
  const VecX& q = sim->q();
  const double h = q[s.model.joints[s.model.jointIndex("hand_joint")].idx_q];
  EXPECT_NEAR(h, 0.5 * alpha * 4.0, 1e-10);
  EXPECT_NEAR(q[s.model.joints[s.model.jointIndex("left_steer")].idx_q], rl * h, 1e-12);
  EXPECT_NEAR(q[s.model.joints[s.model.jointIndex("right_steer")].idx_q], rr * h + 0.1, 1e-12);
}

// Two pendulums under gravity on perpendicular axes, the second following the
// first at half its angle plus 0.1 rad; a third follows the second (a chain
// of couplings). Passive: the energy is conserved, the three formulations
// agree, and the couplings hold to round-off.
TEST(Mimic, CoupledPendulumChainConservesEnergyInEveryFormulation) {
  std::string xml = "<robot name=\"pendula\">\n<link name=\"world\"/>\n";
  for (const char* n : {"a", "b", "c"}) {
    xml += "<link name=\"" + std::string(n) + "\"><inertial><origin xyz=\"0 0 -0.5\"/><mass value=\"1\"/>"
           "<inertia ixx=\"0.02\" ixy=\"0\" ixz=\"0\" iyy=\"0.03\" iyz=\"0\" izz=\"0.01\"/></inertial></link>\n";
  }
  xml += R"(
<joint name="ja" type="continuous"><parent link="world"/><child link="a"/><axis xyz="1 0 0"/></joint>
<joint name="jb" type="continuous"><parent link="world"/><child link="b"/><origin xyz="1 0 0"/>
  <axis xyz="0 1 0"/><mimic joint="ja" multiplier="0.5" offset="0.1"/></joint>
<joint name="jc" type="continuous"><parent link="b"/><child link="c"/><origin xyz="0 0 -1"/>
  <axis xyz="1 0 0"/><mimic joint="jb" multiplier="-2"/></joint>
<appell><initial><joint name="ja" position="0.8" velocity="-0.5"/></initial></appell>
</robot>)";
  const Scene s = loadSceneFromString(xml, ".", "pendula.urdf");
  const Model& m = s.model;
  const int qa = m.joints[m.jointIndex("ja")].idx_q, qb = m.joints[m.jointIndex("jb")].idx_q,
            qc = m.joints[m.jointIndex("jc")].idx_q;
  // The chain settled: b from a, then c from b.
  EXPECT_DOUBLE_EQ(s.q0[qb], 0.5 * 0.8 + 0.1);
  EXPECT_DOUBLE_EQ(s.q0[qc], -2 * (0.5 * 0.8 + 0.1));
  EXPECT_DOUBLE_EQ(s.v0[m.joints[m.jointIndex("jc")].idx_v], -2 * 0.5 * -0.5);
  VecX q_ref;
  for (Formulation f : {Formulation::Tree, Formulation::Multipliers, Formulation::Appell}) {
    SCOPED_TRACE(toString(f));
    RunOptions o = tight(f);
    o.duration = 3.0;
    const RunSummary r = runScene(s, o);
    ASSERT_TRUE(r.ok) << r.failure;
    EXPECT_LT(r.relativeEnergyDeviation(), 1e-10);
    EXPECT_LT(r.max_gap_residual, 1e-12);
    auto sim = makeSimulator(s, o);
    ASSERT_TRUE(sim->advanceTo(3.0, 1e-3).ok);
    const VecX& q = sim->q();
    EXPECT_NEAR(q[qb], 0.5 * q[qa] + 0.1, 1e-12);
    EXPECT_NEAR(q[qc], -2 * q[qb], 1e-12);
    EXPECT_GT(std::abs(q[qa] - 0.8), 0.1);  // it moved
    if (q_ref.size() == 0) q_ref = q;
    else EXPECT_LT((q - q_ref).cwiseAbs().maxCoeff(), 1e-9);
  }
}

// A follower set in <initial> against its leader is not silently moved: the
// initial-state check names the coupling, and --project-initial puts it on.
TEST(Mimic, AFollowerSetAgainstItsLeaderIsNamedOrProjected) {
  const std::string xml =
      gripper(kGripperMimic, R"(<initial><joint name="right_joint" position="0.5"/></initial>)");
  const std::string e = loadError(xml);
  EXPECT_NE(e.find("constraint 'right_joint_mimic' row 'coupling'"), std::string::npos) << e;
  EXPECT_NE(e.find("--project-initial"), std::string::npos) << e;
  LoadOptions o;
  o.project_initial_state = true;
  const Scene s = loadSceneFromString(xml, ".", "mimic.urdf", o);
  const int iq1 = s.model.joints[s.model.jointIndex("left_joint")].idx_q;
  const int iq2 = s.model.joints[s.model.jointIndex("right_joint")].idx_q;
  EXPECT_NEAR(s.q0[iq2], -s.q0[iq1] + 0.02, 1e-10);
}

TEST(Mimic, MalformedCouplingsAreRefusedWithFileLineAndReason) {
  auto expect = [](const std::string& mimic, const std::string& what) {
    const std::string e = loadError(gripper(mimic));
    EXPECT_NE(e.find("mimic.urdf:"), std::string::npos) << e;
    EXPECT_NE(e.find("<mimic"), std::string::npos) << e;
    EXPECT_NE(e.find(what), std::string::npos) << e;
  };
  expect(R"(<mimic joint="thumb"/>)", "mimics joint 'thumb', which is not declared");
  expect(R"(<mimic joint="right_joint"/>)", "mimics itself");
  expect(R"(<mimic joint="palm_joint"/>)", "a fixed joint");
  expect(R"(<mimic joint="left_joint" multiplier="fast"/>)", "multiplier");
  expect(R"(<mimic joint="left_joint" offset="1e309"/>)", "offset");
  expect(R"(<mimic multiplier="2"/>)", "joint");
  // A cycle: left follows right, right follows left.
  std::string xml = gripper(R"(<mimic joint="left_joint"/>)");
  xml.replace(xml.find("</joint>\n<joint name=\"right_joint\""), 8,
              R"(<mimic joint="right_joint"/></joint>)");
  const std::string e = loadError(xml);
  EXPECT_NE(e.find("come back to it"), std::string::npos) << e;
  // Each refusal says what to write instead.
  EXPECT_NE(loadError(gripper(R"(<mimic joint="palm_joint"/>)")).find("remove the <mimic>"), std::string::npos);
}

// A <mimic> left on a fixed joint (a CAD export's or a xacro macro's, the
// joint fixed later) moves nothing: it is ignored with one warning naming
// the line, as Pinocchio ignores it — no coupling row, the gripper unchanged.
TEST(Mimic, AMimicOnAFixedJointIsIgnoredWithAWarning) {
  std::string fixed = gripper(kGripperMimic);
  fixed.replace(fixed.find("</joint>"), 8, R"(<mimic joint="left_joint" multiplier="2"/></joint>)");
  const Scene s = loadSceneFromString(fixed, ".", "mimic.urdf");
  ASSERT_EQ(s.couplings.size(), 1u);  // right_joint's, not palm_joint's
  EXPECT_EQ(s.couplings[0]->follower(), s.model.jointIndex("right_joint"));
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0], "mimic.urdf:6: <mimic>: a fixed joint moves nothing: its <mimic> of "
                           "'left_joint' is ignored");
}

namespace {

// A car with steered front wheels: a hand wheel on the chassis drives both
// knuckles through <mimic multiplier="0.0625"> (a steering ratio of 16:1),
// the knuckles turn about vertical axes through the front wheel centres, and
// all four wheels roll on the ground (ideal rolling). The rear wheels are
// driven with 1 N·m each; `steer` is the hand wheel's initial angle (with
// friction and actuators: examples/steered_car).
std::string steeredCar(double steer) {
  auto wheel = [](const std::string& name) {
    return "<link name=\"" + name + R"("><inertial><mass value="1"/>
  <inertia ixx="0.005925" ixy="0" ixz="0" iyy="0.01125" iyz="0" izz="0.005925"/></inertial>
  <collision><origin rpy="1.5707963267948966 0 0"/><geometry><cylinder radius="0.15" length="0.06"/></geometry></collision></link>
)";
  };
  auto wheelJoint = [](const std::string& name, const std::string& parent, const std::string& child,
                       const std::string& xyz) {
    return "<joint name=\"" + name + "\" type=\"continuous\"><parent link=\"" + parent +
           "\"/><child link=\"" + child + "\"/><origin xyz=\"" + xyz + "\"/><axis xyz=\"0 1 0\"/></joint>\n";
  };
  auto knuckle = [](const std::string& side, const std::string& y) {
    return "<link name=\"knuckle_" + side + R"("><inertial><mass value="0.5"/>
  <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial></link>
<joint name="steer_)" + side + R"(" type="revolute"><parent link="chassis"/><child link="knuckle_)" + side +
           R"("/><origin xyz="0.4 )" + y + R"( 0"/><axis xyz="0 0 1"/><limit lower="-0.6" upper="0.6" effort="50" velocity="2"/>
  <mimic joint="hand_wheel" multiplier="0.0625"/></joint>
)";
  };
  const std::string s = std::to_string(steer);
  return R"(<robot name="steered_car">
<link name="chassis"><inertial><origin xyz="0.1 0 0.1"/><mass value="20"/>
  <inertia ixx="0.666666666666667" ixy="0" ixz="0" iyy="1.73333333333333" iyz="0" izz="2.26666666666667"/></inertial></link>
<link name="hand"><inertial><mass value="0.2"/><inertia ixx="0.002" ixy="0" ixz="0" iyy="0.0015" iyz="0" izz="0.0015"/></inertial></link>
<joint name="hand_wheel" type="revolute"><parent link="chassis"/><child link="hand"/><origin xyz="0.2 0 0.25"/>
  <axis xyz="1 0 0"/><limit lower="-9" upper="9" effort="5" velocity="5"/></joint>
)" + knuckle("left", "0.35") + knuckle("right", "-0.35") + wheel("front_left") + wheel("front_right") +
         wheel("rear_left") + wheel("rear_right") +
         wheelJoint("front_left_joint", "knuckle_left", "front_left", "0 0 0") +
         wheelJoint("front_right_joint", "knuckle_right", "front_right", "0 0 0") +
         wheelJoint("rear_left_joint", "chassis", "rear_left", "-0.4 0.35 0") +
         wheelJoint("rear_right_joint", "chassis", "rear_right", "-0.4 -0.35 0") + R"(
<appell><support name="ground" type="plane" normal="0 0 1" offset="0"/>
  <contact name="fl" link="front_left" kind="rolling" support="ground"/>
  <contact name="fr" link="front_right" kind="rolling" support="ground"/>
  <contact name="rl" link="rear_left" kind="rolling" support="ground"/>
  <contact name="rr" link="rear_right" kind="rolling" support="ground"/>
  <initial><joint name="root_joint" xyz="0 0 0.15"/><joint name="hand_wheel" position=")" + s + R"("/></initial>
  <effort joint="rear_left_joint" value="1"/><effort joint="rear_right_joint" value="1"/>
</appell></robot>)";
}

}  // namespace

// Straight ahead the steered car has two independent velocities (rolling
// forward, turning the steering), drives off under its rear-wheel torques
// with the steering held by symmetry, and its work balance closes. Steered
// at 0.3 rad of hand wheel (≈ 1.1° at the knuckles), the two linearly tied
// knuckles contradict the front wheels' rolling (their axles no longer meet
// the rear axle in one point): only the steering can move, and the loader
// and the run say so (free_velocities) rather than crawling.
TEST(Mimic, SteeredCarDrivesStraightAndReportsTheParallelSteeringLock) {
  const Scene s = loadSceneFromString(steeredCar(0), ".", "steered_car.urdf");
  ASSERT_EQ(s.couplings.size(), 2u);
  RunOptions o = tight(Formulation::Tree);
  o.duration = 1.0;
  const RunSummary r = runScene(s, o);
  ASSERT_TRUE(r.ok) << r.failure;
  EXPECT_EQ(r.free_velocities, 2);
  EXPECT_LT(r.relativeEnergyDeviation(), 1e-9);
  EXPECT_GT(r.joint_work, 0.1);
  auto sim = makeSimulator(s, o);
  ASSERT_TRUE(sim->advanceTo(1.0, 1e-3).ok);
  const Model& m = s.model;
  EXPECT_GT(sim->q()[0], 0.05);                      // drove forward
  EXPECT_NEAR(sim->q()[1], 0, 1e-12);                // straight
  EXPECT_NEAR(sim->q()[m.joints[m.jointIndex("steer_left")].idx_q], 0, 1e-12);

  const Scene turned = loadSceneFromString(steeredCar(0.3), ".", "steered_car.urdf");
  EXPECT_NEAR(turned.q0[m.joints[m.jointIndex("steer_right")].idx_q], 0.3 * 0.0625, 1e-15);
  const RunSummary rt = runScene(turned, o);
  ASSERT_TRUE(rt.ok) << rt.failure;
  EXPECT_EQ(rt.free_velocities, 1);
}

// Protects the issue's Ackermann linkage written with linear mimics, and the
// friction issue's over-constrained vehicle (examples/steered_car): with
// μ = 0.9 the same steered car drives what its actuators command — a
// velocity servos taking the rear wheels from rest to 1 m/s (1.5 N·m at
// most: no wheelspin) while a position servo holds the hand wheel straight,
// then turning it to 0.3 rad (1.07° at the knuckles) over 2 … 2.5 s. The
// parallel knuckles miss Ackermann's by 3·10⁻⁴ rad, so one front tyre must
// scrub (test_friction_vehicles.cpp follows the transition): the outer one (fr) slides on its
// settled direction while the inner one (fl) and the rear tyres roll, and
// the car drives the circle the inner wheel's Ackermann geometry gives —
// yaw rate over the rear axle's speed 1/ρ, ρ = 0.35 + L/tan δ (the inner
// axle line meeting the rear one), to 1e-9 — in under 2500 steps for 6 s at tol 1e-12 (the
// exact sliding law's relaxation, settle time 0, takes 10⁵ per second). The
// work balance, friction included, closes to round-off.
TEST(Mimic, ASteeredCarWithParallelKnucklesTurnsOnTheInnerWheelsCircle) {
  const Scene s = loadScene(std::string(APPELL_SOURCE_DIR) + "/examples/steered_car/steered_car.urdf");
  RunOptions o = tight(Formulation::Tree);
  o.duration = 6.0;
  auto sim = makeSimulator(s, o);
  const double E0 = sim->energy();
  const StepStatus st = sim->advanceTo(6.0, 0.1);
  ASSERT_TRUE(st.ok) << st.message << " at t = " << sim->time();
  EXPECT_LT(sim->counters().steps, 2500) << "no crawl (the exact law: ~6·10⁵)";
  const ConstraintData& cd = sim->constraintData();
  EXPECT_FALSE(cd.isSliding(0)) << "fl rolls";
  EXPECT_TRUE(cd.isSliding(1)) << "fr scrubs";
  EXPECT_FALSE(cd.isSliding(2));
  EXPECT_FALSE(cd.isSliding(3));
  const Model& m = s.model;
  const VecX& v = sim->v();  // root: ω then v of the chassis origin, body frame
  const double delta = sim->q()[m.joints[m.jointIndex("steer_left")].idx_q];
  const double L = 0.8, rho = 0.35 + L / std::tan(delta);
  EXPECT_NEAR(delta, 0.3 * 0.0625, 1e-3 * delta) << "the hand wheel where its servo put it";
  EXPECT_NEAR(v[3], 1.0, 1e-2) << "at the commanded speed";
  EXPECT_NEAR(v[2] / v[3], 1 / rho, 1e-9 / rho) << "the inner wheel's circle";
  EXPECT_NEAR(v[4], 0.4 * v[2], 1e-12) << "the rear axle rolls";
  EXPECT_LT(cd.slide[1].slip.norm(), 1e-3 * v[3]) << "a scrub, not a skid";
  EXPECT_GT(sim->frictionWork(), 0);
  EXPECT_LT(std::abs(sim->energy() + sim->frictionWork() - sim->jointWork() - E0), 1e-10 * E0);
}
