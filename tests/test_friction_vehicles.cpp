// Coulomb friction on vehicles and runners (docs/contacts.md §8): a
// skid-steer robot that turns only because its tyres slip, a sleigh on ice
// that slides sideways when its blade's lateral demand reaches μ, and a car
// with locked wheels — parked on a 10° slope without creeping, sliding down
// a slope steeper than its friction angle at g (sin θ − μₖ cos θ).
#include <appell/run.hpp>
#include <appell/simulator.hpp>
#include <appell/urdf.hpp>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "simulation_helpers.hpp"
#include "sleigh.hpp"

#include <cmath>
#include <limits>
#include <fstream>
#include <numbers>
#include <regex>
#include <sstream>
#include <string>

using namespace appell;
using namespace appell::scenes;

namespace {

std::string example(const std::string& rel) { return std::string(APPELL_SOURCE_DIR) + "/examples/" + rel; }

std::string readText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

double yaw(const VecX& q) {
  const Mat3 R = Eigen::Quaterniond(q[6], q[3], q[4], q[5]).normalized().toRotationMatrix();
  return std::atan2(R(1, 0), R(0, 0));
}

/// |E + impact losses + friction work − work in − E₀|.
double balanceError(const Simulator& sim, double E0) {
  return std::abs(sim.energy() + sim.impactEnergyLoss() + sim.frictionWork() - sim.jointWork() -
                  sim.supportWork() - E0);
}

}  // namespace

// Protects: friction lets a vehicle do what no-slip rows forbid. Four fixed
// wheels (examples/skid_steer) allow no yaw while they roll without
// slipping: with ideal tyres the robot drives dead straight whatever its
// wheel servos do. With μ = 0.8 it drives straight while the servos agree
// (the tyres stick), and turns left once the right wheels are driven faster:
// the tyres slip (slip events), all four slide on the circle, and the work
// balance E + friction work − motor work = E₀ closes to the integration
// tolerance — friction takes most of what the motors put in.
TEST(FrictionVehicles, SkidSteerTurnsOnlyBecauseItsTyresSlip) {
  const std::string text = readText(example("skid_steer/skid_steer.urdf"));
  const Scene scene = loadSceneFromString(text, example("skid_steer"), "skid_steer");
  RunOptions o = runOptions(scene.settings);
  o.tol = 1e-10;
  auto sim = makeSimulator(scene, o);
  const double E0 = sim->energy();
  const auto before = appell::test::advanceCollecting(*sim, 1.5);
  EXPECT_LT(std::abs(yaw(sim->q())), 1e-9) << "straight while the servos agree";
  EXPECT_LT(std::abs(sim->q()[1]), 1e-9);
  EXPECT_NEAR(sim->v()[3], 1.0, 1e-3) << "at the commanded 1 m/s";
  for (int c = 0; c < 4; ++c) EXPECT_FALSE(sim->constraintData().isSliding(c)) << c;
  const auto turning = appell::test::advanceCollecting(*sim, 4.0);
  int slips = 0;
  for (const ContactEvent& e : turning) slips += e.kind == ContactEventKind::Slip;
  EXPECT_GT(slips, 0);
  // A tyre already sliding whose slip direction is decided afresh (its slip
  // along the old direction reversed) slides on: no second "slip" without a
  // "stick" between (the onset used to log up to four per tyre in 3e-8 s).
  std::vector<int> sliding(4, 0);
  for (const ContactEvent& e : turning) {
    if (e.kind == ContactEventKind::Slip) {
      EXPECT_EQ(sliding[e.constraint], 0) << "tyre " << e.constraint << " slips twice, at t = " << e.t;
      sliding[e.constraint] = 1;
    }
    if (e.kind == ContactEventKind::Stick) sliding[e.constraint] = 0;
  }
  for (int c = 0; c < 4; ++c) EXPECT_TRUE(sim->constraintData().isSliding(c)) << c;
  EXPECT_GT(sim->v()[2], 0.5) << "yaw rate: it turns left";
  EXPECT_GT(sim->frictionWork(), 0.5 * sim->jointWork()) << sim->frictionWork() << " of " << sim->jointWork();
  EXPECT_LT(balanceError(*sim, E0), 1e-9 * sim->jointWork());

  // Ideal tyres: the same servos, no turn at all.
  const std::string ideal = std::regex_replace(text, std::regex(R"( mu_static="[0-9.]+" mu_kinetic="[0-9.]+")"), "");
  ASSERT_NE(ideal, text);
  const Scene rigid = loadSceneFromString(ideal, example("skid_steer"), "skid_steer_ideal");
  auto straight = makeSimulator(rigid, o);
  const auto none = appell::test::advanceCollecting(*straight, 4.0);
  EXPECT_TRUE(none.empty());
  EXPECT_LT(std::abs(yaw(straight->q())), 1e-12);
  EXPECT_LT(std::abs(straight->q()[1]), 1e-12);
  EXPECT_GT(straight->q()[0], 3.0) << "it drove";
}

