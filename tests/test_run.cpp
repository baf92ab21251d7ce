// runScene (run.hpp), the loop behind `appell run`: the rolling disk conserves
// energy and stays on its constraints, its contact loads do not depend on the
// formulation, the command line prints the same summary, the observer sees
// the sampled states, and a run that fails says when and why.
#include <appell/custom_constraint.hpp>
#include <appell/run.hpp>
#include <appell/urdf.hpp>

#include "run_command.hpp"
#include "scene_helpers.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <limits>
#include <regex>
#include <sstream>

using namespace appell;

namespace {

const std::string kDisk = std::string(APPELL_SOURCE_DIR) + "/examples/rolling_disk/rolling_disk.urdf";

std::string appellRun(const std::string& args) { return test::runAppell("run " + args).output; }

double field(const std::string& text, const std::string& pattern, int group = 1) {
  std::smatch m;
  if (!std::regex_search(text, m, std::regex(pattern))) return std::nan("");
  return std::stod(m[group]);
}

// |a − b| within `digits` significant digits of printed output.
void expectPrinted(double printed, double exact, int digits, const std::string& what) {
  EXPECT_NEAR(printed, exact, std::abs(exact) * std::pow(10.0, 1 - digits)) << what;
}

}  // namespace

TEST(Run, RollingDiskConservesEnergyAndStaysOnItsConstraints) {
  const Scene scene = loadScene(kDisk);
  RunOptions o = runOptions(scene.settings);
  o.duration = 1.0;
  double normal_min = 0, normal_max = 0;
  for (Formulation f : {Formulation::Tree, Formulation::Multipliers, Formulation::Appell}) {
    o.formulation = f;
    const RunSummary r = runScene(scene, o);
    ASSERT_TRUE(r.ok) << r.failure;
    EXPECT_NEAR(r.time, 1.0, 1e-12);
    EXPECT_TRUE(r.passive);
    // Rolling without slipping is ideal and time-independent: no work is done.
    EXPECT_LT(r.relativeEnergyDeviation(), 1e-8) << toString(f);
    EXPECT_LT(r.max_velocity_residual, 1e-10) << toString(f);
    EXPECT_LT(r.max_gap_residual, 1e-10) << toString(f);
    EXPECT_EQ(r.samples, r.counters.steps + 1);
    // One contact, found by its rows' kinds: normal row 2, tangent rows 0 and 1.
    ASSERT_EQ(r.contacts.size(), 1u);
    const ContactStats& c = r.contacts[0];
    EXPECT_EQ(c.name, "rim");
    EXPECT_EQ(c.normal_row, 2);
    EXPECT_EQ(c.tangential_rows, (std::vector<int>{0, 1}));
    EXPECT_EQ(c.mu, scene.contacts[0]->mu());
    // The disk presses on the floor with about its weight m g (1 kg), and the
    // formulations agree on λ (unique for independent rows).
    EXPECT_GT(c.min_normal, 0.9 * 9.81);
    EXPECT_LT(c.max_normal, 1.1 * 9.81);
    if (f == Formulation::Tree) {
      normal_min = c.min_normal;
      normal_max = c.max_normal;
    } else {
      EXPECT_NEAR(c.min_normal, normal_min, 1e-6) << toString(f);
      EXPECT_NEAR(c.max_normal, normal_max, 1e-6) << toString(f);
    }
    EXPECT_FALSE(c.flagged());
  }
}

