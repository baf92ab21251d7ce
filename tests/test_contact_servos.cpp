// Servos inside Moreau–Jean steps (timestepping/implicit_servos.hpp): taken
// at the step's end, a stiff servo on a light body is the backward-Euler
// spring of its closed-form recurrence, one at its effort limit pushes with
// exactly h τ_max per step, a soft one stays an explicit force, and a stiff
// servo pressing a body onto the floor is balanced by the contact force its
// law demands — the same force as between events — within its effort limit
// or at it.
#include <gtest/gtest.h>

#include <appell/run.hpp>
#include <appell/simulator.hpp>
#include <appell/urdf.hpp>

#include <cmath>
#include <string>

using namespace appell;

namespace {

constexpr double kH = 1e-3;

// A 10 g carriage on a horizontal prismatic joint (gravity across it), its
// limits ±10 m away (unilateral rows the time-stepping stage is built for).
std::string slider(const std::string& actuator, double effort = 1000) {
  return R"(<robot name="slider"><link name="world"/>
<link name="carriage"><inertial><mass value="0.01"/><inertia ixx="1e-5" ixy="0" ixz="0" iyy="1e-5" iyz="0" izz="1e-5"/></inertial></link>
<joint name="x" type="prismatic"><parent link="world"/><child link="carriage"/><axis xyz="1 0 0"/>
<limit lower="-10" upper="10" effort=")" +
         std::to_string(effort) + R"(" velocity="100"/></joint>
<appell>)" + actuator + R"(</appell></robot>)";
}

// A 1 kg ball (radius 5 cm) on a vertical prismatic joint, resting on the
// floor, a frictionless contact; its servo holds the set-point `below` the
// resting height, so it presses the ball down.
std::string pressedBall(double kp, double below, double effort) {
  return R"(<robot name="press"><link name="world"/>
<link name="ball"><inertial><mass value="1"/><inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="1e-3"/></inertial>
<collision><geometry><sphere radius="0.05"/></geometry></collision></link>
<joint name="z" type="prismatic"><parent link="world"/><child link="ball"/><axis xyz="0 0 1"/>
<limit lower="-1" upper="1" effort=")" +
         std::to_string(effort) + R"(" velocity="100"/></joint>
<appell>
  <support name="floor" type="plane" normal="0 0 1" offset="0"/>
  <contact name="foot" link="ball" kind="sliding" support="floor"/>
  <initial><joint name="z" position="0.05"/></initial>
  <actuator name="press" joint="z" type="position" kp=")" +
         std::to_string(kp) + R"(" kv="20" setpoint=")" + std::to_string(0.05 - below) + R"("/>
</appell></robot>)";
}

RunOptions scheme(ContactScheme c) {
  RunOptions o;
  o.contacts = c;
  o.integrator = IntegratorType::RK4;
  o.dt = kH;
  return o;
}

double normalForce(const Scene& s, const Simulator& sim, const std::string& name) {
  for (int c = 0; c < static_cast<int>(s.constraints.size()); ++c)
    if (s.constraints[c]->name() == name)
      return sim.lambda()[sim.constraintData().offset[c] + s.constraints[c]->unilateralRow()];
  ADD_FAILURE() << "no constraint " << name;
  return std::nan("");
}

}  // namespace

// k_p = 10⁵ N/m on 10 g: ω h = √(k_p/m) h = 3.2 at h = 1 ms, beyond what an
// explicit step takes (RK4 keeps |ω h| < 2.8 on the imaginary axis). Taken
// at the step's end (θ = 1) the servo is m (v⁺ − v) = h (k_p (q* − q⁺) − k_v v⁺),
// q⁺ = q + h v⁺: v⁺ = (m v + h k_p (q* − q)) / (m + h (h k_p + k_v)), the
// recurrence the time-stepped carriage must follow to round-off, and which
// settles on the set-point.
TEST(ContactServos, StiffServoOnALightBodyIsTheBackwardEulerSpring) {
  const double m = 0.01, kp = 1e5, kv = 0.5, target = 0.1;
  const Scene s = loadSceneFromString(
      slider(R"(<actuator name="hold" joint="x" type="position" kp="100000" kv="0.5" setpoint="0.1"/>)"),
      ".", "slider.urdf");
  auto sim = makeSimulator(s, scheme(ContactScheme::TimeStepping));
  double q = 0, v = 0;
  for (int k = 0; k < 300; ++k) {
    const StepStatus st = sim->step(kH);
    ASSERT_TRUE(st.ok) << st.message;
    v = (m * v + kH * kp * (target - q)) / (m + kH * (kH * kp + kv));
    q += kH * v;
    ASSERT_NEAR(sim->v()[0], v, 1e-12 * std::max(1.0, std::abs(v))) << "step " << k;
    ASSERT_NEAR(sim->q()[0], q, 1e-13) << "step " << k;
  }
  EXPECT_EQ(sim->counters().timestepping_steps, 300);
  EXPECT_NEAR(sim->q()[0], target, 1e-9) << "settled on its set-point";
}

