// The table of a sweep (appell sweep; appell run --sweep): its setup — the
// scene as loaded, the fixed --set overrides, the varied axes and their
// cases, the analysis and its options — and the function that runs every
// case on the sweep engine (sweep_engine.hpp) and writes one row per case.
#pragma once

#include "args.hpp"
#include "sweep_engine.hpp"

#include <appell/constrained_dynamics.hpp>
#include <appell/run.hpp>
#include <appell/scene.hpp>

#include <cstdint>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace appell::cli {

struct SweepSetup {
  Scene base;                                              ///< as loaded, before any override
  std::vector<std::pair<std::string, std::string>> fixed;  ///< --set NAME=VALUE, in order
  std::vector<SweepAxis> axes;
  std::vector<SweepCase> cases;
  bool random = false;
  std::uint64_t seed = 0;
  bool linearize = false;
  RunOptions run;                ///< --analysis run
  std::vector<int> cyclic;       ///< --analysis linearize
  Formulation form = Formulation::Tree;
  bool project_initial = false;
  bool timing = true;            ///< the wall_seconds column
};

/// The --set NAME=VALUE options of `args`, in order (UsageError without '=').
std::vector<std::pair<std::string, std::string>> fixedOverrides(const Args& args);

/// A one-axis setup for run --sweep and linearize --sweep: the scene as
/// loaded, the --set options, the --sweep NAME=START:STOP:COUNT grid.
SweepSetup oneAxisSetup(Scene loaded, const Args& args);

/// The scene of case `c`: a copy of the base, the fixed overrides, then the
/// case's values, the velocities completed once, and (`check`) the initial
/// state checked — what `appell run --set … --set NAME=VALUE` computes.
Scene caseScene(const SweepSetup& s, const SweepCase& c, bool check);

/// Every --set and every varied name applied once to a copy of the scene
/// (the first case's values), so that a misspelt name or a wrong count fails
/// before anything runs: UsageError "OPTION NAME: reason".
void checkSweepNames(const SweepSetup& s, const std::string& option);

/// Runs every case on `jobs` threads and writes the table ("csv", "json" or,
/// for run --sweep, "text"); `args` carries linearize's own options. Returns
/// the exit status: 0 all ok, 3 some case failed or erred, 130 interrupted.
int runSweepTable(const SweepSetup& s, unsigned jobs, const std::string& format, const Args& args,
                  std::ostream& out);

}  // namespace appell::cli