TEST(Run, TheCommandLinePrintsTheSameSummary) {
  const Scene scene = loadScene(kDisk);
  RunOptions o = runOptions(scene.settings);
  o.duration = 1.0;
  const RunSummary r = runScene(scene, o);
  const std::string out = appellRun(kDisk + " --duration 1 --quiet");
  expectPrinted(field(out, R"(simulated\s+([-+0-9.e]+) s)"), r.time, 6, out);
  EXPECT_EQ(field(out, R"(in ([0-9]+) steps)"), r.counters.steps) << out;
  EXPECT_EQ(field(out, R"(([0-9]+) dynamics solves)"), r.counters.evaluations) << out;
  expectPrinted(field(out, R"(E0 = ([-+0-9.e]+) J)"), r.energy0, 6, out);
  expectPrinted(field(out, R"(max \|E − E0\| = ([-+0-9.e]+) J)"), r.max_energy_deviation, 6, out);
  expectPrinted(field(out, R"(\(([-+0-9.e]+) relative\))"), r.relativeEnergyDeviation(), 6, out);
  expectPrinted(field(out, R"(max \|Av\+b\| = ([-+0-9.e]+))"), r.max_velocity_residual, 6, out);
  expectPrinted(field(out, R"(max \|gap\| = ([-+0-9.e]+))"), r.max_gap_residual, 6, out);
  expectPrinted(field(out, R"(rim\s+normal load ([-+0-9.e]+))"), r.contacts[0].min_normal, 4, out);
  expectPrinted(field(out, R"(normal load [-+0-9.e]+ … ([-+0-9.e]+) N)"), r.contacts[0].max_normal, 4, out);
  expectPrinted(field(out, R"(friction demand max ([-+0-9.e]+))"), r.contacts[0].max_demand, 4, out);
  EXPECT_NE(out.find("events       none"), std::string::npos) << out;
}

TEST(Run, TheObserverSeesEveryNthStepAndTheEnd) {
  const Scene scene = loadScene(kDisk);
  RunOptions o = runOptions(scene.settings);
  o.integrator = IntegratorType::RK4;
  o.dt = 0.01;
  o.duration = 0.255;  // 26 steps, the last one shortened
  o.output_every = 5;
  std::vector<double> times;
  long steps = 0;
  const RunSummary r = runScene(
      scene, o, [&](const Simulator& sim) { times.push_back(sim.time()); },
      [&](const Simulator&) { ++steps; });
  ASSERT_TRUE(r.ok) << r.failure;
  EXPECT_EQ(r.counters.steps, 26);
  EXPECT_EQ(steps, 26);
  // t = 0, steps 5, 10, …, 25, and the last (26th) step.
  ASSERT_EQ(times.size(), 7u);
  EXPECT_EQ(times.front(), 0.0);
  EXPECT_NEAR(times[1], 0.05, 1e-12);
  EXPECT_NEAR(times[5], 0.25, 1e-12);
  EXPECT_NEAR(times.back(), 0.255, 1e-12);
  // The same samples through a TrajectoryWriter: the header and one line each.
  std::ostringstream csv;
  TrajectoryWriter writer(csv, scene);
  runScene(scene, o, writer);
  EXPECT_EQ(writer.samples(), 7);
  EXPECT_NE(csv.str().find("lambda:rim.normal"), std::string::npos);
}

TEST(Run, AFailingRunReportsItsTimeAndReason) {
  // A slider with two copies of one velocity row, A = [1; 1], whose
  // acceleration terms disagree once t > 0.2575: from then on no motion
  // satisfies both (0 = 1), and the step from t = 0.25 (stages up to 0.26)
  // fails. The run keeps the last good state, t = 0.25.
  ModelBuilder b;
  b.addBody("slider", -1, SE3::Identity(), JointType::Prismatic, Vec3::UnitX(),
            Inertia{1.0, Vec3::Zero(), 0.1 * Mat3::Identity()});
  Scene scene;
  scene.model = b.build();
  CustomRows rows;
  rows.name = "twin_rows";
  rows.rows = 2;
  rows.A_b = [](const Model&, const VecX&, double, Eigen::Ref<MatX> A, Eigen::Ref<VecX> bb) {
    A.setOnes();
    bb.setZero();
  };
  rows.bias = [](const Model&, const VecX&, const VecX&, double t, Eigen::Ref<VecX> ab) {
    ab[0] = 0;
    ab[1] = t > 0.2575 ? 1.0 : 0.0;
  };
  scene.constraints.push_back(std::make_shared<CustomConstraint>(rows));
  scene.q0 = VecX::Zero(1);
  scene.v0 = VecX::Zero(1);
  scene.source = "<twin rows>";
  RunOptions o;
  o.integrator = IntegratorType::RK4;
  o.dt = 0.01;
  o.duration = 1.0;
  for (Formulation f : {Formulation::Tree, Formulation::Multipliers, Formulation::Appell}) {
    o.formulation = f;
    double last_sample = -1;
    const RunSummary r = runScene(scene, o, [&](const Simulator& sim) { last_sample = sim.time(); });
    EXPECT_FALSE(r.ok) << toString(f);
    EXPECT_NEAR(r.time, 0.25, 1e-12) << toString(f);
    EXPECT_EQ(r.counters.steps, 25) << toString(f);
    EXPECT_EQ(r.counters.failed, 1) << toString(f);
    EXPECT_NE(r.failure.find("twin_rows"), std::string::npos) << toString(f) << ": " << r.failure;
    // The last good state is the last sample (a trajectory ends there).
    EXPECT_EQ(last_sample, r.time) << toString(f);
  }
}

