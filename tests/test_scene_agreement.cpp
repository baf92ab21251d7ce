// Formulation agreement on every built-in scene: 1000 random admissible states
// per scene; the dense KKT solve is the reference, the Appell/Maggi solve
// (orthonormal null space and coordinate partition) and the O(n) tree solve
// must give the same v̇ and the same reaction Aᵀλ to 1e-10 relative.
#include <gtest/gtest.h>

#include <appell/appell_maggi.hpp>
#include <appell/kkt.hpp>
#include <appell/tree_solver.hpp>

#include "ball.hpp"
#include "chaplygin_ball.hpp"
#include "ellipsoid.hpp"
#include "hemisphere_bowl.hpp"
#include "rolling_disk.hpp"
#include "sleigh.hpp"

using namespace appell;
using namespace appell::scenes;

namespace {

struct Case {
  BuiltScene scene;
  double angle_spread, position_spread, speed;
  bool time_dependent = false;
};

std::vector<Case> cases() {
  std::vector<Case> c;
  RollingDiskParams disk;
  disk.lean = 0.4;
  disk.precession = 1.0;
  c.push_back({rollingDisk(disk), 0.6, 0.5, 3.0});
  c.push_back({verticalRollingDisk(), 3.0, 0.5, 3.0});
  c.push_back({rollingDiskChain(), 0.6, 0.5, 3.0});
  c.push_back({ball(), 3.0, 0.5, 3.0});
  c.push_back({ballOnTurntable(), 3.0, 0.5, 3.0, true});
  c.push_back({chaplyginBall(), 3.0, 0.5, 3.0});
  ChaplyginBallParams top;
  top.com_offset = Vec3(0.02, -0.01, 0.03);
  c.push_back({chaplyginBall(top), 3.0, 0.5, 3.0});
  c.push_back({sleigh(lateralSleighParams()), 0.3, 0.5, 2.0});
  c.push_back({sleigh(usualSleighParams()), 0.3, 0.5, 2.0});
  c.push_back({sleighReduced(lateralSleighParams()), 3.0, 0.5, 2.0});
  c.push_back({hemisphereInBowl(), 0.3, 0.05, 1.0});
  c.push_back({ellipsoidOnPlane(), 3.0, 0.5, 3.0});
  return c;
}

}  // namespace

TEST(SceneAgreement, KktAppellTreeAgreeOnRandomStates) {
  for (const Case& c : cases()) {
    const BuiltScene& s = c.scene;
    KktSolver kkt(s.model, s.constraints);
    AppellOptions part;
    part.null_space = NullSpace::CoordinatePartition;
    std::vector<std::unique_ptr<ConstrainedSolver>> others;
    others.push_back(std::make_unique<AppellSolver>(s.model, s.constraints));
    others.push_back(std::make_unique<AppellSolver>(s.model, s.constraints, SolverOptions{}, part));
    others.push_back(std::make_unique<TreeSolver>(s.model, s.constraints));
    Data data(s.model);
    ConstraintData cd(s.model, s.constraints);
    std::mt19937 rng(12345);
    std::uniform_real_distribution<double> ut(0.0, 3.0), ug(-2.0, 2.0);
    double worst_vdot = 0, worst_reaction = 0;
    int singular = 0;
    for (int k = 0; k < 1000; ++k) {
      const double t = c.time_dependent ? ut(rng) : 0.0;
      VecX q, v;
      randomState(s, rng, c.angle_spread, c.position_spread, c.speed, q, v, t);
      VecX tau(s.model.nv);
      for (int i = 0; i < tau.size(); ++i) tau[i] = ug(rng);
      evaluateConstraints(s.model, data, s.constraints, cd, t, q, v);
      if (cd.singular) {  // e.g. a cap contact past its rim: not a valid state
        ++singular;
        continue;
      }
      ConstrainedResult ref;
      kkt.solve(s.model, data, s.constraints, cd, q, v, tau, ref);
      ASSERT_TRUE(ref.ok) << s.name << ": " << ref.error;
      // Reference sanity: the accelerations satisfy the constraint rows.
      ASSERT_LT((cd.A * ref.vdot + cd.abias).norm(), 1e-9 * (1 + ref.vdot.norm()) * (1 + cd.abias.norm()))
          << s.name;
      for (auto& solver : others) {
        ConstrainedResult r;
        evaluateConstraints(s.model, data, s.constraints, cd, t, q, v);
        solver->solve(s.model, data, s.constraints, cd, q, v, tau, r);
        ASSERT_TRUE(r.ok) << s.name << " " << toString(solver->formulation()) << ": " << r.error;
        const double ev = (r.vdot - ref.vdot).norm() / (1 + ref.vdot.norm());
        const double er = (r.reaction - ref.reaction).norm() / (1 + ref.reaction.norm());
        worst_vdot = std::max(worst_vdot, ev);
        worst_reaction = std::max(worst_reaction, er);
        ASSERT_LT(ev, 1e-10) << s.name << " " << toString(solver->formulation()) << " state " << k;
        ASSERT_LT(er, 1e-10) << s.name << " " << toString(solver->formulation()) << " state " << k;
        ASSERT_EQ(r.redundant, ref.redundant) << s.name;
        // Appell/Maggi's own check: the reaction M v̇ + h − τ lies in range(Aᵀ)
        // to round-off (docs/solvers.md), far below its error threshold.
        if (const auto* appell = dynamic_cast<const AppellSolver*>(solver.get()))
          ASSERT_LT(appell->lastRangeResidual(), 1e-12) << s.name << " state " << k;
      }
    }
    EXPECT_LT(singular, 50) << s.name << ": too many random states were singular";
    RecordProperty(s.name + "_worst_vdot", std::to_string(worst_vdot));
    std::printf("%-28s worst rel. |Δv̇| %.2e  |ΔAᵀλ| %.2e  (%d singular states skipped)\n",
                s.name.c_str(), worst_vdot, worst_reaction, singular);
  }
}
