// Failures inside a step are reported, never hidden: non-finite joint forces,
// constraints that become contradictory, bad arguments. The last good state is
// kept and stepping can resume once the cause is gone. Also: projecting an
// initial state that violates the constraints.
#include <appell/appell_maggi.hpp>
#include <appell/kkt.hpp>
#include <appell/simulator.hpp>

#include "test_solver_rows.hpp"

#include <gtest/gtest.h>

#include <limits>

namespace appell {
namespace {

using test::RollingBall;

// Two copies of one no-slip row; while *broken, the second asks for a
// different acceleration (κ = 1) or, at the velocity level, a different
// velocity (b = 1, κ unchanged): no motion satisfies both.
enum class Level { Acceleration, Velocity };
class ContradictoryWhen final : public Constraint {
 public:
  explicit ContradictoryWhen(std::shared_ptr<bool> broken, Level level = Level::Acceleration)
      : broken_(std::move(broken)), level_(level) {}
  const std::string& name() const override { return name_; }
  int rows() const override { return 2; }
  int bodyA() const override { return 0; }
  RowKind rowKind(int) const override { return RowKind::Custom; }
  std::string rowLabel(int k) const override { return k == 0 ? "first" : "second"; }
  bool holonomic(int) const override { return false; }
  void evaluate(const Model&, const Data& data, double, const VecX&, const VecX&,
                RowBlock& out) const override {
    const Vec6 w = data.oMi[0].actForce(test::pointRow(Vec3(0, 0, 0.3), Vec3::UnitY()));
    out.Wa.row(0) = w.transpose();
    out.Wa.row(1) = w.transpose();
    const bool twisted = *broken_ && level_ == Level::Acceleration;
    const bool offset = *broken_ && level_ == Level::Velocity;
    out.kappa[0] = 0;
    out.kappa[1] = twisted ? 1.0 : 0.0;
    out.b.setZero();
    out.b[1] = offset ? 1.0 : 0.0;
    out.gap.setZero();
  }