TEST(Run, BadOptionsAreRejected) {
  SimulationSettings s;
  s.integrator = "adams_bashforth";
  EXPECT_THROW(runOptions(s), std::invalid_argument);
  s = SimulationSettings{};
  s.formulation = "quantum";
  EXPECT_THROW(runOptions(s), std::invalid_argument);
  const Scene scene = loadScene(kDisk);
  RunOptions o = runOptions(scene.settings);
  o.output_every = 0;
  EXPECT_THROW(runScene(scene, o), std::invalid_argument);
  o.output_every = 1;
  o.dt = -1;
  EXPECT_THROW(runScene(scene, o), std::invalid_argument);
}

// A disk with no spin falls flat. Under dopri5 the step lands on the flat
// pose (singular geometry, named as such); under RK4 the projection's Newton
// stalls just before it — and the failure names the same root cause, the
// contact at the edge of its singular geometry, not only "did not converge".
TEST(Run, ADiskFallingFlatNamesTheSingularGeometry) {
  std::ifstream in(std::string(APPELL_SOURCE_DIR) + "/examples/rolling_disk/rolling_disk.urdf");
  std::string xml((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string spin = "velocity=\"0.5 0 -5   1.5 0 0.15\"";
  ASSERT_NE(xml.find(spin), std::string::npos);
  xml.replace(xml.find(spin), spin.size(), "velocity=\"0.5 0 0   0 0 0\"");
  LoadOptions lo;
  lo.project_initial_state = true;
  const Scene scene = loadSceneFromString(xml, ".", "flat_disk.urdf", lo);
  for (IntegratorType it : {IntegratorType::RK4, IntegratorType::DormandPrince54}) {
    RunOptions o = runOptions(scene.settings);
    o.integrator = it;
    o.dt = 0.01;
    o.duration = 3;
    o.contacts = ContactScheme::Events;  // the events' diagnosis (docs/contacts.md §10)
    const RunSummary s = runScene(scene, o, {});
    ASSERT_FALSE(s.ok) << toString(it);
    const bool named = s.failure.find("contact 'rim' is at the edge of its singular geometry") != std::string::npos ||
                       s.failure.find("rim: wheel lying flat") != std::string::npos;
    EXPECT_TRUE(named) << toString(it) << ": " << s.failure;
    EXPECT_GT(s.time, 0.9);  // it falls for about a second first
  }
}

// Drift the projection would remove grows without it: RK4 at 1e-2 on the
// rolling disk with projection off leaves the constraints by ~1e-6 in 2 s.
// The residual watch stops the run there, keeping the last state within the
// bound; switched off, the same run ends with residuals past it.
TEST(Run, ResidualWatchStopsDriftBeyondItsBound) {
  const Scene scene = loadScene(std::string(APPELL_SOURCE_DIR) + "/examples/rolling_disk/rolling_disk.urdf");
  RunOptions o = runOptions(scene.settings);
  o.integrator = IntegratorType::RK4;
  o.dt = 1e-2;
  o.duration = 20;
  o.project_positions = o.project_velocities = false;
  const RunSummary s = runScene(scene, o, {});
  ASSERT_FALSE(s.ok);
  EXPECT_NE(s.failure.find("the constraint residual reached"), std::string::npos) << s.failure;
  EXPECT_LT(s.time, o.duration);
  EXPECT_LE(std::max(s.max_velocity_residual, s.max_gap_residual), o.max_residual);
  o.max_residual = std::numeric_limits<double>::infinity();
  const RunSummary off = runScene(scene, o, {});
  EXPECT_TRUE(off.ok) << off.failure;
  EXPECT_GT(std::max(off.max_velocity_residual, off.max_gap_residual), 1e-6);
}

// A billion N·m on one wheel of the car: no step can follow what that does,
// and the run must say so — the failure names the joint force and its ratio
// to the weight, not only the symptom (a step below h_min, or contact modes
// that cycle on round-off). The same car with 1 N·m drives on unflagged.
TEST(Run, AHugeJointForceIsNamedAsTheCauseOfTheFailure) {
  std::ifstream in(std::string(APPELL_SOURCE_DIR) + "/examples/car/car.urdf");
  const std::string car((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto withEffort = [&](const std::string& value) {
    // Ideal tyres: with μ = 0.9 the car flips over its spinning wheel and flies
    // (a run that ends, 10⁶ steps for 0.01 s); rolling without slipping it
    // cannot follow the force.
    std::string xml = std::regex_replace(car, std::regex(R"( mu="0.9")"), "");
    const std::string anchor = "<simulation";
    xml.insert(xml.find(anchor), "<effort joint=\"front_left_joint\" value=\"" + value + "\"/>\n    ");
    return loadSceneFromString(xml, std::string(APPELL_SOURCE_DIR) + "/examples/car", "car.urdf");
  };
  RunOptions o = runOptions(withEffort("1e9").settings);
  o.duration = 0.01;
  // The event scheme's diagnosis (auto would take the failing step with
  // time-stepping windows and stop later on the energy watch).
  o.contacts = ContactScheme::Events;
  const RunSummary huge = runScene(withEffort("1e9"), o);
  ASSERT_FALSE(huge.ok);
  EXPECT_NE(huge.failure.find("the likely cause: the joint force on 'front_left_joint' is 1e+09"),
            std::string::npos)
      << huge.failure;
  const RunSummary fine = runScene(withEffort("1"), o);
  EXPECT_TRUE(fine.ok) << fine.failure;
}

// Protects: a fixed-step run that fails because its step left RK4's
// stability region names that as the cause, with a step that would hold.
// The sleigh sliding down its incline speeds up, and its yaw mode's decay
// rate grows with the speed (λ ≈ −1.67 V /s here): with dt = 0.02 s, λ·dt
// passes RK4's real-axis limit 2.785 near t = 31 s and the energy watch stops
// the run. The message gives the mode and a dt that keeps it stable — which
// then runs well past that time — while a mode that grows physically
// (Re λ > 0) is never blamed on the step.
TEST(Run, AStepBeyondRk4sStabilityRegionIsNamedAsTheCause) {
  const Scene scene = loadScene(std::string(APPELL_SOURCE_DIR) + "/examples/sleigh/sleigh.urdf");
  RunOptions o = runOptions(scene.settings);
  o.integrator = IntegratorType::RK4;
  o.dt = 0.02;
  o.duration = 60;
  // The datum-free watch measures the error against the energy that moved,
  // which the sleigh's descent makes large: its default 5 % lets the run go
  // on past the onset until the residual watch stops it. A user who wants
  // the onset asks for a tighter balance.
  o.max_energy_error = 1e-3;
  const RunSummary bad = runScene(scene, o, {});
  ASSERT_FALSE(bad.ok);
  EXPECT_GT(bad.time, 25.0);
  EXPECT_LT(bad.time, 40.0);
  EXPECT_NE(bad.failure.find("outside RK4's stability region"), std::string::npos) << bad.failure;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(bad.failure, m, std::regex("dt ≤ ([0-9.e+-]+) s"))) << bad.failure;
  const double suggested = std::stod(m[1]);
  EXPECT_LT(suggested, o.dt);
  EXPECT_GT(suggested, 0.5 * o.dt);
  o.dt = suggested;
  o.duration = bad.time + 5;
  const RunSummary good = runScene(scene, o, {});
  EXPECT_TRUE(good.ok) << good.failure;
  EXPECT_LT(good.max_energy_deviation, 1e-6 * std::abs(good.energy_scale));
}

namespace {

// A free body (principal moments 1, 2, 3 kg m²) spinning at 10 rad/s about
// its intermediate axis, its centre `height` metres up.
std::string spinningBody(double height) {
  std::ostringstream xml;
  xml << R"(<robot name="top"><link name="body"><inertial><mass value="1"/>)"
      << R"(<inertia ixx="1" ixy="0" ixz="0" iyy="2" iyz="0" izz="3"/></inertial></link>)"
      << R"(<appell><initial><joint name="root_joint" xyz="0 0 )" << height
      << R"(" velocity="0.1 10 0.1 0 0 0"/></initial></appell></robot>)";
  return xml.str();
}

}  // namespace

// Issue 41, reproducer 13: the divergence watch judged the work balance
// against |E₀|, so the same spinning body diverging under RK4 at dt = 0.2 was
// stopped at z = 0 but ran to the end 1000 m up (|E − E₀| = 445 J reported as
// "0.045 relative": 4.5× its rotational energy). Judged against the energy
// that moved (DivergenceWatch), the verdict no longer depends on where the
// potential's zero is: both runs stop at the same step, with the same error.
TEST(Run, TheDivergenceWatchDoesNotDependOnThePotentialsDatum) {
  RunOptions o;
  o.integrator = IntegratorType::RK4;
  o.dt = 0.2;
  o.duration = 20;
  const RunSummary low = runScene(loadSceneFromString(spinningBody(0), ".", "low.urdf"), o);
  const RunSummary high = runScene(loadSceneFromString(spinningBody(1000), ".", "high.urdf"), o);
  ASSERT_FALSE(low.ok);
  ASSERT_FALSE(high.ok) << "ran to t = " << high.time << " with |E − E0| ≤ " << high.max_energy_deviation;
  EXPECT_NE(high.failure.find("the integration is diverging"), std::string::npos) << high.failure;
  EXPECT_NE(high.failure.find("of the energy that moved"), std::string::npos) << high.failure;
  EXPECT_EQ(low.time, high.time);
  EXPECT_NEAR(high.max_energy_deviation, low.max_energy_deviation, 1e-9 * 9810);
  EXPECT_NEAR(high.energy_scale, low.energy_scale, 1e-9 * 9810);
  // The summary covers the states within the bound only.
  EXPECT_LE(high.relativeEnergyDeviation(), o.max_energy_error);
  // The same body integrated accurately is not stopped, 1000 m up either.
  const RunSummary good = runScene(loadSceneFromString(spinningBody(1000), ".", "high.urdf"), test::tightRun(20));
  EXPECT_TRUE(good.ok) << good.failure;
  EXPECT_LT(good.relativeEnergyDeviation(), 1e-6);
}

// Issue 41, reproducer 12: each step sampled the actuators twice ("saturated
// in 43 samples" over 22). A velocity servo saturated for the whole run
// (it needs (100 − 0.02) I / τ_max ≈ 25 s to leave saturation) is saturated
// in exactly every sample: the start and each of the 20 steps.
TEST(Run, ActuatorSaturationIsCountedOncePerSample) {
  const Scene s = loadSceneFromString(R"(<robot name="rotor"><link name="world"/>
<link name="disk"><inertial><mass value="2"/><inertia ixx="0.03" ixy="0" ixz="0" iyy="0.03" iyz="0" izz="0.05"/></inertial></link>
<joint name="spin" type="continuous"><parent link="world"/><child link="disk"/><axis xyz="0 0 1"/>
<limit effort="0.2" velocity="200"/></joint>
<appell><actuator joint="spin" type="velocity" kv="10" setpoint="100"/></appell></robot>)",
                                      ".", "rotor.urdf");
  RunOptions o;
  o.integrator = IntegratorType::RK4;
  o.dt = 0.1;
  o.duration = 2;
  const RunSummary r = runScene(s, o);
  ASSERT_TRUE(r.ok) << r.failure;
  EXPECT_EQ(r.samples, 21);
  ASSERT_EQ(r.actuators.size(), 1u);
  EXPECT_EQ(r.actuators[0].saturated, 21);
  EXPECT_EQ(r.actuators[0].first_saturated, 0.0);
  EXPECT_NEAR(r.actuators[0].last_saturated, 2.0, 1e-12);
}
