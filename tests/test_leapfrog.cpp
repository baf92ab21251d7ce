// The leapfrog (generalised Störmer–Verlet with RATTLE-type discrete
// constraints, leapfrog.cpp) on nonholonomic systems: what a fixed-step user
// needs.
//   • the whole simulator step (kicks, impulses, projections) is
//     time-reversible to round-off on the rolling disk and the sleigh;
//   • second order on the tilted rolling disk through the whole simulator
//     (projections included), with the constraints held at every step;
//   • at dt = 10 ms — where symplectic Euler's energy error passes 5 % within
//     a second — the disk, the Chaplygin sleigh and the Chaplygin ball keep
//     their energy error bounded: no larger over the last tenth of a long run
//     than over the first (no drift), which these reversible integrable
//     problems allow a symmetric method (Modin & Verdier 2020);
//   • an implicit half-step that cannot converge fails the step with a
//     message that says so, keeping the last state;
//   • the sleigh example runs at 10 ms where RK4 is unstable.
#include <gtest/gtest.h>

#include <appell/run.hpp>
#include <appell/simulator.hpp>
#include <appell/urdf.hpp>

#include "chaplygin_ball.hpp"
#include "rolling_disk.hpp"
#include "sleigh.hpp"

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

using namespace appell;
using namespace appell::scenes;

namespace {

BuiltScene tiltedDisk() {
  RollingDiskParams p;
  p.lean = 0.3;
  p.axle_rate = 5.0;
  p.precession = 0.8;
  return rollingDisk(p);
}

/// The lateral sleigh (Emelyanova & Fufaev 1978) on its incline, moving and turning.
BuiltScene movingSleigh(bool reduced = false) {
  SleighParams sp = lateralSleighParams();
  sp.speed = 0.6;
  sp.turn_rate = 0.8;
  return reduced ? sleighReduced(sp) : sleigh(sp);
}

struct NamedScene {
  const char* name;
  BuiltScene scene;
};

std::unique_ptr<Simulator> makeSim(const BuiltScene& s, IntegratorType type,
                                   const IntegratorOptions& o = {}) {
  auto sim = std::make_unique<Simulator>(
      s.model, s.constraints, makeSolver(Formulation::Tree, s.model, s.constraints), type, o);
  sim->setState(0, s.q0, s.v0);
  return sim;
}

struct EnergyRecord {
  double early = 0, late = 0;  ///< max |E − E₀| over the first and the last tenth
  double residual = 0;         ///< max of the constraint residuals after any step
  bool ok = true;
};

EnergyRecord runFixed(const BuiltScene& s, IntegratorType type, double h, int steps) {
  auto sim = makeSim(s, type);
  const double E0 = sim->energy();
  EnergyRecord r;
  for (int k = 0; k < steps; ++k) {
    if (!sim->step(h).ok) {
      r.ok = false;
      return r;
    }
    const double e = std::abs(sim->energy() - E0) / std::abs(E0);
    if (k < steps / 10) r.early = std::max(r.early, e);
    if (k >= steps - steps / 10) r.late = std::max(r.late, e);
    r.residual = std::max({r.residual, sim->velocityResidual(), sim->gapResidual()});
  }
  return r;
}

}  // namespace

// Time reversibility through the simulator: 100 steps of 10 ms, the
// velocities reversed, 100 more return to the start to round-off — on the
// rolling disk (a holonomic contact row: the gap condition at q⁺), the
// floating sleigh (knife edge + two sliding feet) and the reduced sleigh (one
// nonholonomic row, no holonomic one). Projecting only at the step's end
// (no impulse in the first kick) misses by 10⁻³ on the disk; so does
// carrying the fixed point's history across steps (leapfrog.cpp).
TEST(Leapfrog, SimulatorStepIsTimeReversible) {
  const NamedScene cases[] = {
      {"disk", tiltedDisk()}, {"sleigh", movingSleigh()}, {"reduced sleigh", movingSleigh(true)}};
  for (const auto& c : cases) {
    const BuiltScene& s = c.scene;
    auto sim = makeSim(s, IntegratorType::Leapfrog);
    for (int k = 0; k < 100; ++k) ASSERT_TRUE(sim->step(1e-2).ok) << c.name;
    const VecX q = sim->q(), v = -sim->v();
    sim->setState(sim->time(), q, v);
    for (int k = 0; k < 100; ++k) ASSERT_TRUE(sim->step(1e-2).ok) << c.name;
    VecX d(s.model.nv);
    difference(s.model, s.q0, sim->q(), d);
    std::printf("%s: round trip misses by q %.2e, v %.2e\n", c.name, d.norm(), (sim->v() + s.v0).norm());
    EXPECT_LT(d.norm(), 1e-12) << c.name;
    EXPECT_LT((sim->v() + s.v0).norm(), 1e-12) << c.name;
  }
}

// Second order through the simulator: halving dt divides the error at
// t = 2 s by four, measured against Dormand–Prince at 1e-12; the rolling rows
// and the contact gap hold to round-off after every step.
TEST(Leapfrog, RollingDiskIsSecondOrderWithTheConstraintsHeldAtEveryStep) {
  const BuiltScene s = tiltedDisk();
  const double T = 2.0;
  IntegratorOptions tight;
  tight.rtol = tight.atol = 1e-12;
  auto ref = makeSim(s, IntegratorType::DormandPrince54, tight);
  ASSERT_TRUE(ref->advanceTo(T, 1e-3).ok);
  std::vector<double> err;
  for (int n : {100, 200, 400}) {
    auto sim = makeSim(s, IntegratorType::Leapfrog);
    double residual = 0;
    for (int k = 0; k < n; ++k) {
      ASSERT_TRUE(sim->step(T / n).ok);
      residual = std::max({residual, sim->velocityResidual(), sim->gapResidual()});
    }
    EXPECT_LT(residual, 1e-12) << "dt = " << T / n;
    VecX d(s.model.nv);
    difference(s.model, ref->q(), sim->q(), d);
    err.push_back(std::sqrt(d.squaredNorm() + (sim->v() - ref->v()).squaredNorm()));
  }
  for (size_t k = 0; k + 1 < err.size(); ++k) {
    const double order = std::log2(err[k] / err[k + 1]);
    std::printf("dt = %g: error %.3e, observed order %.2f\n", T / (100 << k), err[k], order);
    EXPECT_GT(order, 1.8);
    EXPECT_LT(order, 2.3);
  }
}