// Protects: the formulations agree with sliding contacts — the friction
// forces enter the tree solver and the dense KKT system the same way (a
// generalized force per unit normal load, normal loads from the k × k
// system), so the skid-steer robot's turn, four tyres sliding in 2-D with
// redundant rows, is the same motion in both (the sleigh test below checks
// one sliding blade to 1e-10 in all three formulations).
TEST(FrictionVehicles, TreeAndKktAgreeWhileTheTyresSlide) {
  const Scene scene = loadScene(example("skid_steer/skid_steer.urdf"));
  RunOptions o = runOptions(scene.settings);
  o.tol = 1e-10;
  auto tree = makeSimulator(scene, o);
  o.formulation = Formulation::Multipliers;
  auto kkt = makeSimulator(scene, o);
  appell::test::advanceCollecting(*tree, 1.9);
  appell::test::advanceCollecting(*kkt, 1.9);
  for (int c = 0; c < 4; ++c) {
    EXPECT_TRUE(tree->constraintData().isSliding(c)) << c;
    EXPECT_TRUE(kkt->constraintData().isSliding(c)) << c;
  }
  // Measured 3.4e-10 (q: wheel angles of ~10 rad), 2.0e-11 (v), 4.8e-10 (λ,
  // loads of ~100 N) after 0.3 s of sliding, over 21 slip events.
  EXPECT_LT((tree->q() - kkt->q()).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((tree->v() - kkt->v()).cwiseAbs().maxCoeff(), 1e-10);
  EXPECT_LT((tree->lambda() - kkt->lambda()).cwiseAbs().maxCoeff(), 2e-9);
}

// Protects: stick → slip on a knife edge. A Chaplygin sleigh on level ice,
// started turning in place, speeds up along its blade while its turn slows:
// the blade's lateral reaction grows from zero, peaks and decays. With μ at
// half the peak demand the blade slips exactly where the ideal sleigh's
// demand |λ_lat|/λₙ first reaches μ (the motions are the same until then);
// sliding, the lateral force is μλₙ against the slip, and E + friction work
// is conserved. Tree, KKT and Appell/Maggi agree while it slides.
TEST(FrictionVehicles, SleighOnIceSlidesSidewaysWhenTheDemandReachesMu) {
  SleighParams p = usualSleighParams(0.3, 0.0);
  p.turn_rate = 3.0;
  // The simulator keeps references to its model and constraints: they live
  // with it, on the heap.
  struct Run {
    BuiltScene scene;
    std::unique_ptr<Simulator> sim;
  };
  auto simulate = [&](double mu, Formulation f) {
    auto r = std::make_unique<Run>();
    r->scene = sleigh(p);
    BuiltScene& s = r->scene;
    if (std::isfinite(mu)) {
      ContactSpec spec = static_cast<const ShapeContact&>(*s.constraints[0]).spec();
      spec.mu = mu;
      s.constraints[0] = makeContact(spec);
    }
    r->sim = std::make_unique<Simulator>(s.model, s.constraints, makeSolver(f, s.model, s.constraints),
                                         IntegratorType::DormandPrince54, appell::test::tightIntegrator());
    EXPECT_TRUE(r->sim->setState(0, s.q0, s.v0)) << r->sim->lastStateError();
    return r;
  };
  // Rows: blade lateral, blade normal, the feet's normals.
  auto demand = [](const Simulator& sim) { return std::abs(sim.lambda()[0]) / sim.lambda()[1]; };
  const double inf = std::numeric_limits<double>::infinity();
  const auto ideal_run = simulate(inf, Formulation::Tree);
  Simulator& ideal = *ideal_run->sim;
  double peak = 0;
  while (ideal.time() < 3.0 - 1e-12) {
    ASSERT_TRUE(ideal.step(1e-2).ok);
    peak = std::max(peak, demand(ideal));
  }
  ASSERT_GT(peak, 0.05);
  const double mu = 0.5 * peak;

  const auto icy_run = simulate(mu, Formulation::Tree);
  Simulator& icy = *icy_run->sim;
  const auto events = appell::test::advanceCollecting(icy, 3.0);
  ASSERT_FALSE(events.empty());
  EXPECT_EQ(events[0].kind, ContactEventKind::Slip);
  EXPECT_EQ(events[0].constraint, 0) << "the blade";
  const double t_slip = events[0].t;
  // The ideal sleigh at t_slip: its demand is μ there, below μ before.
  const auto check_run = simulate(inf, Formulation::Tree);
  Simulator& check = *check_run->sim;
  while (check.time() < t_slip - 1e-12) {
    const double h = std::min(1e-2, t_slip - check.time());
    ASSERT_TRUE(check.step(h).ok);
    if (check.time() < t_slip - 1e-9) {
      EXPECT_LT(demand(check), mu) << "t = " << check.time();
    }
  }
  EXPECT_NEAR(demand(check), mu, 1e-9) << "the slip is located where the demand reaches μ";

  // Sliding: the force μλₙ against the blade's lateral slip (body y at the
  // blade point, the body origin), energy gone only to friction.
  EXPECT_TRUE(icy.constraintData().isSliding(0) || events.back().kind == ContactEventKind::Stick);
  const auto slide_run = simulate(mu, Formulation::Tree);
  Simulator& slide = *slide_run->sim;
  const double E0 = slide.energy();
  appell::test::advanceCollecting(slide, t_slip + 0.3);
  ASSERT_TRUE(slide.constraintData().isSliding(0));
  const double lateral_slip = slide.v()[4];
  EXPECT_GT(std::abs(lateral_slip), 1e-4) << "it slides sideways";
  EXPECT_NEAR(std::abs(slide.lambda()[0]), mu * slide.lambda()[1], 1e-9);
  EXPECT_LT(slide.lambda()[0] * lateral_slip, 0) << "against the slip";
  EXPECT_GT(slide.frictionWork(), 0);
  EXPECT_LT(balanceError(slide, E0), 1e-10 * E0);
  for (Formulation f : {Formulation::Multipliers, Formulation::Appell}) {
    const auto other_run = simulate(mu, f);
    Simulator& other = *other_run->sim;
    appell::test::advanceCollecting(other, t_slip + 0.3);
    EXPECT_LT((other.q() - slide.q()).cwiseAbs().maxCoeff(), 1e-10) << toString(f);
    EXPECT_LT((other.v() - slide.v()).cwiseAbs().maxCoeff(), 1e-10) << toString(f);
  }
}

namespace {

/// examples/car with its wheels locked (fixed joints: the brakes), at rest,
/// on a slope of θ (gravity tilted: downhill is +x), tyres μₛ = 0.9, μₖ = 0.7.
Scene brakedCarOnASlope(double theta) {
  std::string text = readText(example("car/car.urdf"));
  text = std::regex_replace(text, std::regex(R"(type="continuous")"), R"(type="fixed")");
  text = std::regex_replace(text, std::regex(R"(\s*<joint name="\w+_joint" position="0" velocity="[0-9.]+"/>)"), "");
  text = std::regex_replace(text, std::regex(R"(velocity="0 0 0  1 0 0")"), R"(velocity="0 0 0  0 0 0")");
  text = std::regex_replace(text, std::regex(R"( mu="0.9")"), R"( mu_static="0.9" mu_kinetic="0.7")");
  std::ostringstream g;
  g.precision(17);
  g << R"(<gravity xyz=")" << 9.81 * std::sin(theta) << " 0 " << -9.81 * std::cos(theta) << R"("/>)";
  text = std::regex_replace(text, std::regex(R"(<gravity xyz="0 0 -9.81"/>)"), g.str());
  return loadSceneFromString(text, example("car"), "braked_car");
}

}  // namespace

// Protects: sticking is exact, not a stiff spring. A car with its wheels
// locked, parked 60 s on a 10° slope (tan θ = 0.18 < μₛ = 0.9), does not
// move: its chassis stays within 1e-12 m of where it was put (engines with
// soft or regularised contacts creep here). Its tyres hold m g sin θ
// downhill and m g cos θ into the ground between them. The run summary says
// it is held by sticking, not stuck for good.
TEST(FrictionVehicles, BrakedCarParkedOnASlopeDoesNotCreep) {
  const double theta = 10 * std::numbers::pi / 180, W = 24 * 9.81;
  const Scene scene = brakedCarOnASlope(theta);
  RunOptions o = runOptions(scene.settings);
  auto sim = makeSimulator(scene, o);
  const VecX q0 = sim->q();
  const auto events = appell::test::advanceCollecting(*sim, 60.0, 0.5);
  EXPECT_TRUE(events.empty());
  EXPECT_LT((sim->q().head<3>() - q0.head<3>()).norm(), 1e-12) << "no creep";
  EXPECT_LT(sim->v().norm(), 1e-12);
  Vec3 force = Vec3::Zero();
  for (int c = 0; c < 4; ++c) {
    EXPECT_FALSE(sim->constraintData().isSliding(c));
    const ContactFrame& f = sim->contactFrame(c);
    const VecX& l = sim->lambda();
    force += l[3 * c] * f.t1 + l[3 * c + 1] * f.t2 + l[3 * c + 2] * f.normal;
  }
  EXPECT_NEAR(force.x(), -W * std::sin(theta), 1e-9) << "friction holds the weight's downhill part";
  EXPECT_NEAR(force.z(), W * std::cos(theta), 1e-9);
  const RunSummary r = runScene(scene, o);
  EXPECT_EQ(r.free_velocities, 0);
  EXPECT_TRUE(r.can_slip) << "held by sticking, not stuck for good";
}

// Protects: the same braked car on a slope steeper than its friction angle
// (45°, tan θ = 1 > μₛ) slides from the first instant, all four tyres
// together, at a = g (sin θ − μₖ cos θ), friction taking μₖ m g cos θ per metre.
TEST(FrictionVehicles, BrakedCarSlidesDownASlopeSteeperThanItsFrictionAngle) {
  const double theta = std::numbers::pi / 4, g = 9.81, m = 24;
  const Scene scene = brakedCarOnASlope(theta);
  RunOptions o = runOptions(scene.settings);
  o.tol = 1e-12;
  auto sim = makeSimulator(scene, o);
  const VecX q0 = sim->q();
  const double E0 = sim->energy();
  appell::test::advanceCollecting(*sim, 1.0);
  for (int c = 0; c < 4; ++c) EXPECT_TRUE(sim->constraintData().isSliding(c)) << c;
  const double a = g * (std::sin(theta) - 0.7 * std::cos(theta)), t = sim->time();
  const double travelled = sim->q()[0] - q0[0];
  EXPECT_NEAR(travelled, 0.5 * a * t * t, 1e-9);
  EXPECT_LT(std::abs(sim->q()[1] - q0[1]), 1e-12) << "straight down";
  EXPECT_NEAR(sim->frictionWork(), 0.7 * m * g * std::cos(theta) * travelled, 1e-8);
  EXPECT_LT(balanceError(*sim, E0), 1e-9);
}

// Protects the example as published (examples/block_incline): the block put
// at rest on a slope steeper than μₛ slides from t = 0 at g (sin α − μₖ cos α)
// on its four lower corners, straight downhill, E + friction work conserved.
TEST(FrictionVehicles, BlockOnAnInclineExampleSlidesAtTheKineticRate) {
  const double alpha = 0.5, g = 9.81, m = 3;
  const Scene scene = loadScene(example("block_incline/block_incline.urdf"));
  RunOptions o = runOptions(scene.settings);
  auto sim = makeSimulator(scene, o);
  const VecX q0 = sim->q();
  const double E0 = sim->energy();
  const std::vector<ContactEvent> start = sim->events();  // setState's own
  ASSERT_EQ(start.size(), 4u) << "the four lower corners start sliding at once";
  for (const ContactEvent& e : start) {
    EXPECT_EQ(e.kind, ContactEventKind::Slip);
    EXPECT_EQ(e.t, 0.0);
  }
  EXPECT_TRUE(appell::test::advanceCollecting(*sim, 1.0).empty()) << "then nothing changes";
  const Vec3 down(-std::cos(alpha), 0, -std::sin(alpha));
  const double travelled = (sim->q().head<3>() - q0.head<3>()).dot(down);
  const double a = g * (std::sin(alpha) - 0.4 * std::cos(alpha));
  EXPECT_NEAR(travelled, 0.5 * a * sim->time() * sim->time(), 1e-9);
  EXPECT_LT(std::abs(sim->q()[1] - q0[1]), 1e-12) << "straight downhill";
  EXPECT_NEAR(sim->frictionWork(), 0.4 * m * g * std::cos(alpha) * travelled, 1e-9);
  EXPECT_LT(balanceError(*sim, E0), 1e-12 * m * g);
}

namespace {

/// A homogeneous ball (m 1 kg, r 0.1 m) on the ground, its centre moving at
/// 1 m/s along x and spinning at ω_y: the contact slips at 1 − 0.1 ω_y m/s.
std::string launchedBall(double omega_y, const char* mu) {
  std::ostringstream s;
  s.precision(17);
  s << R"(<?xml version="1.0"?>
<robot name="ball">
  <link name="ball"><inertial><mass value="1"/><inertia ixx="0.004" ixy="0" ixz="0" iyy="0.004" iyz="0" izz="0.004"/></inertial><collision><geometry><sphere radius="0.1"/></geometry></collision></link>
  <appell>
    <gravity xyz="0 0 -9.81"/>
    <support name="ground" type="plane"/>
    <contact name="foot" link="ball" kind="rolling" support="ground" )"
    << mu << R"(/>
    <initial><joint name="root_joint" xyz="0 0 0.1" velocity="0 )"
    << omega_y << R"( 0 1 0 0"/></initial>
    <simulation integrator="dopri5" tol="1e-11" duration="0.2"/>
  </appell>
</robot>)";
  return s.str();
}

}  // namespace

