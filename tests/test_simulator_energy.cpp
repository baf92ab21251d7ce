// The simulator on passive, time-independent nonholonomic systems: the
// reactions do no work, so energy is conserved (relative drift < 1e-9 over
// 10 s with Dormand–Prince at rtol = atol = 1e-12), and with projection the
// constraint residuals stay below 1e-10. Plus an exact solution (a homogeneous
// ball rolls straight at constant speed) and agreement between formulations.
#include <appell/appell_maggi.hpp>
#include <appell/kkt.hpp>
#include <appell/simulator.hpp>

#include "random_tree.hpp"
#include "test_solver_rows.hpp"

#include <gtest/gtest.h>

#include <numbers>

namespace appell {
namespace {

using test::RollingBall;

IntegratorOptions tight() {
  IntegratorOptions o;
  o.rtol = o.atol = 1e-12;
  return o;
}

struct System {
  std::string name;
  Model model;
  ConstraintList constraints;
  VecX q0, v0;
};

// Ball of radius R with displaced centre of mass and unequal moments (a
// Chaplygin-type ball), rolling on z = 0 under gravity; v0 satisfies the rows.
System offsetBall() {
  System s;
  s.name = "offset ball";
  const double R = 0.25;
  const Mat3 R0 = axisAngle(Vec3(1, 2, 3).normalized(), 0.4);
  s.model = test::ballModel(1.5, R0 * Vec3(0.02, 0.03, 0.04).asDiagonal() * R0.transpose(),
                            Vec3(0.03, -0.02, 0.04));
  s.constraints = {std::make_shared<RollingBall>("ball_contact", 0, R)};
  s.q0 = neutralConfiguration(s.model);
  s.q0[2] = R;
  // Body frame = world at q0: ω = (1, −2, 3), ṗ = ω × (R e_z) (no slip).
  const Vec3 w(1.0, -2.0, 3.0);
  s.v0 = VecX::Zero(6);
  s.v0.head<3>() = w;
  s.v0.tail<3>() = w.cross(Vec3(0, 0, R));
  return s;
}

// Emelyanova–Fufaev sleigh on an incline: a knife edge with the centre of mass beside
// the blade; it slides down, turns and swings across the slope.
System sleigh() {
  System s;
  s.name = "sleigh";
  s.model = test::sleighModel(2.0, 0.1, 0.3, 0.25, 0.1);
  s.constraints = {test::knifeEdge(2)};
  const double phi = 0.7, speed = 0.8;
  s.q0 = Eigen::Vector3d(0, 0, phi);
  s.v0 = Eigen::Vector3d(speed * std::cos(phi), speed * std::sin(phi), 1.5);
  return s;
}

std::unique_ptr<ConstrainedSolver> solverFor(int which, const System& s) {
  if (which == 0) return std::make_unique<KktSolver>(s.model, s.constraints);
  if (which == 1) return std::make_unique<AppellSolver>(s.model, s.constraints);
  return std::make_unique<AppellSolver>(s.model, s.constraints, SolverOptions{},
                                        AppellOptions{NullSpace::CoordinatePartition, 20.0});
}

TEST(SimulatorEnergy, PassiveNonholonomicSystemsConserveEnergy) {
  for (const System& s : {offsetBall(), sleigh()}) {
    for (int which = 0; which < 3; ++which) {
      Simulator sim(s.model, s.constraints, solverFor(which, s), IntegratorType::DormandPrince54,
                    tight());
      sim.setState(0, s.q0, s.v0);
      ASSERT_LT(sim.velocityResidual(), 1e-14);
      const double E0 = sim.energy();
      const double scale = std::max(std::abs(E0), sim.kineticEnergy());
      double drift = 0, vres = 0, gres = 0;
      for (int k = 1; k <= 100; ++k) {
        const StepStatus st = sim.advanceTo(0.1 * k, 1e-3);
        ASSERT_TRUE(st.ok) << s.name << ": " << st.message;
        drift = std::max(drift, std::abs(sim.energy() - E0) / scale);
        vres = std::max(vres, sim.velocityResidual());
        gres = std::max(gres, sim.gapResidual());
      }
      EXPECT_DOUBLE_EQ(sim.time(), 10.0);
      EXPECT_LT(drift, 1e-9) << s.name << " solver " << which;
      EXPECT_LT(vres, 1e-10) << s.name << " solver " << which;
      EXPECT_LT(gres, 1e-10) << s.name << " solver " << which;
      std::printf("%-12s solver %d: %ld steps, energy drift %.2e, max |Av+b| %.2e, max |g| %.2e, "
                  "partition changes %d\n",
                  s.name.c_str(), which, sim.counters().steps, drift, vres, gres,
                  sim.partitionChanges());
    }
  }
}

// The sleigh sweeps through φ = 0 (mod π) many times: the partition solver must
// re-choose its dependent velocity and still follow the KKT trajectory.
TEST(SimulatorEnergy, FormulationsFollowTheSameTrajectory) {
  for (const System& s : {offsetBall(), sleigh()}) {
    std::vector<std::unique_ptr<Simulator>> sims;
    for (int which = 0; which < 3; ++which) {
      sims.push_back(std::make_unique<Simulator>(s.model, s.constraints, solverFor(which, s),
                                                 IntegratorType::RK4));
      sims.back()->setState(0, s.q0, s.v0);
    }
    for (int k = 0; k < 2000; ++k) {
      for (auto& sim : sims) ASSERT_TRUE(sim->step(2e-3).ok);
    }
    for (int which = 1; which < 3; ++which) {
      EXPECT_LT((sims[which]->q() - sims[0]->q()).norm(), 1e-9) << s.name << " " << which;
      EXPECT_LT((sims[which]->v() - sims[0]->v()).norm(), 1e-9) << s.name << " " << which;
      EXPECT_LT((sims[which]->lambda() - sims[0]->lambda()).norm(),
                1e-8 * (1 + sims[0]->lambda().norm()));
    }
    if (s.name == "sleigh") {
      EXPECT_GT(sims[2]->partitionChanges(), 0);
    }
  }
}

// A homogeneous ball rolls straight at constant speed with constant spin.
TEST(SimulatorEnergy, HomogeneousBallRollsStraight) {
  const double R = 0.2, m = 1.3;
  const Model model = test::ballModel(m, Vec3::Constant(0.4 * m * R * R).asDiagonal(), Vec3::Zero());
  ConstraintList c{std::make_shared<RollingBall>("contact", 0, R)};
  VecX q = neutralConfiguration(model);
  q[2] = R;
  const Vec3 w(0.7, -1.1, 2.0);  // includes spin about the vertical
  VecX v(6);
  v << w, w.cross(Vec3(0, 0, R));
  Simulator sim(model, c, std::make_unique<KktSolver>(model, c), IntegratorType::DormandPrince54,
                tight());
  sim.setState(0, q, v);
  const Vec3 pdot0 = w.cross(Vec3(0, 0, R));
  ASSERT_TRUE(sim.advanceTo(3.0, 1e-3).ok);
  const Vec3 expected = Vec3(0, 0, R) + 3.0 * pdot0;
  EXPECT_LT((sim.q().head<3>() - expected).norm(), 1e-10);
  // World angular velocity unchanged; the contact holds the weight, nothing else.
  const Eigen::Quaterniond Q(sim.q()[6], sim.q()[3], sim.q()[4], sim.q()[5]);
  EXPECT_LT((Q * Vec3(sim.v().head<3>()) - w).norm(), 1e-10);
  EXPECT_NEAR(sim.lambda()[2], m * 9.81, 1e-9);
  EXPECT_NEAR(sim.lambda()[0], 0.0, 1e-9);
  EXPECT_NEAR(sim.lambda()[1], 0.0, 1e-9);
  EXPECT_LT((sim.contactFrame(0).point - Vec3(expected.x(), expected.y(), 0)).norm(), 1e-10);
  EXPECT_GT(sim.counters().steps, 0);
  EXPECT_GE(sim.counters().evaluations, 6 * sim.counters().steps);
}

// Fixed-step integrators land exactly on t_end; energy error shrinks at order 4 for RK4.
TEST(SimulatorEnergy, Rk4EnergyErrorShrinksAtFourthOrder) {
  const System s = offsetBall();
  double err[2];
  for (int i = 0; i < 2; ++i) {
    const double h = 0.01 / (1 << i);
    SimulatorOptions so;
    so.project_positions = so.project_velocities = false;
    Simulator sim(s.model, s.constraints, std::make_unique<KktSolver>(s.model, s.constraints),
                  IntegratorType::RK4, {}, so);
    sim.setState(0, s.q0, s.v0);
    const double E0 = sim.energy();
    ASSERT_TRUE(sim.advanceTo(2.0, h).ok);
    EXPECT_EQ(sim.time(), 2.0);
    err[i] = std::abs(sim.energy() - E0);
  }
  const double order = std::log2(err[0] / err[1]);
  EXPECT_GT(order, 3.5) << err[0] << " " << err[1];
  EXPECT_LT(order, 5.5) << err[0] << " " << err[1];
}

}  // namespace
}  // namespace appell
