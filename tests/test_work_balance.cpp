// The work balance of driven scenes (Simulator::jointWork, supportWork):
//     E(t) + impact losses + friction work − ∫ τ·v dt − ∫ −λᵀb dt = E(0).
// Joint forces put work in through τ·v; a constraint that moves in time (a
// turntable under a rolling ball) through its force's power vᵀAᵀλ = −λᵀb.
// The integrals are taken by the integrator's own stages and weights (the
// powers are rates of the acceleration field), so with RK4 the balance closes
// as O(h⁴) — not O(h²) as a trapezoidal rule over the steps would: checked on
// an N-trailer driven by a constant wheel torque and on a ball rolling on a
// spinning turntable, where E alone is not conserved.
#include <appell/run.hpp>
#include <appell/urdf.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using namespace appell;

namespace {

struct Balance {
  double error = 0;     ///< max |E + losses − work in − E₀| over the run (J)
  double work_in = 0;   ///< joint + support work at the end (J)
  double energy_change = 0;
};

Balance run(const std::string& file, double dt) {
  const Scene scene = loadScene(std::string(APPELL_SOURCE_DIR) + "/" + file);
  RunOptions o = runOptions(scene.settings);
  o.integrator = IntegratorType::RK4;
  o.dt = dt;
  o.duration = 1.0;
  const auto sim = makeSimulator(scene, o);
  const double e0 = sim->energy();
  Balance b;
  while (sim->time() < o.duration - 1e-12) {
    const StepStatus st = sim->step(dt);
    EXPECT_TRUE(st.ok) << st.message;
    if (!st.ok) break;
    const double in = sim->jointWork() + sim->supportWork();
    b.error = std::max(b.error, std::abs(sim->energy() + sim->impactEnergyLoss() + sim->frictionWork() - in - e0));
    b.work_in = in;
    b.energy_change = sim->energy() - e0;
  }
  return b;
}

void expectFourthOrderBalance(const std::string& file) {
  const Balance coarse = run(file, 1e-2), fine = run(file, 1e-3);
  SCOPED_TRACE(file);
  // Work really goes in, and the energy changes by it.
  EXPECT_GT(std::abs(fine.work_in), 1e-3);
  EXPECT_GT(std::abs(fine.energy_change), 1e-3);
  // The balance closes, and 10× smaller steps close it ~10⁴× better
  // (measured 7500 and 5700; a second-order quadrature would give 100).
  EXPECT_LT(fine.error, 1e-9 * std::abs(fine.work_in) + 1e-12);
  EXPECT_GT(coarse.error / fine.error, 2000.0) << coarse.error << " → " << fine.error;
}

}  // namespace

TEST(WorkBalance, JointForcesOnADrivenTrailer) { expectFourthOrderBalance("examples/ntrailer/ntrailer3.urdf"); }

TEST(WorkBalance, AMovingSupportDrivesAnOtherwisePassiveBall) {
  expectFourthOrderBalance("tests/data/io/scenes/ball_turntable.urdf");
}

// The divergence watch reads the same balance in driven scenes: symplectic
// Euler at a step far too long for the trailer's steering drifts off it, and
// the run stops, naming the cause, with the last state still within the bound.
TEST(WorkBalance, DivergingDrivenSceneIsStoppedWithinTheBound) {
  const Scene scene = loadScene(std::string(APPELL_SOURCE_DIR) + "/examples/ntrailer/ntrailer3.urdf");
  RunOptions o = runOptions(scene.settings);
  o.integrator = IntegratorType::SymplecticEuler;
  o.dt = 0.2;
  o.duration = 20;
  const RunSummary s = runScene(scene, o, {});
  ASSERT_FALSE(s.ok);
  EXPECT_NE(s.failure.find("work balance of this driven scene"), std::string::npos) << s.failure;
  EXPECT_LT(s.time, o.duration);
  EXPECT_LE(s.max_energy_deviation, o.max_energy_error * s.energy_scale);
  // With the watch off the same run goes on to the end, further off balance.
  o.max_energy_error = std::numeric_limits<double>::infinity();
  const RunSummary off = runScene(scene, o, {});
  EXPECT_TRUE(off.ok) << off.failure;
  EXPECT_GT(off.relativeEnergyDeviation(), 0.05);
}
