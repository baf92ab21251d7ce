// Joint servos (actuators.hpp) and the <actuator> element: the set-point
// schedule, a critically damped position servo and a saturated velocity servo
// against their closed forms, the differential-drive robot driving the
// manoeuvre its schedule commands (straight at 0.5 m/s, then the circle its
// wheel rates give), the README's embedding applying the scene's forces, and
// malformed actuators refused with file, line and reason.
#include <appell/appell.hpp>
#include <appell/run.hpp>
#include <appell/urdf.hpp>

#include "scene_helpers.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

using namespace appell;

namespace {

// A rotor: one body on a continuous joint about z (I = 0.05 kg m² about the
// axis, centre of mass on it, so gravity exerts no torque), with `actuator`
// and an optional URDF <limit>.
std::string rotor(const std::string& actuator, const std::string& limit = "") {
  return R"(<robot name="rotor"><link name="world"/>
<link name="disk"><inertial><mass value="2"/><inertia ixx="0.03" ixy="0" ixz="0" iyy="0.03" iyz="0" izz="0.05"/></inertial></link>
<joint name="spin" type="continuous"><parent link="world"/><child link="disk"/><axis xyz="0 0 1"/>)" +
         limit + R"(</joint>
<appell>)" + actuator + R"(</appell></robot>)";
}

std::string loadError(const std::string& xml) { return test::loadMessage(xml, "servo.urdf"); }

RunOptions tight(double duration) { return test::tightRun(duration); }

}  // namespace

TEST(Actuators, ScheduleIsPiecewiseLinearAndHeldOutside) {
  Schedule s{{1, 3, 4}, {2, 6, 0}};
  s.validate();
  EXPECT_EQ(s.at(0), 2);
  EXPECT_EQ(s.at(1), 2);
  EXPECT_DOUBLE_EQ(s.at(2), 4);
  EXPECT_DOUBLE_EQ(s.at(3.5), 3);
  EXPECT_EQ(s.at(10), 0);
  EXPECT_EQ(s.rate(0.5), 0);
  EXPECT_DOUBLE_EQ(s.rate(2), 2);
  EXPECT_DOUBLE_EQ(s.rate(3), -6);  // at a kink: the slope ahead
  EXPECT_EQ(s.rate(4), 0);
  EXPECT_THROW((Schedule{{1, 1}, {0, 1}}.validate()), std::invalid_argument);
  EXPECT_THROW((Schedule{{}, {}}.validate()), std::invalid_argument);
  EXPECT_THROW((Schedule{{0, 1}, {0, NAN}}.validate()), std::invalid_argument);
}

// τ = k_p (q* − q) − k_v q̇ with k_v = 2√(k_p I): I q̈ + k_v q̇ + k_p q = k_p q*,
// critically damped, q(t) = q* (1 − (1 + ω t) e^{−ω t}), ω = √(k_p / I).
TEST(Actuators, PositionServoIsTheCriticallyDampedOscillator) {
  const double I = 0.05, kp = 8, kv = 2 * std::sqrt(kp * I), target = 1.2, w = std::sqrt(kp / I);
  const Scene s = loadSceneFromString(
      rotor("<actuator name=\"hold\" joint=\"spin\" type=\"position\" kp=\"8\" kv=\"" +
            std::to_string(kv) + "\" setpoint=\"1.2\"/>"),
      ".", "rotor.urdf");
  // std::to_string keeps 6 decimals: take the gain the scene really has.
  const double kv_scene = s.actuators.at(0).kv;
  ASSERT_NEAR(kv_scene, kv, 1e-6);
  auto sim = makeSimulator(s, tight(1));
  for (double t : {0.05, 0.1, 0.3, 1.0}) {
    ASSERT_TRUE(sim->advanceTo(t, 1e-3).ok);
    // The closed form for the scene's k_v (a hair off critical): solve
    // I q̈ + k_v q̇ + k_p q = k_p q* from rest by its two real or complex roots.
    const double a = kv_scene / (2 * I), d = a * a - w * w;
    double q;
    if (std::abs(d) < 1e-12) {
      q = target * (1 - (1 + w * t) * std::exp(-w * t));
    } else if (d > 0) {
      const double r1 = -a + std::sqrt(d), r2 = -a - std::sqrt(d);
      q = target * (1 - (r2 * std::exp(r1 * t) - r1 * std::exp(r2 * t)) / (r2 - r1));
    } else {
      const double b = std::sqrt(-d);
      q = target * (1 - std::exp(-a * t) * (std::cos(b * t) + a / b * std::sin(b * t)));
    }
    EXPECT_NEAR(sim->q()[0], q, 1e-9) << "t = " << t;
  }
}