// The friction issue's first item: an initial state that slips at a contact
// with finite μ is not refused — the contact starts sliding. A ball launched
// at 1 m/s without spin on μ = 0.5 loads (only its normal row is checked),
// slides from t = 0 and rolls from t* = 2v₀/(7μg) at 5v₀/7 (the classic
// result). Without μ the same state is refused as before. A slip at CAD
// level (1e-7 m/s on 10 rad/s) starts sliding as well and sticks at the
// same law's time, 6 ns later (located to 1e-12 s).
TEST(FrictionVehicles, ABallLaunchedSlidingLoadsAndStartsSliding) {
  LoadOptions no_check;
  no_check.check_initial_state = false;
  Scene raw = loadSceneFromString(launchedBall(0, R"(mu="0.5")"), ".", "launched", no_check);
  const InitialStateReport report = checkInitialState(raw, false);
  ASSERT_EQ(report.sliding, std::vector<std::string>{"foot"});
  EXPECT_LT(report.velocity_residual, 1e-12);  // the normal row holds

  const Scene scene = loadSceneFromString(launchedBall(0, R"(mu="0.5")"), ".", "launched");
  const RunSummary run = runScene(scene, runOptions(scene.settings));
  ASSERT_TRUE(run.ok) << run.failure;
  const double g = 9.81, mu = 0.5, t_star = 2.0 / (7 * mu * g);
  ASSERT_EQ(run.events.size(), 2u);
  EXPECT_EQ(run.events[0].kind, ContactEventKind::Slip);
  EXPECT_EQ(run.events[0].t, 0.0);
  EXPECT_EQ(run.events[1].kind, ContactEventKind::Stick);
  EXPECT_NEAR(run.events[1].t, t_star, 1e-9);

  EXPECT_THROW(loadSceneFromString(launchedBall(0, ""), ".", "ideal"), SceneError);
  // A slip at CAD level, s₀ = 1e-7 m/s on 10 rad/s, is a sliding start too:
  // the ball slides on its settled direction and sticks after 2s₀/(7μg).
  const double s0 = 1 - 0.1 * (10 - 1e-6);
  const Scene cad = loadSceneFromString(launchedBall(10 - 1e-6, R"(mu="0.5")"), ".", "cad");
  RunOptions o = runOptions(cad.settings);
  o.duration = 1e-3;
  const RunSummary tiny = runScene(cad, o);
  ASSERT_TRUE(tiny.ok) << tiny.failure;
  ASSERT_EQ(tiny.events.size(), 2u);
  EXPECT_EQ(tiny.events[0].kind, ContactEventKind::Slip);
  EXPECT_EQ(tiny.events[1].kind, ContactEventKind::Stick);
  EXPECT_NEAR(tiny.events[1].t, 2 * s0 / (7 * mu * g), 1e-12);
}

