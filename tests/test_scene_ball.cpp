// Balls: the homogeneous ball on a turntable (a moving support, b ≠ 0) and
// the Chaplygin ball (conserved angular momentum about the contact point).
#include <gtest/gtest.h>

#include <appell/simulator.hpp>

#include "ball.hpp"
#include "chaplygin_ball.hpp"

using namespace appell;
using namespace appell::scenes;

namespace {

IntegratorOptions tight() {
  IntegratorOptions o;
  o.rtol = 1e-12;
  o.atol = 1e-12;
  o.h_max = 0.01;
  return o;
}

Vec3 centreVelocity(const VecX& q, const VecX& v) { return floatingRotation(q, 0) * Vec3(v.tail<3>()); }

}  // namespace

// a_G = (2/7) Ω e_z × v_G (ball.hpp): v_G(t) = Rot_z(kt) v_G(0), k = 2Ω/7, and
// the centre x(t) = x(0) − (1/k) e_z × (v_G(t) − v_G(0)) runs round a circle.
TEST(BallOnTurntable, CentreCirclesAtTwoSeventhsOfTheTableRate) {
  BallParams p;
  p.centre = Vec3(0.3, -0.1, 0);
  p.omega = Vec3(2.0, 1.0, -0.7);
  const double Omega = 2.0;
  const BuiltScene s = ballOnTurntable(Omega, p);
  ASSERT_EQ(s.name, "ball_on_turntable");
  const double k = 2 * Omega / 7;
  const Vec3 x0 = s.q0.head<3>(), v0 = centreVelocity(s.q0, s.v0);
  ASSERT_GT(v0.norm(), 0.1);
  for (Formulation f : {Formulation::Multipliers, Formulation::Appell, Formulation::Tree}) {
    Simulator sim(s.model, s.constraints, makeSolver(f, s.model, s.constraints),
                  IntegratorType::DormandPrince54, tight());
    sim.setState(0, s.q0, s.v0);
    for (int i = 1; i <= 8; ++i) {
      const double t = 0.6 * i;
      const StepStatus st = sim.advanceTo(t, 1e-3);
      ASSERT_TRUE(st.ok) << st.message;
      const Vec3 vt = axisAngle(Vec3::UnitZ(), k * t) * v0;
      const Vec3 xt = x0 - Vec3::UnitZ().cross(vt - v0) / k;
      EXPECT_LT((centreVelocity(sim.q(), sim.v()) - vt).norm(), 1e-9) << toString(f) << " t = " << t;
      EXPECT_LT((sim.q().head<3>() - xt).norm(), 1e-9) << toString(f) << " t = " << t;
      EXPECT_LT(sim.velocityResidual(), 1e-10);
    }
  }
}

// K_P = I_G ω + m r² (ω − (ω·n) n) is conserved (Chaplygin 1903), and so is the energy.
TEST(ChaplyginBall, MomentumAboutTheContactPointAndEnergyAreConserved) {
  ChaplyginBallParams p;
  const BuiltScene s = chaplyginBall(p);
  Simulator sim(s.model, s.constraints, makeSolver(Formulation::Multipliers, s.model, s.constraints),
                IntegratorType::DormandPrince54, tight());
  sim.setState(0, s.q0, s.v0);
  auto K = [&](const VecX& q, const VecX& v) {
    const Mat3 R = floatingRotation(q, 0);
    const Vec3 w = R * Vec3(v.head<3>());
    const Mat3 IG = R * Mat3(p.principal.asDiagonal()) * R.transpose();
    const Vec3 n = Vec3::UnitZ();
    return Vec3(IG * w + p.mass * p.radius * p.radius * (w - w.dot(n) * n));
  };
  const Vec3 K0 = K(s.q0, s.v0);
  const double E0 = sim.energy();
  double worstK = 0, worstE = 0;
  for (int i = 1; i <= 20; ++i) {
    ASSERT_TRUE(sim.advanceTo(0.5 * i, 1e-3).ok);
    worstK = std::max(worstK, (K(sim.q(), sim.v()) - K0).norm());
    worstE = std::max(worstE, std::abs(sim.energy() - E0));
  }
  EXPECT_LT(worstK, 1e-9 * K0.norm());
  EXPECT_LT(worstE, 1e-9 * std::abs(E0));
  // A negative control: with the centre of mass displaced, K_P is no longer conserved.
  ChaplyginBallParams off = p;
  off.com_offset = Vec3(0.02, 0, 0.01);
  const BuiltScene so = chaplyginBall(off);
  Simulator simo(so.model, so.constraints, makeSolver(Formulation::Multipliers, so.model, so.constraints),
                 IntegratorType::DormandPrince54, tight());
  simo.setState(0, so.q0, so.v0);
  const Vec3 Ko = K(so.q0, so.v0);
  ASSERT_TRUE(simo.advanceTo(2.0, 1e-3).ok);
  EXPECT_GT((K(simo.q(), simo.v()) - Ko).norm(), 1e-4 * Ko.norm());
}