// A velocity servo asked for 100 rad/s with a stiff gain saturates at the
// URDF's <limit effort="0.2">: the rotor spins up at exactly τ_max / I until
// the demand drops below the limit (ω > 100 − 0.2/k_v), then approaches 100
// exponentially; the work done is ½ I ω².
TEST(Actuators, VelocityServoSaturatesAtTheUrdfEffortLimit) {
  const double I = 0.05, tau_max = 0.2, kv = 10;
  const Scene s = loadSceneFromString(
      rotor(R"(<actuator joint="spin" type="velocity" kv="10" setpoint="100"/>)",
            R"(<limit effort="0.2" velocity="200"/>)"),
      ".", "rotor.urdf");
  ASSERT_EQ(s.actuators.size(), 1u);
  EXPECT_EQ(s.actuators[0].name, "spin");  // named after its joint by default
  EXPECT_EQ(s.actuators[0].effort_limit, tau_max);
  auto sim = makeSimulator(s, tight(30));
  ASSERT_TRUE(sim->advanceTo(10, 1e-3).ok);
  EXPECT_NEAR(sim->v()[0], tau_max / I * 10, 1e-9);  // 40 rad/s, still saturated
  const double t_sat = (100 - tau_max / kv) * I / tau_max;  // saturation ends
  ASSERT_TRUE(sim->advanceTo(t_sat + 1, 1e-3).ok);
  const double w_expected = 100 - tau_max / kv * std::exp(-kv / I * 1.0);
  EXPECT_NEAR(sim->v()[0], w_expected, 1e-8);
  const RunSummary r = runScene(s, tight(30));
  ASSERT_TRUE(r.ok) << r.failure;
  EXPECT_FALSE(r.passive);
  // The summary: the servo applied its limit, saturated from t = 0 to the
  // last sample before t_sat (samples are the steps, at most duration/20 apart).
  ASSERT_EQ(r.actuators.size(), 1u);
  EXPECT_EQ(r.actuators[0].max_force, tau_max);
  EXPECT_EQ(r.actuators[0].first_saturated, 0);
  EXPECT_LE(r.actuators[0].last_saturated, t_sat);
  EXPECT_GT(r.actuators[0].last_saturated, t_sat - 30.0 / 20);
  // ΔE = ∫ τ ω dt, integrated with the state by the method's own weights
  // (the saturation's kink in τ(t) is inside steps: not round-off).
  EXPECT_LT(r.relativeEnergyDeviation(), 1e-8);
}

// "Drive at 0.5 m/s for 3 s, then turn": examples/diff_drive/diff_drive_servo.urdf.
// Straight at t = 3: exactly the commanded 0.5 m/s (driving straight at a
// steady speed needs no force, so a P servo has no steady error), heading and
// lateral offset zero by symmetry. By t = 6 it is on a steady circle: speed
// and yaw rate constant, tied to the wheel rates by rolling —
// v = r (ω_l + ω_r)/2, Ω = r (ω_r − ω_l)/(2b) — and, rolling dissipating
// nothing, the servos' power τ_l ω_l + τ_r ω_r is zero. The circle is not
// exactly the commanded one (0.36 m): the centre of mass rides 5 cm behind
// the axle, so the turn needs a yaw moment from unequal wheel forces, which
// a P servo makes from a steady rate error — within 2 % here.
TEST(Actuators, DiffDriveDrivesStraightThenTheCommandedCircle) {
  const Scene s = loadScene(std::string(APPELL_SOURCE_DIR) + "/examples/diff_drive/diff_drive_servo.urdf");
  ASSERT_EQ(s.actuators.size(), 2u);
  const RunOptions o = runOptions(s.settings);
  auto sim = makeSimulator(s, o);
  const Model& m = s.model;
  const int chassis = m.bodyIndex("chassis");
  const int wl = m.joints[m.jointIndex("left_wheel_joint")].idx_v;
  const int wr = m.joints[m.jointIndex("right_wheel_joint")].idx_v;
  Data data(m);
  struct Motion { double speed, yaw, wl, wr; };
  auto motion = [&]() {  // axle midpoint speed (the chassis link origin), yaw rate, wheel rates
    forwardKinematics(m, data, sim->q(), sim->v());
    const Vec3 w = data.oMi[chassis].R * data.v[chassis].head<3>();
    return Motion{data.v[chassis].tail<3>().norm(), w.z(), sim->v()[wl], sim->v()[wr]};
  };
  ASSERT_TRUE(sim->advanceTo(3.0, o.dt).ok);
  const Motion m3 = motion();
  EXPECT_NEAR(m3.speed, 0.5, 1e-9);
  EXPECT_NEAR(m3.yaw, 0, 5e-12);  // round-off over 3 s (rad/s); any asymmetry of the model shows orders above
  EXPECT_NEAR(sim->q()[1], 0, 1e-12);
  ASSERT_TRUE(sim->advanceTo(6.0, o.dt).ok);
  const Motion m6 = motion();
  ASSERT_TRUE(sim->advanceTo(8.0, o.dt).ok);
  const Motion m8 = motion();
  const double r = 0.1, b = 0.18, kv = 2;
  EXPECT_NEAR(m8.speed, m6.speed, 1e-9);  // steady
  EXPECT_NEAR(m8.yaw, m6.yaw, 1e-9);
  EXPECT_NEAR(m8.speed, r * (m8.wl + m8.wr) / 2, 1e-12);  // rolling
  EXPECT_NEAR(m8.yaw, r * (m8.wr - m8.wl) / (2 * b), 1e-12);
  EXPECT_NEAR(kv * (2.5 - m8.wl) * m8.wl + kv * (7.5 - m8.wr) * m8.wr, 0, 1e-7);  // no power
  EXPECT_GT(m8.yaw, 1.0);  // it turns left …
  EXPECT_NEAR(m8.speed / m8.yaw, 0.36, 0.02 * 0.36);  // … on about the commanded circle
  const RunSummary run = runScene(s, o);
  ASSERT_TRUE(run.ok) << run.failure;
  EXPECT_EQ(run.flaggedContacts(), 0);  // within μ = 1 throughout
  // E − E₀ = the motors' work, integrated with the state by dopri5's weights
  // (the set-point schedule's corners are inside steps: not round-off).
  EXPECT_LT(run.relativeEnergyDeviation(), 1e-8);
  EXPECT_GT(run.joint_work, 0.5);
}

