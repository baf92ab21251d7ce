// One case of a run or a linearization, as the single-case calls
// (`_appell.run`, `apply_overrides` + `linearize`) and the batch calls of a
// sweep (sweep_bindings.cpp) both compute it — one code path, so a sweep's
// numbers equal the cases run one by one bit for bit. Everything here but
// readOverrides and cyclicIndices runs without the GIL: it touches no
// Python object.
#pragma once

#include "bindings.hpp"

#include <appell/linearization.hpp>
#include <appell/overrides.hpp>
#include <appell/run.hpp>

#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace appell::python {

/// Overrides as (name, values), in the order given.
using OverrideList = std::vector<std::pair<std::string, std::vector<double>>>;

/// The Python overrides (a dict or a sequence of (name, number or sequence)
/// pairs; None: none), read with the GIL held. ValueError for a string value
/// or a pair that is not one.
OverrideList readOverrides(py::handle overrides);

/// A copy of `base` with the overrides applied in order and the velocities
/// completed (overrides.hpp), what was done added to `report`.
Scene overriddenScene(const Scene& base, const OverrideList& overrides, OverrideReport& report);

/// The keywords of `run` beside the scene and its overrides.
struct RunKnobs {
  std::optional<double> duration, dt, tol;
  std::optional<std::string> integrator, formulation;
  double max_energy_error = 5e-2, max_residual = 1e-6, settle_time = 0;
  bool project = true, project_initial = false;
};

/// The run options of a (overridden) scene: its settings with the knobs'
/// replacements; only the first and last states sampled.
RunOptions caseRunOptions(const Scene& scene, const RunKnobs& knobs);

/// A run's summary, its final state and its events with the states around them.
struct RunResult {
  RunSummary summary;
  VecX q, v;
  double energy = 0, kinetic = 0;
  /// Per event: the last state the run passed before it (the start of the
  /// step the event ended, at t_before) and the state at the event, after
  /// its impulse (the end of that step).
  std::vector<double> t_before;
  std::vector<VecX> q_before, v_before, q_after, v_after;
  int nq = 0, nv = 0;
  std::vector<std::string> overrides;
};

/// runScene, keeping the final state and the states around each event.
RunResult runWithEvents(const Scene& scene, const RunOptions& options);

/// One whole case of `run`: the overridden scene, its initial state checked
/// when `check` (the loader checked a scene's own state), the run.
RunResult runCase(const Scene& base, const OverrideList& overrides, const RunKnobs& knobs, bool check,
                  std::vector<std::string>* lines = nullptr);

/// The keywords of `linearize` beside the scene and its reference state;
/// `cyclic` already resolved to velocity indices (cyclicIndices).
struct LinearizeKnobs {
  std::optional<std::string> formulation;
  std::optional<VecX> tau;
  double time = 0, fd_step = 1e-5, rank_tolerance = 1e-9;
  std::vector<int> cyclic;
};

/// The linearization of `scene` at (q, v): tau and formulation from the
/// knobs or else the scene's own.
LinearizationResult linearizeScene(const Scene& scene, const VecX& q, const VecX& v, const LinearizeKnobs& knobs);

/// Cyclic coordinates by velocity index, or by name — a velocity's
/// (Scene.velocity_names) or a position's (localCoordinateIndex,
/// joint_types.hpp); KeyError for an unknown name. The GIL held.
std::vector<int> cyclicIndices(const Scene& scene, const py::iterable& cyclic);

}  // namespace appell::python