namespace {

/// examples/car at rest with its rear-left axle turned `yaw` rad about the
/// vertical (a CAD-level misalignment: no motion is left to the no-slip
/// rows), μ = 0.5 under it (the others 0.9: its scrub, on the circle, is
/// held by the rear-right tyre inside its cone) and 1 N·m on each rear wheel.
Scene misalignedCar(double yaw) {
  std::string text = readText(example("car/car.urdf"));
  std::ostringstream o;
  o.precision(17);
  o << R"(<origin xyz="-0.4 0.35 0" rpy="0 0 )" << yaw << R"("/>)";
  text = std::regex_replace(text, std::regex(R"(<origin xyz="-0.4 0.35 0" rpy="0 0 0"/>)"), o.str());
  text = std::regex_replace(text, std::regex(R"(velocity="0 0 0  1 0 0")"), R"(velocity="0 0 0  0 0 0")");
  text = std::regex_replace(text, std::regex(R"(velocity="6.666666666666667")"), R"(velocity="0")");
  text = std::regex_replace(text, std::regex(R"((name="rear_left_tyre".*) mu="0.9")"), "$1 mu=\"0.5\"");
  text = std::regex_replace(text, std::regex(R"(<simulation)"),
                            R"(<effort joint="rear_left_joint" value="1"/><effort joint="rear_right_joint" value="1"/><simulation)");
  return loadSceneFromString(text, example("car"), "misaligned_car");
}

std::unique_ptr<Simulator> carSimulator(const Scene& scene, Formulation f, double settle_time,
                                        double tol = 1e-10, const SolverOptions& solver = {}) {
  IntegratorOptions iopt;
  iopt.rtol = tol;
  iopt.atol = 1e-2 * tol;
  iopt.h_max = 0.1;
  SimulatorOptions sopt;
  sopt.contacts.settle_time = settle_time;
  // The exact law (settle_time 0) relaxes the slip direction at ~10⁸ s⁻¹:
  // at tight tolerances that is a legitimate run of thousands of tiny steps,
  // which the stall rule (docs/contacts.md §10: 5000 evaluations within
  // 10 µs) cannot tell from a stall and would time-step. Off here, where
  // that run is the point of the comparison.
  if (settle_time == 0)
    sopt.timestepping.stall_work = sopt.timestepping.stall_steps = std::numeric_limits<long>::max();
  auto sim = std::make_unique<Simulator>(scene.model, scene.constraints,
                                         makeSolver(f, scene.model, scene.constraints, solver),
                                         IntegratorType::DormandPrince54, iopt, sopt);
  sim->setJointForces(scene.jointForces());
  sim->setState(0.0, scene.q0, scene.v0);
  return sim;
}

}  // namespace