// The README's embedding: a Simulator built by hand applies the scene's
// forces with setJointForces(scene.jointForces()).
TEST(Actuators, TheReadmeEmbeddingAppliesTheScenesForces) {
  const Scene scene = loadScene(std::string(APPELL_SOURCE_DIR) + "/examples/diff_drive/diff_drive_servo.urdf");
  Simulator sim(scene.model, scene.constraints,
                makeSolver(Formulation::Tree, scene.model, scene.constraints),
                IntegratorType::DormandPrince54);
  sim.setJointForces(scene.jointForces());
  sim.setState(0.0, scene.q0, scene.v0);
  ASSERT_TRUE(sim.advanceTo(1.0, 0.01).ok);
  // Spun up (the servos saturate at 0.5 N·m for the first ~0.2 s), then at
  // the commanded 0.5 m/s: without the scene's forces it would stand still.
  EXPECT_GT(sim.q()[0], 0.4);
  EXPECT_NEAR(sim.v()[3], 0.5, 1e-6);
  // The README reads the left tyre's load as λ[2]: its normal row.
  EXPECT_EQ(scene.constraints[0]->name(), "left_tyre");
  EXPECT_EQ(scene.constraints[0]->rowKind(2), RowKind::Normal);
  EXPECT_GT(sim.lambda()[2], 15);
  EXPECT_LT(sim.lambda()[2], 25);
  EXPECT_FALSE(Scene().jointForces());        // nothing declared: no function
}

TEST(Actuators, MalformedActuatorsAreRefusedWithFileLineAndReason) {
  auto expect = [](const std::string& actuator, const std::string& what) {
    const std::string e = loadError(rotor(actuator));
    EXPECT_NE(e.find("servo.urdf:"), std::string::npos) << e;
    EXPECT_NE(e.find(what), std::string::npos) << e;
  };
  expect(R"(<actuator joint="nope" type="velocity" kv="1"/>)", "unknown joint 'nope'");
  expect(R"(<actuator joint="spin" type="torque" kv="1"/>)", "unknown actuator type 'torque'");
  expect(R"(<actuator joint="spin" type="velocity" kv="0"/>)", "needs kv > 0");
  expect(R"(<actuator joint="spin" type="velocity" kp="1" kv="1"/>)", "has no kp");
  expect(R"(<actuator joint="spin" type="position" kv="1"/>)", "needs kp > 0");
  expect(R"(<actuator joint="spin" type="position" kp="-1"/>)", "kp must be finite and ≥ 0");
  expect(R"(<actuator joint="spin" type="velocity" kv="1" effort_limit="0"/>)", "effort_limit");
  expect(R"(<actuator joint="spin" type="velocity" kv="1" gain="3"/>)", "gain");
  expect(R"(<actuator joint="spin" type="velocity" kv="1"><setpoint t="1" value="0"/><setpoint t="1" value="2"/></actuator>)",
         "times must increase");
  expect(R"(<actuator joint="spin" type="velocity" kv="1" setpoint="2"><setpoint t="1" value="0"/></actuator>)",
         "not both");
  expect(R"(<actuator joint="spin" type="velocity" kv="1"/><actuator joint="spin" type="position" kp="1"/>)",
         "actuator name 'spin' is used twice");
  // A floating joint has no single coordinate to servo.
  const std::string floating = R"(<robot name="f"><link name="b"><inertial><mass value="1"/>
<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
<appell><actuator joint="root_joint" type="velocity" kv="1"/></appell></robot>)";
  EXPECT_NE(loadError(floating).find("servos drive revolute, continuous and prismatic joints"),
            std::string::npos)
      << loadError(floating);
}
