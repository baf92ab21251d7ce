// Named overrides of a scene's initial state and parameters — the `--set
// NAME=VALUE` of the command line and the parameters of a Python sweep:
//   gravity=gx,gy,gz           the model's gravity
//   speed=V                    a floating base's velocity along its link x
//                              axis (a straight-running vehicle's speed)
//   <joint>.position=x,…       a joint's nq positions
//   <joint>.velocity=x,…       a joint's nv velocities
//   <joint>.effort=f,…         a joint's constant generalized forces (nv:
//                              N·m or N; Scene::tau, added to any actuator)
//   <contact>.mu=μ             a contact's Coulomb coefficient (static and
//                              kinetic alike; ∞ none)
//   <coordinate>=x             a position or velocity by its CSV name
//                              (root_joint.z, root_joint.vx, a 1-dof joint's
//                              own name for its position, <joint>.rate)
// Velocities set are kept; after the overrides every other velocity changes
// as little as the closed constraints allow (least squares from the scene's
// own values: min ‖v_f − v0_f‖ subject to A v + b = 0, a complete orthogonal
// decomposition), so a rolling disk's lean rate survives `speed=` while its
// spin follows the new speed; the report names every velocity so changed.
#pragma once

#include <appell/scene.hpp>

#include <string>
#include <vector>

namespace appell {

/// What applyOverride and completeVelocities did, for the summary.
struct OverrideReport {
  struct Applied {
    std::string name;             ///< as given (speed, rim.mu, hinge.velocity …)
    std::vector<double> values;
    std::string target;           ///< what it set: "root_joint.vx", "gravity", "rim: μ" …
  };
  /// A velocity the constraints moved to keep A v + b = 0.
  struct Completed {
    int index = 0;                ///< into v
    double before = 0, after = 0;
  };
  std::vector<Applied> applied;
  std::vector<int> kept;          ///< velocity indices set by an override
  std::vector<Completed> completed;
};

/// Applies NAME=values to the scene, adding what it did to `report`. Throws
/// std::invalid_argument "NAME: reason" (unknown name, wrong count, a
/// non-finite number, a μ on a contact that cannot take it).
void applyOverride(Scene& scene, const std::string& name, const std::vector<double>& values,
                   OverrideReport& report);

/// The velocities not in report.kept change as little as the closed
/// constraints allow (top of this file); those that moved are added to
/// report.completed. Throws std::invalid_argument when the kept velocities
/// admit no solution (residual named).
void completeVelocities(Scene& scene, OverrideReport& report);

/// One line per applied override and per completed velocity, for a summary:
/// "speed = 1.5 → root_joint.vx", "completed: root_joint.wy 10 → 15".
std::vector<std::string> describe(const Scene& scene, const OverrideReport& report);

}  // namespace appell
