// State and parameter overrides on the command line (appell run, linearize
// and sweep: --set NAME=VALUE; the sweeps' values in sweep_engine.hpp): the text
// parsed into numbers here, the names applied by the run library
// (appell/overrides.hpp, which lists them), its errors made usage errors
// ("--set NAME: reason"). A name that takes one number can be swept.
#pragma once

#include "args.hpp"

#include <appell/overrides.hpp>
#include <appell/scene.hpp>

#include <string>
#include <vector>

namespace appell::cli {

/// Applies NAME=VALUE (comma-separated numbers) to the scene, adding what it
/// did to `report`; throws UsageError naming what is wrong.
void applyOverride(Scene& scene, const std::string& name, const std::string& value, OverrideReport& report);

/// appell::completeVelocities, its errors as UsageError.
void completeSetVelocities(Scene& scene, OverrideReport& report);

/// Every --set of `args`, in order, then the velocities completed.
OverrideReport applyOverrides(Scene& scene, const Args& args);

}  // namespace appell::cli