// A soft servo (k_p = 10 N/m on 10 g: (ω h)² = 10⁻³) is left explicit by
// the gate, as between events: its force at the step's start,
// v⁺ = v + h (k_p (q* − q) − k_v v)/m, q⁺ = q + h v⁺ — no response solves.
TEST(ContactServos, SoftServoStaysAnExplicitForce) {
  const double m = 0.01, kp = 10, kv = 0.01, target = 0.1;
  const Scene s = loadSceneFromString(
      slider(R"(<actuator name="hold" joint="x" type="position" kp="10" kv="0.01" setpoint="0.1"/>)"),
      ".", "slider.urdf");
  auto sim = makeSimulator(s, scheme(ContactScheme::TimeStepping));
  double q = 0, v = 0;
  for (int k = 0; k < 300; ++k) {
    ASSERT_TRUE(sim->step(kH).ok);
    v += kH * (kp * (target - q) - kv * v) / m;
    q += kH * v;
    ASSERT_NEAR(sim->v()[0], v, 1e-12 * std::max(1.0, std::abs(v))) << "step " << k;
    ASSERT_NEAR(sim->q()[0], q, 1e-13) << "step " << k;
  }
}

// The same servo limited to 0.5 N and asked for a set-point 1 m away pushes
// with P = h τ_max at every step: v_N = N h τ_max / m, q_N = h² τ_max/m ·
// N(N+1)/2, and the work it did, Σ P (v + v⁺)/2, is exactly ½ m v_N².
TEST(ContactServos, ServoAtItsEffortLimitPushesWithExactlyItsLimit) {
  const double m = 0.01, tau_max = 0.5;
  const Scene s = loadSceneFromString(
      slider(R"(<actuator name="hold" joint="x" type="position" kp="100000" kv="0.5" setpoint="1"/>)",
             tau_max),
      ".", "slider.urdf");
  auto sim = makeSimulator(s, scheme(ContactScheme::TimeStepping));
  const int N = 100;
  for (int k = 0; k < N; ++k) ASSERT_TRUE(sim->step(kH).ok);
  const double vN = N * kH * tau_max / m, qN = kH * kH * tau_max / m * N * (N + 1) / 2;
  EXPECT_NEAR(sim->v()[0], vN, 1e-12 * vN);
  EXPECT_NEAR(sim->q()[0], qN, 1e-12 * qN);
  EXPECT_NEAR(sim->jointWork(), 0.5 * m * vN * vN, 1e-12 * m * vN * vN);
}

// A stiff servo pressing a resting ball onto the floor: at rest its force is
// k_p (q* − q) = −k_p δ, so the floor carries m g + k_p δ — under the events
// (an exact solve) and under time-stepping, where the servo and the contact
// are one problem (the contact sees the servo's Schur complement). At an
// effort limit below k_p δ the floor carries m g + τ_max.
TEST(ContactServos, ServoPressingOnTheFloorIsBalancedByTheContact) {
  // k_p = 10⁶ N/m on 1 kg, (ω h)² = 1: stiff, so implicit in time-stepping.
  const double g = 9.81, kp = 1e6, delta = 1e-4;
  for (double effort : {1000.0, 30.0}) {
    SCOPED_TRACE("effort limit " + std::to_string(effort));
    const Scene s = loadSceneFromString(pressedBall(kp, delta, effort), ".", "press.urdf");
    const double expected = g + std::min(kp * delta, effort);
    for (ContactScheme c : {ContactScheme::Events, ContactScheme::TimeStepping}) {
      SCOPED_TRACE(toString(c));
      auto sim = makeSimulator(s, scheme(c));
      ASSERT_TRUE(sim->advanceTo(0.2, kH).ok);
      EXPECT_TRUE(sim->isClosed(0));
      EXPECT_NEAR(sim->q()[0], 0.05, 1e-9) << "on the floor";
      EXPECT_NEAR(normalForce(s, *sim, "foot"), expected, 1e-9 * expected);
    }
  }
}
