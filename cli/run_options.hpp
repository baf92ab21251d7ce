// The options of a run from the command line — the scene's <simulation>
// settings overridden by --duration, --dt, --tol, --integrator,
// --formulation, --contacts, --every, --max-energy-error, --max-residual,
// --settle-time and --no-projection: shared by `appell run` and
// `appell sweep`, so a sweep's case is the run the same options give.
#pragma once

#include "args.hpp"

#include <appell/run.hpp>

namespace appell::cli {

/// The valued options runOptionsFromArgs reads.
inline const std::set<std::string> kRunOptionNames = {"duration", "dt", "tol", "integrator", "formulation",
                                                      "contacts", "every", "max-energy-error", "max-residual",
                                                      "settle-time"};

/// RunOptions of `scene` with the command line's overrides; UsageError for
/// a bad value, naming the option.
RunOptions runOptionsFromArgs(const Scene& scene, const Args& args);

}  // namespace appell::cli
