// Passive, time-independent constraints do no work (the nonholonomic terms are
// gyroscopic: Levi-Civita & Amaldi, Lezioni di meccanica razionale II.2, 1927, §60): the total energy is conserved. 10 s of each
// scene with Dormand–Prince 5(4) at tight tolerance and drift projection:
// relative energy drift < 1e-9 and constraint residuals < 1e-10 throughout.
#include <gtest/gtest.h>

#include <appell/simulator.hpp>

#include "ball.hpp"
#include "chaplygin_ball.hpp"
#include "ellipsoid.hpp"
#include "hemisphere_bowl.hpp"
#include "rolling_disk.hpp"
#include "sleigh.hpp"

using namespace appell;
using namespace appell::scenes;

namespace {

std::vector<BuiltScene> passiveScenes() {
  std::vector<BuiltScene> s;
  RollingDiskParams disk;
  disk.lean = 0.35;
  disk.precession = 1.2;
  disk.axle_rate = 6.0;
  disk.lean_rate = 0.4;
  s.push_back(rollingDisk(disk));
  s.push_back(verticalRollingDisk());
  DiskChainParams chain;
  chain.lean = 0.2;
  chain.heading_rate = 0.8;
  chain.spin_rate = 7.0;
  s.push_back(rollingDiskChain(chain));
  s.push_back(ball());
  s.push_back(chaplyginBall());
  ChaplyginBallParams top;
  top.com_offset = Vec3(0.015, -0.01, 0.02);
  s.push_back(chaplyginBall(top));
  SleighParams lateral = lateralSleighParams();
  lateral.heading = 0.7;
  lateral.speed = 1.0;
  lateral.turn_rate = 0.8;
  lateral.duration = 10;
  s.push_back(sleigh(lateral));
  s.push_back(sleighReduced(lateral));
  SleighParams usual = usualSleighParams();
  usual.heading = -0.4;
  usual.speed = 0.5;
  usual.turn_rate = 1.5;
  s.push_back(sleigh(usual));
  HemisphereBowlParams hb;
  hb.contact_polar = 0.25;
  hb.tilt = 0.1;
  hb.omega = Vec3(0.4, -0.3, 1.2);
  s.push_back(hemisphereInBowl(hb));
  s.push_back(ellipsoidOnPlane());
  return s;
}

}  // namespace

TEST(SceneEnergy, ConservedOverTenSecondsWithProjection) {
  IntegratorOptions io;
  io.rtol = 1e-12;
  io.atol = 1e-12;
  io.h_max = 0.01;
  for (const BuiltScene& s : passiveScenes()) {
    Simulator sim(s.model, s.constraints, makeSolver(Formulation::Multipliers, s.model, s.constraints),
                  IntegratorType::DormandPrince54, io);
    sim.setState(0, s.q0, s.v0);
    const double E0 = sim.energy();
    const double scale = std::max({std::abs(E0), sim.kineticEnergy(), std::abs(sim.potentialEnergy())});
    double drift = 0, vres = 0, gres = 0;
    for (int k = 1; k <= 100; ++k) {
      const StepStatus st = sim.advanceTo(0.1 * k, 1e-3);
      ASSERT_TRUE(st.ok) << s.name << ": " << st.message;
      drift = std::max(drift, std::abs(sim.energy() - E0) / scale);
      vres = std::max(vres, sim.velocityResidual());
      gres = std::max(gres, sim.gapResidual());
    }
    std::printf("%-28s energy drift %.2e  |Av+b| %.1e  |g| %.1e  steps %ld\n", s.name.c_str(), drift,
                vres, gres, sim.counters().steps);
    EXPECT_LT(drift, 1e-9) << s.name;
    EXPECT_LT(vres, 1e-10) << s.name;
    EXPECT_LT(gres, 1e-10) << s.name;
  }
}
