// Joint position limits as unilateral constraints (joint_limit.hpp): a
// slider falling onto its lower limit and a pendulum swinging into, resting
// on and leaving its limit, against closed forms; the URDF's <limit> read
// into limits, switched off, and bad input named.
#include <gtest/gtest.h>

#include <appell/joint_limit.hpp>
#include <appell/simulator.hpp>
#include <appell/urdf.hpp>
#include "simulation_helpers.hpp"

#include <cmath>

using namespace appell;

namespace {

constexpr double kG = 9.81;


/// A body of mass m on a vertical prismatic joint, limit q ≥ 0.
Model slider(double m) {
  ModelBuilder b;
  b.addBody("block", -1, SE3::Identity(), JointType::Prismatic, Vec3::UnitZ(),
            Inertia{m, Vec3::Zero(), Vec3::Constant(0.01).asDiagonal()}, "slide");
  Model model = b.build();
  model.joints[0].limits.lower = 0.0;
  return model;
}

/// A point-like bob (m, length l) on a revolute joint about y, limits ±θ_L.
Model pendulum(double m, double l, double theta_limit) {
  ModelBuilder b;
  b.addBody("bob", -1, SE3::Identity(), JointType::Revolute, Vec3::UnitY(),
            Inertia{m, Vec3(0, 0, -l), Vec3::Constant(1e-6).asDiagonal()}, "hinge");
  Model model = b.build();
  model.joints[0].limits.lower = -theta_limit;
  model.joints[0].limits.upper = theta_limit;
  return model;
}


}  // namespace

// Protects: reaching a limit is an impact with the limit's restitution. The
// slider dropped from h reaches q = 0 at √(2h/g); e = 0 stops it there with
// the limit carrying its weight, e = 1 sends it back up at the same speed.
TEST(JointLimits, SliderFallsOntoItsLimitAndStopsOrBounces) {
  const double m = 2.0, h = 0.3, t_star = std::sqrt(2 * h / kG);
  const Model model = slider(m);
  for (double e : {0.0, 1.0}) {
    for (Formulation f : {Formulation::Tree, Formulation::Multipliers}) {
      const ConstraintList c{std::make_shared<JointLimit>(model, 0, LimitSide::Lower, e)};
      Simulator sim(model, c, makeSolver(f, model, c), IntegratorType::DormandPrince54, appell::test::tightIntegrator());
      VecX q(1), v(1);
      q << h;
      v << 0;
      ASSERT_TRUE(sim.setState(0, q, v));
      EXPECT_FALSE(sim.isClosed(0));
      const auto events = appell::test::advanceCollecting(sim, t_star + 0.05);
      ASSERT_EQ(events.size(), 1u) << "e = " << e;
      EXPECT_NEAR(events[0].t, t_star, 1e-10);
      EXPECT_NEAR(events[0].speed_before, -kG * t_star, 1e-9);
      if (e == 0) {
        EXPECT_EQ(events[0].kind, ContactEventKind::Touchdown);
        EXPECT_NEAR(sim.q()[0], 0.0, 1e-12);
        EXPECT_NEAR(sim.v()[0], 0.0, 1e-12);
        EXPECT_NEAR(sim.lambda()[0], m * kG, 1e-9) << "the limit carries the weight";
      } else {
        EXPECT_EQ(events[0].kind, ContactEventKind::Bounce);
        EXPECT_NEAR(events[0].speed_after, kG * t_star, 1e-9);
        const double dt = sim.time() - t_star;
        EXPECT_NEAR(sim.v()[0], kG * t_star - kG * dt, 1e-9);
      }
    }
  }
}

