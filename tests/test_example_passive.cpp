// Example scenes with one body (examples/*/): load each URDF, run it with the
// Simulator (tree solver, Dormand–Prince at a tight tolerance) and check its
// physics: energy where the scene is passive and time-independent, the
// constraint residuals, and the motion the scene is known for.
#include <appell/simulator.hpp>
#include <appell/urdf.hpp>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <numbers>
#include <string>

namespace appell {
namespace {

std::string examplePath(const std::string& rel) {
  return std::string(APPELL_SOURCE_DIR) + "/examples/" + rel;
}

Mat3 rootRotation(const VecX& q) {
  return Eigen::Quaterniond(q[6], q[3], q[4], q[5]).normalized().toRotationMatrix();
}

std::unique_ptr<Simulator> simulate(const Scene& s, Formulation f = Formulation::Tree,
                                    double rtol = 1e-10) {
  IntegratorOptions io;
  io.rtol = rtol;
  io.atol = rtol * 1e-2;
  io.h_max = 0.05;
  auto sim = std::make_unique<Simulator>(s.model, s.constraints,
                                         makeSolver(f, s.model, s.constraints),
                                         IntegratorType::DormandPrince54, io);
  if (s.tau.size() == s.model.nv && s.tau.cwiseAbs().maxCoeff() > 0) {
    const VecX tau = s.tau;
    sim->setJointForces([tau](double, const VecX&, const VecX&, VecX& out) { out = tau; });
  }
  // After the joint forces: setState evaluates λ and v̇ for reports with them.
  sim->setState(0.0, s.q0, s.v0);
  return sim;
}

struct Stats {
  bool started = false;
  double E0 = 0;              ///< energy when the first advance() began
  double max_energy_dev = 0;  ///< max |E − E0|
  double max_residual = 0;    ///< max ‖A v + b‖∞
  double max_gap = 0;         ///< max |g|
  long steps = 0;
};

/// Steps to t_end (adaptive steps, the last one shortened to land on t_end),
/// calling each(sim) after every accepted step.
template <class Each>
void advance(Simulator& sim, double t_end, Stats& st, Each&& each) {
  if (!st.started) {
    st.started = true;
    st.E0 = sim.energy();
  }
  double h = 0.01;
  while (sim.time() < t_end - 1e-14) {
    const StepStatus status = sim.step(std::min(h, t_end - sim.time()));
    ASSERT_TRUE(status.ok) << "at t = " << sim.time() << ": " << status.message;
    h = status.h_next;
    ++st.steps;
    st.max_energy_dev = std::max(st.max_energy_dev, std::abs(sim.energy() - st.E0));
    st.max_residual = std::max(st.max_residual, sim.velocityResidual());
    st.max_gap = std::max(st.max_gap, sim.gapResidual());
    each(sim);
  }
}
void advance(Simulator& sim, double t_end, Stats& st) {
  advance(sim, t_end, st, [](const Simulator&) {});
}

int normalRow(const Scene& s, int contact) {
  int offset = 0;
  for (int c = 0; c < contact; ++c) offset += s.constraints[c]->rows();
  for (int r = 0; r < s.constraints[contact]->rows(); ++r)
    if (s.constraints[contact]->rowKind(r) == RowKind::Normal) return offset + r;
  return -1;
}

// World acceleration of the root body's origin from v̇ = (ω̇, v̇) body frame:
// a = R (v̇_lin + ω × v_lin).
Vec3 rootOriginAcceleration(const VecX& q, const VecX& v, const VecX& vdot) {
  return rootRotation(q) * (vdot.segment<3>(3) + v.head<3>().cross(v.segment<3>(3)));
}

// ---------------------------------------------------------------------------
// Rolling disk (the default example; the file is shared with the README).

TEST(ExampleRollingDisk, EnergyConservedAndNormalLoadBalancesWeight) {
  const Scene s = loadScene(examplePath("rolling_disk/rolling_disk.urdf"));
  auto sim = simulate(s);
  const double m = s.model.inertias[0].mass, g = 9.81;
  const double E0 = sim->energy();
  const int n = normalRow(s, 0);
  ASSERT_GE(n, 0);
  double max_newton = 0, min_load = 1e300, max_load = 0;
  Stats st;
  // The disk's centre is its centre of mass; on flat ground the tangent rows
  // are horizontal, so the normal load alone balances m (g + a_z).
  advance(*sim, 2.0, st, [&](const Simulator& si) {
    const double fn = si.lambda()[n];
    const Vec3 a = rootOriginAcceleration(si.q(), si.v(), si.dynamics().vdot);
    max_newton = std::max(max_newton, std::abs(fn - m * (g + a.z())));
    min_load = std::min(min_load, fn);
    max_load = std::max(max_load, fn);
  });
  EXPECT_LT(st.max_energy_dev / std::max(std::abs(E0), 1e-12), 1e-8);
  EXPECT_LT(st.max_residual, 1e-10);
  EXPECT_LT(st.max_gap, 1e-10);
  EXPECT_LT(max_newton, 1e-8 * m * g);
  EXPECT_GT(min_load, 0.97 * m * g);
  EXPECT_LT(max_load, 1.03 * m * g);
  // It did fall into a turn: the lean changed and the heading turned.
  const Vec3 axle0 = rootRotation(s.q0).col(2), axle = rootRotation(sim->q()).col(2);
  EXPECT_GT(std::abs(axle.z() - axle0.z()), 0.05);
}

// ---------------------------------------------------------------------------
// Ball on a turntable: the centre circles at 2Ω/7 whatever the initial velocity.

TEST(ExampleBallTurntable, CentreCirclesAtTwoSeventhsOfTheTableRate) {
  const Scene s = loadScene(examplePath("ball_turntable/ball_turntable.urdf"));
  ASSERT_EQ(s.supports.size(), 1u);
  const double Omega = 2.0;  // the file's turntable rate
  const double w = 2 * Omega / 7, T = 2 * std::numbers::pi / w;
  auto sim = simulate(s);
  auto centreVelocity = [](const Simulator& si) { return Vec3(rootRotation(si.q()) * si.v().segment<3>(3)); };
  auto spinZ = [](const Simulator& si) { return (rootRotation(si.q()) * si.v().head<3>()).z(); };
  const Vec3 p0 = s.q0.head<3>(), v0 = centreVelocity(*sim);
  const double speed0 = v0.head<2>().norm(), spin0 = spinZ(*sim);
  ASSERT_GT(speed0, 0.1);
  double max_speed_dev = 0, max_spin_dev = 0, max_height_dev = 0;
  Stats st;
  auto each = [&](const Simulator& si) {
    max_speed_dev = std::max(max_speed_dev, std::abs(centreVelocity(si).head<2>().norm() - speed0));
    max_spin_dev = std::max(max_spin_dev, std::abs(spinZ(si) - spin0));
    max_height_dev = std::max(max_height_dev, std::abs(si.q()[2] - 0.1));
  };
  // A quarter period: the velocity has turned by exactly π/2, counter-clockwise.
  advance(*sim, T / 4, st, each);
  const Vec3 vq = centreVelocity(*sim);
  EXPECT_NEAR(vq.x(), -v0.y(), 1e-7);
  EXPECT_NEAR(vq.y(), v0.x(), 1e-7);
  // A full period 7π/Ω: back where it started, with the same velocity.
  advance(*sim, T, st, each);
  EXPECT_LT((sim->q().head<3>() - p0).norm(), 1e-7) << sim->q().head<3>().transpose();
  EXPECT_LT((centreVelocity(*sim) - v0).norm(), 1e-7);
  EXPECT_LT(max_speed_dev, 1e-8);
  EXPECT_LT(max_spin_dev, 1e-8);
  EXPECT_LT(max_height_dev, 1e-10);
  EXPECT_LT(st.max_residual, 1e-10);
  EXPECT_LT(st.max_gap, 1e-10);
}

TEST(ExampleBallTurntable, RateIndependentOfInitialVelocity) {
  // Same scene, a different (consistent) initial velocity: project a guess.
  Scene s = loadScene(examplePath("ball_turntable/ball_turntable.urdf"));
  s.v0 << -4, 6, -1, 0.2, -0.5, 0;  // sliding guess; the projection makes it roll
  const InitialStateReport rep = checkInitialState(s, true);
  ASSERT_TRUE(rep.projected);
  const double T = 2 * std::numbers::pi / (2 * 2.0 / 7);
  auto sim = simulate(s);
  const Vec3 v0 = rootRotation(sim->q()) * sim->v().segment<3>(3);
  Stats st;
  advance(*sim, T / 2, st);
  const Vec3 vh = rootRotation(sim->q()) * sim->v().segment<3>(3);
  EXPECT_LT((vh.head<2>() + v0.head<2>()).norm(), 1e-7);  // turned by π
  advance(*sim, T, st);
  EXPECT_LT((sim->q().head<3>() - s.q0.head<3>()).norm(), 1e-7);
  EXPECT_LT(st.max_residual, 1e-10);
}

// ---------------------------------------------------------------------------
// Chaplygin sleigh on an incline: it turns to slide straight down the slope.

TEST(ExampleSleigh, TurnsDownTheSlopeEnergyConserved) {
  const Scene s = loadScene(examplePath("sleigh/sleigh.urdf"));
  const double alpha = 0.3;
  const Vec3 down(0, std::cos(alpha), -std::sin(alpha));
  auto sim = simulate(s);
  const double E0 = sim->energy();
  auto misalignment = [&](const Simulator& si) {
    return std::acos(std::clamp(rootRotation(si.q()).col(0).dot(down), -1.0, 1.0));
  };
  EXPECT_NEAR(misalignment(*sim), std::numbers::pi / 2, 1e-12);  // starts across the slope
  Stats st;
  advance(*sim, 3.0, st);
  const double at3 = misalignment(*sim);
  advance(*sim, 6.0, st);
  const double at6 = misalignment(*sim);
  EXPECT_LT(at6, 0.05);
  EXPECT_LT(at6, at3);
  // Sliding down, CoM first: the blade point moves along +blade, downhill.
  const Vec3 vel = rootRotation(sim->q()) * sim->v().segment<3>(3);
  EXPECT_GT(vel.dot(down), 10.0);
  EXPECT_LT(st.max_energy_dev / std::max(std::abs(E0), 1e-12), 1e-8);
  EXPECT_LT(st.max_residual, 1e-10);
  EXPECT_LT(st.max_gap, 1e-10);
}

// ---------------------------------------------------------------------------
// Heavy hemisphere in a spherical bowl.

TEST(ExampleHemisphereBowl, RocksAndRollsEnergyConserved) {
  const Scene s = loadScene(examplePath("hemisphere_bowl/hemisphere_bowl.urdf"));
  const Vec3 C(0, 0, 1);
  const double R1 = 1.0, R = 0.3;
  auto sim = simulate(s);
  const double E0 = sim->energy();
  double max_centre_dev = 0, max_cap_angle = 0, max_travel = 0;
  Stats st;
  advance(*sim, 4.0, st, [&](const Simulator& si) {
    const Vec3 O = si.q().head<3>();
    max_centre_dev = std::max(max_centre_dev, std::abs((O - C).norm() - (R1 - R)));
    // The contact point must stay on the curved face: within 90° of the pole.
    const Vec3 pole = -rootRotation(si.q()).col(2);
    const Vec3 P = si.contactFrame(0).point;
    max_cap_angle = std::max(max_cap_angle, std::acos(std::clamp((P - O).normalized().dot(pole), -1.0, 1.0)));
    max_travel = std::max(max_travel, (O - s.q0.head<3>()).norm());
  });
  EXPECT_LT(max_centre_dev, 1e-10);   // the sphere's centre stays at R₁ − R from C
  EXPECT_LT(max_cap_angle, std::numbers::pi / 2);
  EXPECT_GT(max_travel, 0.1);          // it does move
  EXPECT_LT(st.max_energy_dev / std::max(std::abs(E0), 1e-12), 1e-8);
  EXPECT_LT(st.max_residual, 1e-10);
  EXPECT_LT(st.max_gap, 1e-10);
}

// ---------------------------------------------------------------------------
// Ellipsoid on a plane.

TEST(ExampleEllipsoid, CentreHeightFollowsSupportFunctionEnergyConserved) {
  const Scene s = loadScene(examplePath("ellipsoid/ellipsoid.urdf"));
  const Vec3 D2(0.25 * 0.25, 0.15 * 0.15, 0.1 * 0.1);
  auto sim = simulate(s);
  const double E0 = sim->energy();
  double max_height_dev = 0, max_slip = 0, hmin = 1, hmax = 0;
  Stats st;
  advance(*sim, 3.0, st, [&](const Simulator& si) {
    const Mat3 Rw = rootRotation(si.q());
    const Vec3 u = Rw.transpose() * Vec3(0, 0, -1);
    const double h = std::sqrt(u.dot(D2.asDiagonal() * u));
    max_height_dev = std::max(max_height_dev, std::abs(si.q()[2] - h));
    hmin = std::min(hmin, h);
    hmax = std::max(hmax, h);
    // The material point at the contact does not move: v_c + ω × (P − c) = 0.
    const Vec3 p_body = D2.asDiagonal() * u / h;
    const Vec3 slip = si.v().segment<3>(3) + si.v().head<3>().cross(p_body);
    max_slip = std::max(max_slip, slip.norm());
  });
  EXPECT_LT(max_height_dev, 1e-10);
  EXPECT_LT(max_slip, 1e-9);
  EXPECT_GT(hmax - hmin, 0.01);  // it wobbles
  EXPECT_LT(st.max_energy_dev / std::max(std::abs(E0), 1e-12), 1e-8);
  EXPECT_LT(st.max_residual, 1e-10);
  EXPECT_LT(st.max_gap, 1e-10);
}

// ---------------------------------------------------------------------------
// Every example scene: the tree solver agrees with the dense multiplier
// (KKT) reference at the initial state (v̇, Aᵀλ and the minimum-norm λ), and
// over a short run; the dense Appell/Maggi solver agrees at the initial state.

class ExampleFormulations : public ::testing::TestWithParam<const char*> {};

TEST_P(ExampleFormulations, TreeMatchesMultipliers) {
  const Scene s = loadScene(examplePath(GetParam()));
  auto tree = simulate(s, Formulation::Tree), kkt = simulate(s, Formulation::Multipliers);
  const ConstrainedResult &a = tree->dynamics(), &b = kkt->dynamics();
  ASSERT_TRUE(a.ok) << a.error;
  ASSERT_TRUE(b.ok) << b.error;
  const double vs = std::max(1.0, b.vdot.cwiseAbs().maxCoeff());
  const double fs = std::max(1.0, b.reaction.cwiseAbs().maxCoeff());
  EXPECT_LT((a.vdot - b.vdot).cwiseAbs().maxCoeff(), 1e-9 * vs);
  EXPECT_LT((a.reaction - b.reaction).cwiseAbs().maxCoeff(), 1e-9 * fs);
  EXPECT_LT((a.lambda - b.lambda).cwiseAbs().maxCoeff(), 1e-8 * fs)
      << "tree λ " << a.lambda.transpose() << "\nkkt  λ " << b.lambda.transpose();
  EXPECT_EQ(a.redundant, b.redundant);
  // The dense Appell/Maggi (null-space) formulation gives the same v̇ and Aᵀλ.
  auto maggi = simulate(s, Formulation::Appell);
  const ConstrainedResult& c = maggi->dynamics();
  ASSERT_TRUE(c.ok) << c.error;
  EXPECT_LT((c.vdot - b.vdot).cwiseAbs().maxCoeff(), 1e-9 * vs);
  EXPECT_LT((c.reaction - b.reaction).cwiseAbs().maxCoeff(), 1e-9 * fs);
  Stats sa, sb;
  advance(*tree, 0.5, sa);
  advance(*kkt, 0.5, sb);
  EXPECT_LT((tree->q() - kkt->q()).cwiseAbs().maxCoeff(), 1e-7);
  EXPECT_LT((tree->v() - kkt->v()).cwiseAbs().maxCoeff(), 1e-6 * std::max(1.0, kkt->v().cwiseAbs().maxCoeff()));
}

INSTANTIATE_TEST_SUITE_P(AllExamples, ExampleFormulations,
                         ::testing::Values("rolling_disk/rolling_disk.urdf",
                                           "ball_turntable/ball_turntable.urdf",
                                           "sleigh/sleigh.urdf",
                                           "hemisphere_bowl/hemisphere_bowl.urdf",
                                           "ellipsoid/ellipsoid.urdf",
                                           "diff_drive/diff_drive.urdf",
                                           "diff_drive/diff_drive_turn.urdf",
                                           "diff_drive/diff_drive_servo.urdf",
                                           "car/car.urdf",
                                           "ntrailer/ntrailer3.urdf"),
                         [](const ::testing::TestParamInfo<const char*>& p) {
                           std::string n = p.param;
                           n = n.substr(n.find('/') + 1);
                           n = n.substr(0, n.find('.'));
                           return n;
                         });

}  // namespace
}  // namespace appell