// Protects the friction issue's over-constrained vehicle (item 4): a car
// whose rear-left axle is 1e-6 or 1e-8 rad out of line has no motion left
// to its no-slip rows, and with μ = 0.9 it drives — that tyre scrubs
// sideways by the misalignment times the speed, on its settled slip
// direction: its friction, on the circle μλₙ, is the wheel's drive force
// along the tyre and the rest of the circle across it, held by the other
// rear tyre. The car accelerates at 2τ/R over m + 4I/R² less the scrub's drag,
// the friction takes |f| |s| with |s| the misalignment's slip — before, the
// same run crawled (26 000 steps per simulated millisecond) — and the work
// balance closes to round-off.
TEST(FrictionVehicles, AMisalignedCarScrubsAndDrives) {
  for (const double eps : {1e-6, 1e-8}) {
    SCOPED_TRACE(eps);
    const Scene scene = misalignedCar(eps);
    auto sim = carSimulator(scene, Formulation::Tree, SimulatorOptions{}.contacts.settle_time);
    const double E0 = sim->energy();
    ASSERT_EQ(sim->events().size(), 1u);  // at setState: the no-slip rows cannot all hold
    EXPECT_EQ(sim->events()[0].kind, ContactEventKind::Slip);
    EXPECT_EQ(scene.constraints[sim->events()[0].constraint]->name(), "rear_left_tyre");
    EXPECT_TRUE(appell::test::advanceCollecting(*sim, 2.0, 0.1).empty()) << "it scrubs throughout";
    EXPECT_TRUE(sim->constraintData().isSliding(2));
    EXPECT_LT(sim->counters().steps, 200) << "no crawl";
    const double R = 0.15, m = 24, I = 0.01125, t = sim->time();
    const double a = 2 * 1.0 / R / (m + 4 * I / (R * R)), x = sim->q()[0];
    EXPECT_NEAR(x, 0.5 * a * t * t, 2e-6 * eps / 1e-6 + 1e-12) << "drives straight ahead";
    EXPECT_LT(std::abs(sim->q()[1]), 1e-12);
    // The scrubbing tyre: on its circle, the drive force along it.
    const VecX& l = sim->lambda();
    const double ft = std::hypot(l[6], l[7]), fn = l[8];
    EXPECT_NEAR(ft, 0.5 * fn, 1e-9 * fn);
    const double slip = sim->constraintData().slide[2].slip.norm();
    EXPECT_NEAR(slip, eps * sim->v()[3] * ft / std::abs(l[6]), 1e-6 * slip) << "the slip the misalignment forces";
    // Dissipation |f| |s| integrated: with v = a t, ∫ |s| dt = ε x ft/|f_lat|.
    EXPECT_NEAR(sim->frictionWork(), ft * eps * x * ft / std::abs(l[6]), 1e-5 * sim->frictionWork());
    EXPECT_LT(balanceError(*sim, E0), 1e-12 * E0);
    // The run summary reports the scrub: that tyre sliding in every sample,
    // its largest slip the one at the end.
    RunOptions o = runOptions(scene.settings);
    const RunSummary r = runScene(scene, o);
    ASSERT_TRUE(r.ok) << r.failure;
    EXPECT_EQ(r.contacts[2].sliding_samples, r.samples);
    EXPECT_NEAR(r.contacts[2].max_slip, slip, 1e-6 * slip);
    EXPECT_EQ(r.contacts[3].sliding_samples, 0);
  }
}

