// State and parameter overrides on the command line (appell run and
// linearize: --set NAME=VALUE, --sweep NAME=START:STOP:COUNT).
//   gravity=gx,gy,gz           the scene's gravity
//   <coordinate>=x             a position or velocity by its CSV name
//                              (root_joint.z, root_joint.vx, a joint's name
//                              for its position, <joint>.rate… see below)
//   <joint>.position=x,…       a joint's nq positions
//   <joint>.velocity=x,…       a joint's nv velocities
//   speed=V                    the forward speed of a straight-running
//                              vehicle: the floating base's velocity along its
//                              link x axis
// A one-degree-of-freedom joint's own name is its position. Velocities set
// are kept and every other velocity becomes the least (minimum norm) the
// closed constraints allow — a disk's spin rate set, its rolling follows.
// A name that takes one number can be swept.
#pragma once

#include "args.hpp"

#include <appell/scene.hpp>

#include <string>
#include <vector>

namespace appell::cli {

/// Applies NAME=VALUE to the scene, adding the velocities it sets to `kept`;
/// throws UsageError naming what is wrong.
void applyOverride(Scene& scene, const std::string& name, const std::string& value, std::vector<int>& kept);

/// The velocities not in `kept` become the minimum-norm solution of the closed
/// constraints A v + b = 0; throws UsageError when the kept ones admit none.
void completeVelocities(Scene& scene, const std::vector<int>& kept);

/// Every --set of `args`, in order, then the velocities completed; returns
/// the velocities set.
std::vector<int> applyOverrides(Scene& scene, const Args& args);

struct Sweep {
  std::string name;
  std::vector<double> values;  ///< count values from start to stop, evenly spaced
};

/// NAME=START:STOP:COUNT (COUNT ≥ 2, or 1 for START alone).
Sweep parseSweep(const std::string& spec);

}  // namespace appell::cli
