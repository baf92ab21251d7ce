// The time-stepping step's contact problem as data (appell/contact_problem.hpp):
// what Simulator::contactProblem records is the problem the step solved —
// its impulses balance the load, and ContactProblemSolver re-solves it to
// the same impulses bit for bit, also where the step skipped a finish that
// failed in an earlier step — and bad problems are refused by name.
#include <gtest/gtest.h>

#include <appell/contact_problem.hpp>
#include <appell/run.hpp>
#include <appell/simulator.hpp>
#include <appell/urdf.hpp>

#include "corner_box.hpp"
#include "scene.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

using namespace appell;
using namespace appell::scenes;

namespace {

constexpr double kG = 9.81, kMass = 2.0, kMu = 0.5, kPush = 3.0, kStep = 1e-3;
// The problem's velocities are solved to 1e-10 m/s (the default
// residual_tol); the box's heave after the step, (Σ Pₙ − m g h)/m, is then
// within that of zero, so Σ Pₙ within m · 1e-10 of m g h (twice, for the
// four corners' combination).
constexpr double kLoadTol = 2 * kMass * 1e-10;

// A box on its four lower corners (μ 0.5), pushed at its centre by a
// constant 3 N — below μ m g = 9.81 N, so it sticks —, stepped `steps` times.
struct PushedBox {
  BuiltScene s = cornerBox({.half = Vec3(0.2, 0.1, 0.05), .mass = kMass, .h = 0, .R = Mat3::Identity(),
                            .kind = ContactKind::Rolling, .mu = kMu});
  std::unique_ptr<Simulator> sim;
  explicit PushedBox(ContactScheme scheme, int steps) {
    SimulatorOptions o;
    o.scheme = scheme;
    o.timestepping.step = kStep;
    sim = std::make_unique<Simulator>(s.model, s.constraints,
                                      makeSolver(Formulation::Tree, s.model, s.constraints),
                                      IntegratorType::DormandPrince54, IntegratorOptions{}, o);
    sim->setJointForces([](double, const VecX& q, const VecX&, VecX& tau) {
      tau.tail<3>() = floatingRotation(q, 0).transpose() * Vec3(kPush, 0, 0);
    });
    EXPECT_TRUE(sim->setState(0, s.q0, s.v0)) << sim->lastStateError();
    for (int i = 0; i < steps; ++i) EXPECT_TRUE(sim->step(kStep).ok);
  }
};

}  // namespace

// The recorded problem is the step's: four cones, their normal impulses
// carrying the weight over the step (Σ Pₙ = m g h) and the impulses
// within the solver's residual; re-solved from its warm start by
// ContactProblemSolver, the same impulses to the last bit.
TEST(ContactProblem, RecordedStepResolvesToItsImpulses) {
  PushedBox box(ContactScheme::TimeStepping, 5);
  ContactProblemData d;
  ASSERT_TRUE(box.sim->contactProblem(d));
  EXPECT_NEAR(d.t, 4 * kStep, 1e-15);
  ASSERT_EQ(d.blocks.size(), 4u);
  double load = 0;
  for (const ContactProblemBlock& b : d.blocks) {
    EXPECT_EQ(b.friction_rows, 2);
    EXPECT_EQ(b.equality_rows, 0);
    EXPECT_EQ(b.mu, kMu);
    EXPECT_EQ(box.sim->constraints()[b.constraint]->name().rfind("box", 0), 0u)
        << box.sim->constraints()[b.constraint]->name();
    load += d.P[b.first];
  }
  EXPECT_NEAR(load, kMass * kG * kStep, kLoadTol);
  EXPECT_LT(box.sim->v().norm(), 1e-8) << "it sticks";
  EXPECT_TRUE(d.converged);

  ContactProblemSolver solver(d);
  VecX P, u;
  const SimulatorOptions defaults;
  const ContactProblemSolver::Result r =
      solver.solve(d.warm_start, defaults.timestepping.residual_tol, defaults.timestepping.max_sweeps, P, u);
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(r.sweeps, d.sweeps);
  EXPECT_EQ(r.residual, d.residual);
  for (int i = 0; i < d.rows(); ++i) EXPECT_EQ(P[i], d.P[i]) << "row " << i;
  EXPECT_EQ(solver.residual(P), d.residual);
  // u = W P + u_free, and every normal velocity meets its target.
  const VecX u_check = d.W * P + d.u_free;
  EXPECT_LT((u - u_check).lpNorm<Eigen::Infinity>(), 1e-14);
  for (const ContactProblemBlock& b : d.blocks) EXPECT_GT(u[b.first] - d.target[b.first], -1e-10);
}