// Protects: the pendulum at a limit. Swinging up from θ = 0 at ω₀ into the
// limit θ_L, e = 1 reverses it at the speed energy gives, ω² = ω₀² −
// 2(g/l)(1 − cos θ_L) (I ≈ m l²); e = 0 stops it there. Driven into the
// limit by a torque τ₀ it rests with the limit holding τ₀ − m g l sin θ_L,
// and when the torque ramps down, τ = τ₀ − k(t − t₀), it leaves at
// t* = t₀ + (τ₀ − m g l sin θ_L)/k (the multiplier reaching zero: a lift-off).
TEST(JointLimits, PendulumBouncesStopsRestsAndLeavesItsLimit) {
  const double m = 1.0, l = 0.5, limit = 0.4, I = m * l * l + 1e-6;
  const Model model = pendulum(m, l, limit);
  for (Formulation f : {Formulation::Tree, Formulation::Multipliers}) {
    for (double e : {1.0, 0.0}) {
      const ConstraintList c{std::make_shared<JointLimit>(model, 0, LimitSide::Lower, e),
                             std::make_shared<JointLimit>(model, 0, LimitSide::Upper, e)};
      Simulator sim(model, c, makeSolver(f, model, c), IntegratorType::DormandPrince54, appell::test::tightIntegrator());
      const double w0 = e == 1 ? 2.0 : 0.0, tau0 = e == 1 ? 0.0 : 3.0;
      sim.setJointForces([&](double, const VecX&, const VecX&, VecX& tau) { tau[0] = tau0; });
      VecX q(1), v(1);
      q << 0;
      v << w0;
      ASSERT_TRUE(sim.setState(0, q, v));
      // Which way gravity turns the bob (θ > 0 about y moves the bob along −x,
      // up on either side): V(θ) = m g l (1 − cos θ).
      const double E0 = sim.energy();
      std::vector<ContactEvent> events;
      while (sim.time() < 2.0 && events.empty()) {
        ASSERT_TRUE(sim.step(1e-2).ok);
        events.insert(events.end(), sim.events().begin(), sim.events().end());
      }
      ASSERT_EQ(events.size(), 1u) << toString(f) << " e = " << e;
      EXPECT_EQ(events[0].constraint, 1) << "the upper limit";
      const double w = std::sqrt(w0 * w0 + (2 * tau0 * limit - 2 * m * kG * l * (1 - std::cos(limit))) / I);
      EXPECT_NEAR(std::abs(events[0].speed_before), w, 1e-8);
      if (e == 1) {
        EXPECT_EQ(events[0].kind, ContactEventKind::Bounce);
        EXPECT_NEAR(events[0].speed_after, w, 1e-8);
        EXPECT_NEAR(sim.energy(), E0, 1e-9);
        EXPECT_LT(sim.v()[0], 0) << "reversed";
      } else {
        EXPECT_EQ(events[0].kind, ContactEventKind::Touchdown);
        EXPECT_NEAR(sim.q()[0], limit, 1e-12);
        EXPECT_NEAR(sim.v()[0], 0, 1e-12);
        EXPECT_NEAR(sim.lambda()[1], tau0 - m * kG * l * std::sin(limit), 1e-9);
        const double k = 2.0, t0 = sim.time(), t_star = t0 + (tau0 - m * kG * l * std::sin(limit)) / k;
        sim.setJointForces([&, t0](double t, const VecX&, const VecX&, VecX& tau) { tau[0] = tau0 - k * (t - t0); });
        const auto later = appell::test::advanceCollecting(sim, t_star + 0.1);
        ASSERT_EQ(later.size(), 1u);
        EXPECT_EQ(later[0].kind, ContactEventKind::LiftOff);
        EXPECT_NEAR(later[0].t, t_star, 1e-9);
        EXPECT_LT(sim.q()[0], limit);
      }
    }
  }
}

// Protects: the URDF's limits reach the scene (one constraint per finite
// side of a revolute or prismatic joint), can be switched off, and bad
// settings are named.
TEST(JointLimits, UrdfLimitsBecomeUnilateralConstraints) {
  const std::string urdf = R"(<?xml version="1.0"?>
<robot name="arm">
  <link name="world"/>
  <link name="upper"><inertial><mass value="1"/><origin xyz="0 0 -0.25"/>
    <inertia ixx="0.02" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.001"/></inertial></link>
  <joint name="shoulder" type="revolute"><parent link="world"/><child link="upper"/>
    <axis xyz="0 1 0"/><limit lower="-0.5" upper="0.7" effort="10" velocity="2"/></joint>
  <appell>@LIMITS@</appell>
</robot>)";
  auto load = [&](const std::string& limits, const LoadOptions& o = {}) {
    std::string text = urdf;
    text.replace(text.find("@LIMITS@"), 8, limits);
    return loadSceneFromString(text, ".", "arm.urdf", o);
  };
  const Scene s = load("<joint_limits restitution=\"0.5\"/>");
  ASSERT_EQ(s.joint_limits.size(), 2u);
  EXPECT_EQ(s.constraints.size(), 2u);
  EXPECT_EQ(s.joint_limits[0]->name(), "shoulder_lower_limit");
  EXPECT_EQ(s.joint_limits[1]->bound(), 0.7);
  EXPECT_EQ(s.joint_limits[0]->restitution(), 0.5);
  EXPECT_TRUE(s.constraints[1]->unilateral());
  EXPECT_TRUE(load("<joint_limits enabled=\"false\"/>").joint_limits.empty());
  LoadOptions off;
  off.joint_limits = false;
  EXPECT_TRUE(load("", off).joint_limits.empty());
  try {
    load("<joint_limits restitution=\"2\"/>");
    ADD_FAILURE() << "restitution 2 accepted";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("restitution must lie in [0, 1]"), std::string::npos) << e.what();
  }
  // The initial state outside the range is penetration of the limit: named.
  try {
    load("<initial><joint name=\"shoulder\" position=\"0.9\"/></initial>");
    ADD_FAILURE() << "a joint beyond its limit accepted";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("'shoulder_upper_limit' penetrates"), std::string::npos) << e.what();
  }
}
