// Rolling disk: the exact vertical-disk solution and steady circular rolling.
#include <gtest/gtest.h>

#include <appell/simulator.hpp>

#include "rolling_disk.hpp"

#include <cstdio>
#include <numbers>

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

/// World contact force of a rolling contact from its three multipliers.
Vec3 contactForce(const VecX& lambda, const ContactFrame& f) {
  return lambda[0] * f.t1 + lambda[1] * f.t2 + lambda[2] * f.normal;
}

}  // namespace

// The vertical rolling disk (Bloch, Nonholonomic Mechanics and Control, 2003): x = ρ(sin φ − sin φ₀) + x₀, y = −ρ(cos φ − cos φ₀) + y₀,
// ρ = ω_θ R/ω_φ, φ = ω_φ t + φ₀; the contact force is m ω_φ R ω_θ (−sin φ, cos φ)
// (the centripetal force of the centre's uniform circular motion).
TEST(VerticalRollingDisk, CentreFollowsTheExactCircleAndMultipliersMatch) {
  VerticalDiskParams p;
  p.centre = Vec3(0.4, -0.2, 0);
  const BuiltScene s = verticalRollingDisk(p);
  for (Formulation f : {Formulation::Multipliers, Formulation::Appell, Formulation::Tree}) {
    Simulator sim(s.model, s.constraints, makeSolver(f, s.model, s.constraints),
                  IntegratorType::DormandPrince54, tight());
    sim.setState(0, s.q0, s.v0);
    const double rho = p.spin_rate * p.radius / p.heading_rate;
    for (int k = 1; k <= 10; ++k) {
      const double t = 0.5 * k;
      const StepStatus st = sim.advanceTo(t, 1e-3);
      ASSERT_TRUE(st.ok) << st.message;
      const double phi = p.heading + p.heading_rate * t;
      const double x = rho * (std::sin(phi) - std::sin(p.heading)) + p.centre.x();
      const double y = -rho * (std::cos(phi) - std::cos(p.heading)) + p.centre.y();
      EXPECT_NEAR(sim.q()[0], x, 1e-9) << toString(f) << " t = " << t;
      EXPECT_NEAR(sim.q()[1], y, 1e-9) << toString(f) << " t = " << t;
      EXPECT_NEAR(sim.q()[2], phi, 1e-9);
      EXPECT_NEAR(sim.v()[3], p.spin_rate, 1e-9);
      const Vec3 F = contactForce(sim.lambda(), sim.contactFrame(0));
      const double scale = p.mass * p.heading_rate * p.radius * p.spin_rate;
      EXPECT_NEAR(F.x(), -scale * std::sin(phi), 1e-9 * scale) << toString(f);
      EXPECT_NEAR(F.y(), scale * std::cos(phi), 1e-9 * scale) << toString(f);
      // The sliders carry the weight: the contact's normal row is redundant (λ = 0, min norm).
      EXPECT_EQ(sim.redundantRows(), 1);
      EXPECT_NEAR(F.z(), 0.0, 1e-9 * scale);
    }
  }
}

namespace {

struct LeanState {
  double lean, axle, up, lean_rate;  // θ, ω·a, ω·u, ω·t
};

LeanState leanState(const VecX& q, const VecX& v) {
  const Mat3 R = floatingRotation(q, 0);
  const Vec3 a = R.col(2);
  const Vec3 w = R * Vec3(v.head<3>());
  const Vec3 u = (Vec3::UnitZ() - a.z() * a).normalized();
  const Vec3 t = u.cross(a);
  return {std::asin(a.z()), w.dot(a), w.dot(u), w.dot(t)};
}

double maxLeanDeviation(const BuiltScene& s, double T, LeanState* worst_out = nullptr) {
  Simulator sim(s.model, s.constraints, makeSolver(Formulation::Multipliers, s.model, s.constraints),
                IntegratorType::DormandPrince54, tight());
  sim.setState(0, s.q0, s.v0);
  const LeanState s0 = leanState(s.q0, s.v0);
  LeanState worst{0, 0, 0, 0};
  for (int k = 1; k <= 40; ++k) {
    const StepStatus st = sim.advanceTo(T * k / 40, 1e-3);
    if (!st.ok) ADD_FAILURE() << st.message;
    const LeanState c = leanState(sim.q(), sim.v());
    worst.lean = std::max(worst.lean, std::abs(c.lean - s0.lean));
    worst.axle = std::max(worst.axle, std::abs(c.axle - s0.axle));
    worst.up = std::max(worst.up, std::abs(c.up - s0.up));
    worst.lean_rate = std::max(worst.lean_rate, std::abs(c.lean_rate - s0.lean_rate));
    if (sim.velocityResidual() > 1e-10 || sim.gapResidual() > 1e-10)
      ADD_FAILURE() << "constraint residual " << sim.velocityResidual() << " " << sim.gapResidual();
  }
  if (worst_out) *worst_out = worst;
  return worst.lean;
}

}  // namespace