// The case: symplectic Euler at dt = 10 ms loses the disk (its energy
// error grows past 5 % within a second and keeps growing); the leapfrog at the
// same step keeps the error bounded over 200 s (20 000 steps), the last
// tenth no worse than the first.
TEST(Leapfrog, RollingDiskEnergyStaysBoundedAtTenMilliseconds) {
  const BuiltScene s = tiltedDisk();
  const EnergyRecord lf = runFixed(s, IntegratorType::Leapfrog, 1e-2, 20000);
  ASSERT_TRUE(lf.ok);
  std::printf("leapfrog, disk, 200 s: max |ΔE|/E first 20 s %.3e, last 20 s %.3e\n", lf.early, lf.late);
  EXPECT_LT(lf.late, 1.5 * lf.early);
  EXPECT_LT(lf.late, 1e-3);
  const EnergyRecord eu = runFixed(s, IntegratorType::SymplecticEuler, 1e-2, 100);
  std::printf("symplectic Euler, disk, 1 s: max |ΔE|/E %.3e\n", eu.early + eu.late);
  EXPECT_TRUE(!eu.ok || eu.late > 30 * lf.late);
}

// Two more reversible problems: the Chaplygin sleigh on its incline (energy
// passes between the motion and the height) and the Chaplygin ball (an
// unbalanced-inertia ball rolling without slipping), 10 000 steps each.
TEST(Leapfrog, SleighAndChaplyginBallEnergyStaysBounded) {
  const NamedScene cases[] = {{"sleigh", movingSleigh()}, {"Chaplygin ball", chaplyginBall()}};
  for (const auto& c : cases) {
    const EnergyRecord r = runFixed(c.scene, IntegratorType::Leapfrog, 1e-2, 10000);
    ASSERT_TRUE(r.ok) << c.name;
    std::printf("leapfrog, %s, 100 s: max |ΔE|/E first 10 s %.3e, last 10 s %.3e, residual %.1e\n",
                c.name, r.early, r.late, r.residual);
    EXPECT_LT(r.late, 1.5 * r.early) << c.name;
    EXPECT_LT(r.residual, 1e-12) << c.name;
  }
}

// A body spinning at 2000 rad/s about an intermediate axis at dt = 10 ms:
// ½h |∂f/∂v| ≈ 10, the implicit half-kick's fixed point diverges. The step
// fails, says why and what to do, and the state is the last good one.
TEST(Leapfrog, AHalfStepThatCannotConvergeFailsWithTheReason) {
  ModelBuilder b;
  b.addBody("top", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(),
            Inertia{1.0, Vec3::Zero(), Vec3(0.1, 0.2, 0.3).asDiagonal()});
  const Model m = b.build();
  VecX q = neutralConfiguration(m), v = VecX::Zero(m.nv);
  v.head<3>() = Vec3(30, 2000, 30);
  Simulator sim(m, {}, makeSolver(Formulation::Tree, m, {}), IntegratorType::Leapfrog);
  sim.setState(0, q, v);
  const StepStatus st = sim.step(1e-2);
  EXPECT_FALSE(st.ok);
  EXPECT_NE(st.message.find("implicit half-step did not converge"), std::string::npos) << st.message;
  EXPECT_NE(st.message.find("smaller dt"), std::string::npos) << st.message;
  EXPECT_EQ(sim.time(), 0.0);
  EXPECT_EQ(sim.v(), v);
  // A step the fixed point can take converges (½h |∂f/∂v| ≈ 0.1).
  EXPECT_TRUE(sim.step(1e-4).ok);
}

// The sleigh example (docs/engine.md's claim): its motion has a damped mode
// (λ ≈ −290 s⁻¹) that puts RK4 at 10 ms outside its stability region — the
// run stops, naming that cause — while the leapfrog at 10 ms runs 100 s with
// the energy error bounded and every constraint at round-off.
TEST(Leapfrog, SleighExampleRunsAtTenMillisecondsWhereRk4IsUnstable) {
  const Scene scene = loadScene(std::string(APPELL_SOURCE_DIR) + "/examples/sleigh/sleigh.urdf");
  RunOptions o = runOptions(scene.settings);
  o.duration = 100;
  o.dt = 1e-2;
  o.integrator = IntegratorType::Leapfrog;
  const RunSummary lf = runScene(scene, o);
  ASSERT_TRUE(lf.ok) << lf.failure;
  EXPECT_LT(lf.relativeEnergyDeviation(), 2e-4);
  EXPECT_LT(lf.max_velocity_residual, 1e-12);
  EXPECT_LT(lf.max_gap_residual, 1e-11);  // round-off on coordinates that grow along the slope
  o.integrator = IntegratorType::RK4;
  const RunSummary rk = runScene(scene, o);
  EXPECT_FALSE(rk.ok);
  EXPECT_NE(rk.failure.find("outside RK4's stability region"), std::string::npos) << rk.failure;
}