// Protects the settled direction as the limit of the exact sliding law, and
// its solve in both formulations: from the scrubbing car's state at 0.5 s,
// the exact law (settle_time = 0, the direction integrated through its
// relaxation, ~10⁸ s⁻¹, at tolerance 1e-13: the direction of a 2.6e-7 m/s
// slip is only as good as the slip's absolute error) and the settled one
// agree after 0.1 ms — velocities to 1e-9, forces to 1e-6 of the scrub's —
// and the tree and dense KKT formulations agree over 0.5 s of scrubbing to
// 1e-10.
TEST(FrictionVehicles, TheSettledScrubIsTheExactSlidingLimit) {
  const Scene scene = misalignedCar(1e-6);
  auto tree = carSimulator(scene, Formulation::Tree, 1e-6);
  auto kkt = carSimulator(scene, Formulation::Multipliers, 1e-6);
  appell::test::advanceCollecting(*tree, 0.5, 0.1);
  appell::test::advanceCollecting(*kkt, 0.5, 0.1);
  EXPECT_LT((tree->q() - kkt->q()).lpNorm<Eigen::Infinity>(), 1e-10);
  EXPECT_LT((tree->v() - kkt->v()).lpNorm<Eigen::Infinity>(), 1e-10);
  EXPECT_LT((tree->lambda() - kkt->lambda()).lpNorm<Eigen::Infinity>(), 1e-8);

  auto exact = carSimulator(scene, Formulation::Tree, 0.0, 1e-13);
  exact->setState(tree->time(), tree->q(), tree->v());
  ASSERT_TRUE(exact->constraintData().isSliding(2));
  const double t1 = tree->time() + 1e-4;
  const long settled_before = tree->counters().steps;
  appell::test::advanceCollecting(*exact, t1, 1e-4);
  appell::test::advanceCollecting(*tree, t1, 1e-4);
  EXPECT_GT(exact->counters().steps, 100 * (tree->counters().steps - settled_before))
      << "the exact law is stiff";
  EXPECT_EQ(exact->counters().windows + tree->counters().windows, 0) << "both event-driven";
  EXPECT_LT((tree->v() - exact->v()).lpNorm<Eigen::Infinity>(), 1e-9);
  EXPECT_LT((tree->lambda() - exact->lambda()).lpNorm<Eigen::Infinity>(), 1e-6 * 23.4);
}