// From zero instead of the warm start: another iterate, the same load
// (the split among four corners is indeterminate; the sum is not).
TEST(ContactProblem, ColdStartCarriesTheSameLoad) {
  PushedBox box(ContactScheme::TimeStepping, 5);
  ContactProblemData d;
  ASSERT_TRUE(box.sim->contactProblem(d));
  ContactProblemSolver solver(d);
  VecX P, u;
  const ContactProblemSolver::Result r = solver.solve(VecX::Zero(d.rows()), 1e-10, 2000, P, u);
  ASSERT_TRUE(r.converged);
  double load = 0;
  for (const ContactProblemBlock& b : d.blocks) load += P[b.first];
  EXPECT_NEAR(load, kMass * kG * kStep, kLoadTol);
  EXPECT_LE(solver.residual(P), 1e-10 * std::max(1.0, d.u_free.lpNorm<Eigen::Infinity>()));
}

// No problem to record after an event step; a problem whose blocks do not
// tile its rows is refused with the constraint named, one with a NaN or a
// start of the wrong size too.
TEST(ContactProblem, EventStepsRecordNothingAndBadLayoutsAreRefused) {
  PushedBox box(ContactScheme::Events, 1);
  ContactProblemData d;
  EXPECT_FALSE(box.sim->contactProblem(d));

  PushedBox stepped(ContactScheme::TimeStepping, 1);
  ASSERT_TRUE(stepped.sim->contactProblem(d));
  {
    ContactProblemData nan = d;
    nan.W(0, 0) = std::nan("");
    EXPECT_THROW(ContactProblemSolver{nan}, std::invalid_argument);
    ContactProblemSolver ok(d);
    VecX P, u;
    EXPECT_THROW(ok.solve(VecX::Zero(d.rows() + 1), 1e-10, 100, P, u), std::invalid_argument);
    EXPECT_THROW(ok.solve(VecX::Zero(d.rows()), 0.0, 100, P, u), std::invalid_argument);
    ContactProblemData skips = d;
    skips.skipped_finish_modes.assign(d.blocks.size() + 1, 1);
    EXPECT_THROW(ContactProblemSolver{skips}, std::invalid_argument) << "one mode per block";
    skips.skipped_finish_modes.assign(d.blocks.size(), 3);
    EXPECT_THROW(ContactProblemSolver{skips}, std::invalid_argument) << "modes 0, 1, 2";
  }
  d.blocks[1].first += 1;
  try {
    ContactProblemSolver bad(d);
    FAIL() << "a gap between blocks was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("block of constraint " + std::to_string(d.blocks[1].constraint)),
              std::string::npos)
        << e.what();
  }
}

// The CAD car time-stepped (examples/cad_car: one rear wheel 0.2 mm out of
// line, so sticking on four tyres is inconsistent and the active-set finish
// fails often): a step that skipped the finish from the modes of an earlier
// step's failed one records them, and ContactProblemSolver, given them,
// reproduces the step bit for bit. Without them it tries that finish too:
// the answer may differ (the problem's impulses are not unique) but meets
// the same tolerance and every normal target.
TEST(ContactProblem, SkippedFinishModesAreRecordedAndReproduced) {
  const Scene scene = loadScene(std::string(APPELL_SOURCE_DIR) + "/examples/cad_car/cad_car.urdf");
  RunOptions o = runOptions(scene.settings);
  o.contacts = ContactScheme::TimeStepping;
  std::unique_ptr<Simulator> sim = makeSimulator(scene, o);
  ContactProblemData d;
  int step = 0, skipped = 0;
  for (; step < 3000 && skipped < 20; ++step) {
    ASSERT_TRUE(sim->step(1e-3).ok) << "step " << step;
    ASSERT_TRUE(sim->contactProblem(d));
    if (d.skipped_finish_modes.empty()) continue;
    ++skipped;
    ASSERT_EQ(d.skipped_finish_modes.size(), d.blocks.size());
    const SimulatorOptions defaults;
    const double tol = defaults.timestepping.residual_tol;
    const int max_sweeps = defaults.timestepping.max_sweeps;
    VecX P, u;
    ContactProblemSolver solver(d);
    const ContactProblemSolver::Result r = solver.solve(d.warm_start, tol, max_sweeps, P, u);
    EXPECT_EQ(r.sweeps, d.sweeps) << "t = " << d.t;
    EXPECT_EQ(r.converged, d.converged);
    for (int i = 0; i < d.rows(); ++i) ASSERT_EQ(P[i], d.P[i]) << "t = " << d.t << ", row " << i;

    ContactProblemData tried = d;
    tried.skipped_finish_modes.clear();
    ContactProblemSolver again(tried);
    const ContactProblemSolver::Result r2 = again.solve(d.warm_start, tol, max_sweeps, P, u);
    if (!r2.converged) continue;  // (at the sweep limit both ways: nothing to compare)
    const double scale = std::max(1.0, d.u_free.lpNorm<Eigen::Infinity>());
    EXPECT_LE(again.residual(P), tol * scale) << "t = " << d.t;
    for (const ContactProblemBlock& b : d.blocks) {
      EXPECT_GE(P[b.first], 0.0);
      EXPECT_GT(u[b.first] - d.target[b.first], -tol * scale) << "t = " << d.t;
    }
  }
  EXPECT_GE(skipped, 20) << "the car's steps skip failed finishes (" << step << " steps)";
}
