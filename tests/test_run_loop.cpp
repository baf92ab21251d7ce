// The one stepping loop (appell/run_loop.hpp):
//  - Simulator::advanceTo is the loop without an observer: the same states,
//    bit for bit, as runLoop stepped by hand, for fixed and adaptive steps
//    (the adaptive suggestion carried from one call to the next), and it
//    lands exactly on t_end;
//  - the observer's hooks come in the documented order, rows at the start,
//    every N-th step and the last state; a stop request or an observer's
//    veto ends the loop there, a failed step leaves a row of the last good
//    state;
//  - the two end rules differ only in how the last remainder is taken.
#include <appell/run_loop.hpp>
#include <appell/simulator.hpp>

#include <gtest/gtest.h>

#include <limits>
#include <string>
#include <vector>

namespace appell {
namespace {

// A double pendulum under gravity: no constraints, chaotic enough that any
// change of step size shows in the state.
Model doublePendulum() {
  ModelBuilder b;
  const Inertia link{1.0, Vec3(0, 0, -0.5), Vec3(0.02, 0.02, 0.001).asDiagonal()};
  b.addBody("upper", -1, SE3::Identity(), JointType::Revolute, Vec3::UnitX(), link, "shoulder");
  SE3 X;
  X.p = Vec3(0, 0, -1);
  b.addBody("lower", 0, X, JointType::Revolute, Vec3::UnitX(), link, "elbow");
  return b.build();
}

std::unique_ptr<Simulator> pendulum(const Model& model, IntegratorType integrator) {
  IntegratorOptions io;
  io.rtol = 1e-9;
  io.atol = 1e-11;
  auto sim = std::make_unique<Simulator>(model, ConstraintList{},
                                         makeSolver(Formulation::Tree, model, {}), integrator, io);
  VecX q(2), v(2);
  q << 1.2, -0.4;
  v << 0.3, 2.0;
  sim->setState(0, q, v);
  return sim;
}

// Writes each hook's name and the step count at which it came.
struct Trace final : StepObserver {
  std::vector<std::string> calls;
  int stop_after = -1, veto_at = -1;
  int accepted_steps = 0;
  std::vector<double> row_times;
  bool check(Simulator&, const StepStatus&) override {
    calls.push_back("check");
    return accepted_steps + 1 != veto_at;
  }
  void events(const Simulator&) override { calls.push_back("events"); }
  bool accepted(Simulator&, const StepStatus&) override {
    calls.push_back("accepted");
    ++accepted_steps;
    return true;
  }
  void row(const Simulator& sim) override {
    calls.push_back("row");
    row_times.push_back(sim.time());
  }
  bool stopRequested() override {
    calls.push_back("stop?");
    return accepted_steps == stop_after;
  }
  void progress(const Simulator&) override { calls.push_back("progress"); }
};

TEST(RunLoop, AdvanceToIsTheLoopWithoutObserverFixedStep) {
  const Model model = doublePendulum();
  auto a = pendulum(model, IntegratorType::RK4), b = pendulum(model, IntegratorType::RK4);
  ASSERT_TRUE(a->advanceTo(0.2505, 1e-3).ok);
  LoopSpec spec;
  spec.t_end = 0.2505;
  spec.h = 1e-3;
  const LoopResult r = runLoop(*b, spec);
  EXPECT_EQ(r.end, LoopEnd::Reached);
  EXPECT_EQ(r.steps, 251);  // 250 steps of h and the remainder of 0.5 ms
  EXPECT_TRUE(r.landed);
  EXPECT_EQ(a->time(), 0.2505);  // advanceTo lands exactly
  EXPECT_EQ(a->q(), b->q());
  EXPECT_EQ(a->v(), b->v());
  EXPECT_EQ(a->counters().steps, b->counters().steps);
}

TEST(RunLoop, AdvanceToCarriesTheAdaptiveSuggestionAcrossCalls) {
  const Model model = doublePendulum();
  auto a = pendulum(model, IntegratorType::DormandPrince54);
  auto b = pendulum(model, IntegratorType::DormandPrince54);
  ASSERT_TRUE(a->advanceTo(0.5, 1e-3).ok);
  ASSERT_TRUE(a->advanceTo(1.0, 1e-3).ok);
  LoopSpec spec;
  spec.t_end = 0.5;
  spec.h = 1e-3;
  const LoopResult first = runLoop(*b, spec);
  spec.t_end = 1.0;
  spec.h_suggest = first.h_suggest;  // the step the integrator suggested, not h again
  EXPECT_NE(first.h_suggest, spec.h);
  const LoopResult second = runLoop(*b, spec);
  EXPECT_EQ(a->q(), b->q());
  EXPECT_EQ(a->v(), b->v());
  EXPECT_EQ(a->counters().steps, first.steps + second.steps);
}

TEST(RunLoop, HooksComeInOrderWithRowsEveryNthStepAndTheLastState) {
  const Model model = doublePendulum();
  auto sim = pendulum(model, IntegratorType::RK4);
  Trace trace;
  LoopSpec spec;
  spec.t_end = 5e-3;
  spec.h = 1e-3;
  spec.row_every = 2;
  const LoopResult r = runLoop(*sim, spec, &trace);
  EXPECT_EQ(r.end, LoopEnd::Reached);
  EXPECT_EQ(r.steps, 5);
  // No contacts: no events hook. Rows: the start, steps 2 and 4, the end (5).
  const std::vector<std::string> step = {"check", "accepted", "stop?", "progress"};
  const std::vector<std::string> step_row = {"check", "accepted", "row", "stop?", "progress"};
  std::vector<std::string> expected = {"row"};
  for (int k = 1; k <= 5; ++k)
    expected.insert(expected.end(), (k % 2 == 0 ? step_row : step).begin(),
                    (k % 2 == 0 ? step_row : step).end());
  expected.push_back("row");
  EXPECT_EQ(trace.calls, expected);
  ASSERT_EQ(trace.row_times.size(), 4u);
  EXPECT_EQ(trace.row_times.front(), 0.0);
  EXPECT_NEAR(trace.row_times[1], 2e-3, 1e-15);
  EXPECT_NEAR(trace.row_times[2], 4e-3, 1e-15);
  EXPECT_NEAR(trace.row_times[3], 5e-3, 1e-15);
}

TEST(RunLoop, AStopRequestEndsTheLoopAfterThatStepsProgress) {
  const Model model = doublePendulum();
  auto sim = pendulum(model, IntegratorType::RK4);
  Trace trace;
  trace.stop_after = 3;
  LoopSpec spec;
  spec.t_end = 1.0;
  spec.h = 1e-3;
  spec.row_every = 2;
  const LoopResult r = runLoop(*sim, spec, &trace);
  EXPECT_EQ(r.end, LoopEnd::Stopped);
  EXPECT_EQ(r.steps, 3);
  EXPECT_NEAR(sim->time(), 3e-3, 1e-15);
  ASSERT_GE(trace.calls.size(), 3u);
  // The stopped step still reports progress, and its state (not a row: 3 is
  // odd) is the last row.
  EXPECT_EQ(trace.calls[trace.calls.size() - 2], "progress");
  EXPECT_EQ(trace.calls.back(), "row");
  EXPECT_NEAR(trace.row_times.back(), 3e-3, 1e-15);
}

TEST(RunLoop, AnObserversVetoEndsTheLoopBeforeThatStepsBookkeeping) {
  const Model model = doublePendulum();
  auto sim = pendulum(model, IntegratorType::RK4);
  Trace trace;
  trace.veto_at = 4;
  LoopSpec spec;
  spec.t_end = 1.0;
  spec.h = 1e-3;
  const LoopResult r = runLoop(*sim, spec, &trace);
  EXPECT_EQ(r.end, LoopEnd::Observer);
  EXPECT_EQ(r.steps, 4);
  EXPECT_EQ(trace.accepted_steps, 3);
  EXPECT_EQ(trace.calls.back(), "check");  // step 3 was a row: no row after the veto
  EXPECT_EQ(trace.row_times.size(), 4u);  // the start and steps 1–3
}

TEST(RunLoop, AFailedStepEndsWithARowOfTheLastGoodState) {
  const Model model = doublePendulum();
  auto sim = pendulum(model, IntegratorType::RK4);
  // A joint force that turns non-finite after 2.5 ms fails the third step.
  sim->setJointForces([](double t, const VecX&, const VecX&, VecX& tau) {
    if (t > 2.5e-3) tau.setConstant(std::numeric_limits<double>::quiet_NaN());
  });
  Trace trace;
  LoopSpec spec;
  spec.t_end = 1.0;
  spec.h = 1e-3;
  spec.row_every = 5;
  const LoopResult r = runLoop(*sim, spec, &trace);
  EXPECT_EQ(r.end, LoopEnd::Failed);
  EXPECT_FALSE(r.status.ok);
  EXPECT_FALSE(r.status.message.empty());
  EXPECT_EQ(r.steps, 2);
  ASSERT_EQ(trace.row_times.size(), 2u);  // the start and the last good state
  EXPECT_NEAR(trace.row_times.back(), 2e-3, 1e-15);
  EXPECT_NEAR(sim->time(), 2e-3, 1e-15);
}

TEST(RunLoop, TheEndRulesDifferOnlyInTheLastRemainder) {
  const Model model = doublePendulum();
  // t_end 0.1 + 5e-14: with steps of 0.05 the remainder after the first step
  // exceeds h by 5e-14. Absorb (ε = 1e-12) takes it in the second step;
  // Clip takes h and stops, within its relative bound 1e-12·t_end of t_end.
  auto absorb = pendulum(model, IntegratorType::RK4), clip = pendulum(model, IntegratorType::RK4);
  LoopSpec spec;
  spec.t_end = 0.1 + 5e-14;
  spec.h = 0.05;
  const LoopResult a = runLoop(*absorb, spec);
  spec.finish = LoopSpec::Finish::Clip;
  const LoopResult c = runLoop(*clip, spec);
  EXPECT_EQ(a.steps, 2);
  EXPECT_EQ(c.steps, 2);
  EXPECT_TRUE(a.landed);
  EXPECT_FALSE(c.landed);
  EXPECT_NEAR(absorb->time(), spec.t_end, 1e-16);
  EXPECT_NEAR(clip->time(), 0.1, 1e-16);
  EXPECT_NE(absorb->q(), clip->q());
}

TEST(RunLoop, BadSpecificationsThrowNamingTheValue) {
  const Model model = doublePendulum();
  auto sim = pendulum(model, IntegratorType::RK4);
  LoopSpec spec;
  spec.t_end = 1;
  spec.h = 0;
  EXPECT_THROW(runLoop(*sim, spec), std::invalid_argument);
  spec.h = 1e-3;
  spec.row_every = 0;
  try {
    runLoop(*sim, spec);
    FAIL() << "row_every 0 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "runLoop: row_every must be at least 1, got 0");
  }
  try {
    sim->advanceTo(std::numeric_limits<double>::infinity(), 1e-3);
    FAIL() << "an infinite t_end accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "Simulator::advanceTo: h must be positive and t_end finite");
  }
  EXPECT_EQ(sim->time(), 0.0);
}

}  // namespace
}  // namespace appell