 private:
  std::shared_ptr<bool> broken_;
  Level level_;
  std::string name_ = "twin_rows";
};

struct Ball {
  Model model = test::ballModel(1.0, Vec3(0.02, 0.03, 0.04).asDiagonal(), Vec3(0.01, 0, 0.02));
  double R = 0.3;
  VecX q0, v0;
  Ball() {
    q0 = neutralConfiguration(model);
    q0[2] = R;
    const Vec3 w(0.3, 1.0, -0.5);
    v0 = VecX(6);
    v0 << w, w.cross(Vec3(0, 0, R));
  }
};

void expectSameState(const Simulator& sim, double t, const VecX& q, const VecX& v) {
  EXPECT_EQ(sim.time(), t);
  EXPECT_EQ(sim.q(), q);
  EXPECT_EQ(sim.v(), v);
}

TEST(SimulatorFailure, NonFiniteJointForcesKeepTheLastGoodState) {
  const Ball b;
  ConstraintList c{std::make_shared<RollingBall>("contact", 0, b.R)};
  for (IntegratorType it : {IntegratorType::RK4, IntegratorType::DormandPrince54}) {
    Simulator sim(b.model, c, std::make_unique<KktSolver>(b.model, c), it);
    auto poison = std::make_shared<bool>(false);
    sim.setJointForces([poison](double, const VecX&, const VecX&, VecX& tau) {
      if (*poison) tau[0] = std::numeric_limits<double>::quiet_NaN();
    });
    sim.setState(0, b.q0, b.v0);
    for (int k = 0; k < 10; ++k) ASSERT_TRUE(sim.step(1e-3).ok);
    const double t = sim.time();
    const VecX q = sim.q(), v = sim.v();
    *poison = true;
    const StepStatus st = sim.step(1e-3);
    EXPECT_FALSE(st.ok);
    EXPECT_NE(st.message.find("joint-force callback"), std::string::npos) << st.message;
    expectSameState(sim, t, q, v);
    EXPECT_EQ(sim.counters().failed, 1);
    EXPECT_EQ(sim.counters().steps, 10);
    // The cause removed, stepping resumes from the kept state.
    *poison = false;
    EXPECT_TRUE(sim.step(1e-3).ok);
    EXPECT_GT(sim.time(), t);
  }
}

TEST(SimulatorFailure, ContradictoryConstraintsAreReportedByName) {
  const Ball b;
  auto broken = std::make_shared<bool>(false);
  ConstraintList c{std::make_shared<RollingBall>("contact", 0, b.R),
                   std::make_shared<ContradictoryWhen>(broken)};
  for (int which = 0; which < 2; ++which) {
    std::unique_ptr<ConstrainedSolver> solver;
    if (which == 0) solver = std::make_unique<KktSolver>(b.model, c);
    else solver = std::make_unique<AppellSolver>(b.model, c);
    Simulator sim(b.model, c, std::move(solver), IntegratorType::RK4);
    *broken = false;
    sim.setState(0, b.q0, b.v0);
    ASSERT_TRUE(sim.projectState().ok);
    for (int k = 0; k < 5; ++k) ASSERT_TRUE(sim.step(1e-3).ok);
    EXPECT_EQ(sim.redundantRows(), 1);  // the twin row is redundant while consistent
    const double t = sim.time();
    const VecX q = sim.q(), v = sim.v();
    *broken = true;
    const StepStatus st = sim.step(1e-3);
    EXPECT_FALSE(st.ok);
    EXPECT_NE(st.message.find("inconsistent"), std::string::npos) << st.message;
    EXPECT_NE(st.message.find("twin_rows"), std::string::npos) << st.message;
    expectSameState(sim, t, q, v);
  }
}

// A failed velocity projection says why, whatever the formulation: the reason
// comes through the solver interface (lastError), so the tree solver's own
// account — which rows, found where — reaches StepStatus::message.
TEST(SimulatorFailure, ProjectionFailureReportsTheSolversReason) {
  const Ball b;
  auto broken = std::make_shared<bool>(false);
  ConstraintList c{std::make_shared<RollingBall>("contact", 0, b.R),
                   std::make_shared<ContradictoryWhen>(broken, Level::Velocity)};
  for (Formulation f : {Formulation::Tree, Formulation::Multipliers, Formulation::Appell}) {
    SCOPED_TRACE(toString(f));
    Simulator sim(b.model, c, makeSolver(f, b.model, c), IntegratorType::RK4);
    *broken = false;
    sim.setState(0, b.q0, b.v0);
    ASSERT_TRUE(sim.projectState().ok);
    for (int k = 0; k < 5; ++k) ASSERT_TRUE(sim.step(1e-3).ok);
    const double t = sim.time();
    const VecX q = sim.q(), v = sim.v();
    // b does not enter the accelerations: the step integrates, then the
    // velocity projection meets rows no velocity satisfies.
    *broken = true;
    StepStatus st = sim.step(1e-3);
    EXPECT_FALSE(st.ok);
    EXPECT_NE(st.message.find("velocity projection failed: inconsistent"), std::string::npos)
        << st.message;
    EXPECT_NE(st.message.find("twin_rows"), std::string::npos) << st.message;
    expectSameState(sim, t, q, v);
    // The same reason from the initial-state projection.
    st = sim.projectState();
    EXPECT_FALSE(st.ok);
    EXPECT_NE(st.message.find("velocity projection failed: inconsistent"), std::string::npos)
        << st.message;
    EXPECT_NE(st.message.find("twin_rows"), std::string::npos) << st.message;
    expectSameState(sim, t, q, v);
    if (f == Formulation::Tree) {  // the tree solver names where it found them
      EXPECT_NE(st.message.find("detected at body"), std::string::npos) << st.message;
    }
  }
}

TEST(SimulatorFailure, BadArgumentsThrowClearly) {
  const Ball b;
  ConstraintList c{std::make_shared<RollingBall>("contact", 0, b.R)};
  EXPECT_THROW(Simulator(b.model, c, nullptr, IntegratorType::RK4), std::invalid_argument);
  Simulator sim(b.model, c, std::make_unique<KktSolver>(b.model, c), IntegratorType::RK4);
  EXPECT_THROW(sim.setState(0, VecX::Zero(3), b.v0), std::invalid_argument);
  VecX bad = b.v0;
  bad[1] = std::numeric_limits<double>::infinity();
  EXPECT_THROW(sim.setState(0, b.q0, bad), std::invalid_argument);
  EXPECT_THROW(sim.step(0.0), std::invalid_argument);
  EXPECT_THROW(sim.step(-1e-3), std::invalid_argument);
  EXPECT_THROW(sim.contactFrame(1), std::out_of_range);
}

TEST(SimulatorFailure, InitialStateIsProjectedOntoTheConstraints) {
  const Ball b;
  ConstraintList c{std::make_shared<RollingBall>("contact", 0, b.R)};
  Simulator sim(b.model, c, std::make_unique<AppellSolver>(b.model, c), IntegratorType::RK4);
  VecX q = b.q0, v = b.v0;
  q[2] += 0.02;   // above the plane
  v[3] += 0.5;    // slipping
  v[5] -= 0.3;    // leaving the plane
  sim.setState(0, q, v);
  EXPECT_GT(sim.gapResidual(), 0.01);
  EXPECT_GT(sim.velocityResidual(), 0.1);
  const StepStatus st = sim.projectState();
  ASSERT_TRUE(st.ok) << st.message;
  EXPECT_LT(sim.gapResidual(), 1e-12);
  EXPECT_LT(sim.velocityResidual(), 1e-12);
  EXPECT_GE(sim.lastProjection().iterations, 1);
  EXPECT_NEAR(sim.q()[2], b.R, 1e-12);
  // The impulse that removed the slip and the lift: v⁺ = v − M⁻¹Aᵀμ.
  EXPECT_GT(sim.lastImpulse().norm(), 0.0);
}

// The message of the std::invalid_argument `make` throws ("" if none).
template <class Make>
std::string invalidArgument(Make make) {
  try {
    make();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

// Issue 41, reproducer 6: a NaN tolerance made dopri5's step() loop for ever
// (its error norm NaN, h shrinking to NaN, which `h < h_min` never catches)
// and dop853 accept every step unchecked; a negative one was accepted. Every
// option is now checked where the integrator is made, by name.
TEST(SimulatorFailure, IntegratorOptionsAreFinitePositiveAndOrdered) {
  const Ball b;
  ConstraintList c{std::make_shared<RollingBall>("contact", 0, b.R)};
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  auto messageFor = [&](IntegratorType type, auto&& change) {
    IntegratorOptions o;
    change(o);
    return invalidArgument([&] {
      Simulator(b.model, c, std::make_unique<AppellSolver>(b.model, c), type, o);
    });
  };
  for (IntegratorType type : {IntegratorType::DormandPrince54, IntegratorType::DormandPrince853}) {
    EXPECT_EQ(messageFor(type, [&](IntegratorOptions& o) { o.rtol = nan; }),
              "IntegratorOptions: rtol must be finite and > 0 (got nan)");
    EXPECT_EQ(messageFor(type, [](IntegratorOptions& o) { o.rtol = -1; }),
              "IntegratorOptions: rtol must be finite and > 0 (got -1)");
    EXPECT_EQ(messageFor(type, [&](IntegratorOptions& o) { o.atol = inf; }),
              "IntegratorOptions: atol must be finite and > 0 (got inf)");
    EXPECT_EQ(messageFor(type, [](IntegratorOptions& o) { o.h_min = 1, o.h_max = 0.1; }),
              "IntegratorOptions: h_min must not exceed h_max (got h_min = 1, h_max = 0.1)");
    EXPECT_EQ(messageFor(type, [&](IntegratorOptions& o) { o.h_max = nan; }),
              "IntegratorOptions: h_max must be finite and > 0 (got nan)");
    EXPECT_EQ(messageFor(type, [](IntegratorOptions& o) { o.safety = 1.5; }),
              "IntegratorOptions: safety must be in (0, 1] (got 1.5)");
  }
  // Fixed-step methods ignore the tolerances but the options are still one
  // set, checked the same way (a NaN there is a bug in the caller).
  EXPECT_NE(messageFor(IntegratorType::RK4, [&](IntegratorOptions& o) { o.rtol = nan; }), "");
  EXPECT_EQ(messageFor(IntegratorType::Leapfrog, [](IntegratorOptions& o) { o.implicit_max_iterations = 0; }),
            "IntegratorOptions: implicit_max_iterations must be at least 1 (got 0)");

  SimulatorOptions so;
  so.contacts.gap_tol = nan;
  EXPECT_EQ(invalidArgument([&] {
              Simulator(b.model, c, std::make_unique<AppellSolver>(b.model, c), IntegratorType::RK4, {}, so);
            }),
            "SimulatorOptions: contacts.gap_tol must be finite and >= 0 (got nan)");
  so = {};
  so.projection.max_iterations = 0;
  EXPECT_EQ(invalidArgument([&] {
              Simulator(b.model, c, std::make_unique<AppellSolver>(b.model, c), IntegratorType::RK4, {}, so);
            }),
            "SimulatorOptions: projection.max_iterations must be at least 1 (got 0)");
}

// The step controllers themselves never loop on a NaN step and never accept
// a step whose error estimate is NaN (a field that returns NaN rates once
// the tolerances scale them: here the integrator is driven directly).
TEST(SimulatorFailure, AdaptiveStepsRefuseANanStepInsteadOfLooping) {
  const Ball b;
  struct FreeFall final : AccelerationField {
    bool operator()(double, const VecX&, const VecX& v, VecX& vdot) override {
      vdot = VecX::Zero(v.size());
      vdot[5] = -9.81;
      return true;
    }
  } field;
  for (IntegratorType type : {IntegratorType::DormandPrince54, IntegratorType::DormandPrince853}) {
    const auto integrator = makeIntegrator(type, b.model);
    double t = 0;
    VecX q = b.q0, v = b.v0;
    const StepResult r = integrator->step(field, t, q, v, std::numeric_limits<double>::quiet_NaN());
    EXPECT_FALSE(r.ok);
    ASSERT_NE(r.failure, nullptr);
    EXPECT_STREQ(r.failure, "the step size is not positive and finite");
    EXPECT_EQ(t, 0.0);
    EXPECT_EQ(q, b.q0);
  }
}

// Issue 41, reproducer 15 (C++ side): a zero quaternion has no rotation
// (q/|q| is 0/0); setState refuses it by the joint's name.
TEST(SimulatorFailure, AZeroQuaternionIsRefusedByItsJoint) {
  const Ball b;
  ConstraintList c{std::make_shared<RollingBall>("contact", 0, b.R)};
  Simulator sim(b.model, c, std::make_unique<AppellSolver>(b.model, c), IntegratorType::RK4);
  VecX q = b.q0;
  q.segment<4>(3).setZero();
  const std::string m = invalidArgument([&] { sim.setState(0, q, b.v0); });
  EXPECT_NE(m.find("the quaternion of joint '"), std::string::npos) << m;
  EXPECT_NE(m.find("' is zero (it has no rotation)"), std::string::npos) << m;
  // Off the unit sphere but not zero: accepted (its rotation is that of q/|q|).
  q = b.q0;
  q.segment<4>(3) *= 3.0;
  EXPECT_NO_THROW(sim.setState(0, q, b.v0));
}

}  // namespace
}  // namespace appell