// Protects the transition the settled scrub alone could not make (the
// mimic issue's "drive, then turn"): sticking contacts that become
// over-constrained while they move. With parallel knuckles at δ ≠ 0 the four
// tyres have no common instantaneous centre: sticking would need internal
// lateral forces growing like δ̇/δ, so a tyre must scrub from δ = 0⁺. The
// rows count as redundant until their mismatch (∝ δ²) passes the solver's
// consistency tolerance; there the solve fails, the over-constrained
// direction of W picks the tyre whose cone fills first — the outer front
// one — and the step is redone with it sliding (friction_overconstrained.cpp).
// Before, the run stopped there with "inconsistent constraints". Checked:
// one slip event, within 5 ms of the hand wheel starting; then the car
// turns on the inner wheel's Ackermann circle ρ = t/2 + L/tan δ (the
// rolling tyres' common centre) to 1e-9, with the outer tyre scrubbing on
// its settled decelerating-or-growing direction without a crawl; the work
// balance closes; and locating the event at a 1000× tighter consistency
// tolerance moves the final state by the lag's effect only.
TEST(FrictionVehicles, AParallelSteeredCarStartsToScrubWhenItsHandWheelTurnsAtSpeed) {
  // examples/steered_car: parallel knuckles (both mimic the hand wheel, 1/16),
  // driven from rest to 1 m/s with the hand wheel held straight, which turns
  // to 0.3 rad (δ = 0.01875) over t = 2 … 2.5 s.
  const Scene scene = loadScene(example("steered_car/steered_car.urdf"));
  auto sim = carSimulator(scene, Formulation::Tree, 1e-4);
  const double E0 = sim->energy();
  const double T = 3.5;
  const auto events = appell::test::advanceCollecting(*sim, T, 0.05);
  ASSERT_NEAR(sim->time(), T, 1e-12);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].kind, ContactEventKind::Slip);
  EXPECT_EQ(scene.constraints[events[0].constraint]->name(), "fr") << "the outer front tyre";
  EXPECT_GT(events[0].t, 2.0);
  EXPECT_LT(events[0].t, 2.005);
  EXPECT_EQ(sim->counters().overconstrained, 1);
  EXPECT_LT(sim->counters().steps, 2000) << "no crawl";
  const ConstraintData& cd = sim->constraintData();
  EXPECT_FALSE(cd.isSliding(0));
  EXPECT_TRUE(cd.isSliding(1));
  EXPECT_FALSE(cd.isSliding(2));
  EXPECT_FALSE(cd.isSliding(3));
  const Model& m = scene.model;
  const VecX& v = sim->v();
  const double delta = sim->q()[m.joints[m.jointIndex("steer_left")].idx_q];
  const double rho = 0.35 + 0.8 / std::tan(delta);
  EXPECT_NEAR(delta, 0.01875, 1e-6);
  EXPECT_NEAR(v[2] / v[3], 1 / rho, 1e-9 / rho) << "the inner wheel's circle";
  EXPECT_NEAR(v[4], 0.4 * v[2], 1e-12) << "the rear axle rolls";
  EXPECT_GT(sim->frictionWork(), 0);
  EXPECT_LT(balanceError(*sim, E0), 1e-10 * E0);

  SolverOptions tighter;
  tighter.consistency_tol = 1e-11;
  auto early = carSimulator(scene, Formulation::Tree, 1e-4, 1e-10, tighter);
  const auto early_events = appell::test::advanceCollecting(*early, T, 0.05);
  ASSERT_EQ(early_events.size(), 1u);
  EXPECT_LT(early_events[0].t, 2.0005) << "located 10× nearer δ = 0⁺";
  EXPECT_LT((early->q() - sim->q()).head(3).norm(), 1e-9) << "the lag's scrub is ∝ δ²";

  // The dense formulations find the mismatch by their own rank tests (the
  // event a little earlier or later) and agree on the rest.
  for (Formulation f : {Formulation::Multipliers, Formulation::Appell}) {
    auto other = carSimulator(scene, f, 1e-4);
    const auto other_events = appell::test::advanceCollecting(*other, T, 0.05);
    ASSERT_EQ(other_events.size(), 1u) << toString(f);
    EXPECT_EQ(other_events[0].constraint, events[0].constraint) << toString(f);
    EXPECT_NEAR(other_events[0].t, events[0].t, 5e-3) << toString(f);
    EXPECT_LT((other->q() - sim->q()).head(3).norm(), 1e-9) << toString(f);
    EXPECT_LT((other->v() - sim->v()).norm(), 1e-8) << toString(f);
  }
}