// Steady circular rolling of a tilted disk: with ω_a from steadyDiskAxleRate
// (angular-momentum balance about the centre, see rolling_disk.hpp), the lean,
// the axle rate and the turn rate stay constant and the lean rate stays 0.
TEST(TiltedRollingDisk, SteadyCircularRollingStaysSteady) {
  for (double lean : {0.3, -0.5, 0.9}) {
    RollingDiskParams p;
    p.lean = lean;
    p.precession = 2.5;
    const Vec3 I = thinDiskInertia(p.mass, p.radius);
    p.axle_rate = steadyDiskAxleRate(p.mass, p.radius, I.x(), I.z(), 9.81, lean, p.precession);
    const BuiltScene s = rollingDisk(p);
    const LeanState s0 = leanState(s.q0, s.v0);
    ASSERT_NEAR(s0.lean, lean, 1e-12);
    ASSERT_NEAR(s0.axle, p.axle_rate, 1e-12);
    ASSERT_NEAR(s0.up, p.precession * std::cos(lean), 1e-12);
    LeanState dev;
    maxLeanDeviation(s, 4.0, &dev);
    EXPECT_LT(dev.lean, 1e-8) << "lean " << lean;
    EXPECT_LT(dev.axle, 1e-8 * std::abs(p.axle_rate));
    EXPECT_LT(dev.up, 1e-8 * p.precession);
    EXPECT_LT(dev.lean_rate, 1e-8 * p.precession);
  }
}

// Dormand–Prince through the simulator: the drift projection after each step
// moves the state by less than the error tolerance, so the FSAL stage is
// kept (Integrator::stateMoved) and every attempt costs 6 evaluations, not 7
// — with the steady motion still exact to 1e-8 (the test above).
TEST(TiltedRollingDisk, DormandPrinceKeepsItsFsalStageAcrossTheProjection) {
  RollingDiskParams p;
  p.lean = 0.3;
  p.precession = 2.5;
  const Vec3 I = thinDiskInertia(p.mass, p.radius);
  p.axle_rate = steadyDiskAxleRate(p.mass, p.radius, I.x(), I.z(), 9.81, p.lean, p.precession);
  const BuiltScene s = rollingDisk(p);
  Simulator sim(s.model, s.constraints, makeSolver(Formulation::Tree, s.model, s.constraints),
                IntegratorType::DormandPrince54, tight());
  sim.setState(0, s.q0, s.v0);
  ASSERT_TRUE(sim.advanceTo(4.0, 1e-3).ok);
  const auto& c = sim.counters();
  const long attempts = c.steps + c.rejected;
  std::printf("%ld steps, %ld rejected, %ld evaluations\n", static_cast<long>(c.steps),
              static_cast<long>(c.rejected), static_cast<long>(c.evaluations));
  EXPECT_GT(c.steps, 100);
  EXPECT_LE(c.evaluations, 6 * attempts + 1);  // + the very first step's k₁
  EXPECT_LT(sim.velocityResidual(), 1e-12);
}

// The same test must fail when the condition is not met: a 5 % wrong axle
// rate makes the disk nutate visibly.
TEST(TiltedRollingDisk, OffTheSteadyConditionTheLeanOscillates) {
  RollingDiskParams p;
  p.lean = 0.3;
  p.precession = 2.5;
  const Vec3 I = thinDiskInertia(p.mass, p.radius);
  p.axle_rate = 1.05 * steadyDiskAxleRate(p.mass, p.radius, I.x(), I.z(), 9.81, p.lean, p.precession);
  EXPECT_GT(maxLeanDeviation(rollingDisk(p), 4.0), 1e-3);
}