// Protects: a car on uneven ground with creeping tyres (examples/
// suspended_car: four struts on spring-dampers, tyres μ = 0.9 with a creep
// speed v_c = 0.1 m/s, over sines within ±5 cm). With ideal or sticking
// tyres this car stops around its landing (t = 0.15 s, 0.11 s): its rear
// tyres' lateral rows are nearly dependent on two different cross-slopes,
// and their exact multipliers reach ±10¹⁰ N (docs/contacts.md §4). With the
// creep law they are forces, and the car coasts on at 4 m/s. Checked at
// every step end:
// every step succeeds; every closed tyre slides and carries exactly its
// law, λₜ = −μ λₙ s/max(|s|, v_c), so |λₜ| ≤ μ λₙ; the tyres lift off over
// the crests and land again (located events); the work balance
// E + impact losses + friction work − servo work = E₀ closes to 1e-9
// (relative; measured 1.6e-11) and the residuals stay at round-off.
TEST(FrictionVehicles, ASuspendedCarWithCreepingTyresCrossesUnevenGround) {
  const Scene scene = loadScene(example("suspended_car/suspended_car.urdf"));
  RunOptions o = runOptions(scene.settings);
  auto sim = makeSimulator(scene, o);
  const double E0 = sim->energy(), mu = 0.9, vc = 0.1;
  const ConstraintData& cd = sim->constraintData();
  int lift_offs = 0, touchdowns = 0, checked = 0;
  double worst_law = 0, residual = 0;
  while (sim->time() < 2.5 - 1e-12) {
    const StepStatus st = sim->step(std::min(1e-2, 2.5 - sim->time()));
    ASSERT_TRUE(st.ok) << "at t = " << sim->time() << ": " << st.message;
    for (const ContactEvent& e : sim->events()) {
      lift_offs += e.kind == ContactEventKind::LiftOff;
      touchdowns += e.kind == ContactEventKind::Touchdown;
      EXPECT_NE(e.kind, ContactEventKind::Stick) << "a creeping tyre never sticks";
      EXPECT_NE(e.kind, ContactEventKind::Slip);
    }
    residual = std::max({residual, sim->velocityResidual(), sim->gapResidual()});
    for (int c = 0; c < 4; ++c) {
      if (!sim->isClosed(c)) continue;
      EXPECT_TRUE(cd.isSliding(c)) << "closed means sliding, tyre " << c;
      const auto& sr = cd.slide[c];
      const double load = sim->lambda()[cd.offset[c] + sim->constraints()[c]->unilateralRow()];
      const Vec3 law = -mu * load * sr.slip / std::max(sr.slip.norm(), vc);
      for (int i = 0; i < sr.n; ++i)
        worst_law = std::max(worst_law, std::abs(sim->lambda()[cd.offset[c] + sr.row[i]] - law[i]));
      ++checked;
    }
  }
  EXPECT_GT(checked, 1000);
  EXPECT_LT(worst_law, 1e-9) << "the friction force is the creep law (loads ~100 N)";
  EXPECT_GE(lift_offs, 2) << "tyres lift off over the crests";
  EXPECT_GE(touchdowns, lift_offs + 4) << "the landing, and every lift-off lands again";
  EXPECT_LT(balanceError(*sim, E0), 1e-9 * E0);
  EXPECT_LT(residual, 1e-10);
  EXPECT_GT(sim->q()[0], 8.0) << "it coasted on";
  EXPECT_LT(std::abs(sim->q()[1]), 0.05) << "and stayed on course";

  // Sticking or ideal tyres: the event scheme stops at the landing, says
  // why, and points to the creep law (the automatic scheme would take the
  // landing with time-stepping instead: test_contact_timestepping.cpp).
  o.contacts = ContactScheme::Events;
  const std::string text = readText(example("suspended_car/suspended_car.urdf"));
  for (const char* rigid : {R"( creep_speed="0.1")", R"( mu="0.9" creep_speed="0.1")"}) {
    const std::string xml = std::regex_replace(text, std::regex(rigid), "");
    ASSERT_NE(xml, text);
    const Scene rigid_scene = loadSceneFromString(xml, example("suspended_car"), "rigid");
    auto stuck = makeSimulator(rigid_scene, o);
    StepStatus st;
    while (stuck->time() < 1.0 && (st = stuck->step(1e-2)).ok) {
    }
    EXPECT_FALSE(st.ok) << rigid << ": ran to t = " << stuck->time();
    EXPECT_LT(stuck->time(), 0.5);
    EXPECT_NE(st.message.find("'creep_speed' slip a little instead"), std::string::npos) << st.message;
  }
}
