// One case of a run or a linearization (case_runs.hpp), shared by the
// single-case bindings and the sweep's batches.
#include "case_runs.hpp"

#include <appell/constrained_dynamics.hpp>
#include <appell/joint_types.hpp>
#include <appell/urdf.hpp>

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <cmath>

namespace appell::python {

OverrideList readOverrides(py::handle overrides) {
  OverrideList out;
  if (overrides.is_none()) return out;
  py::object items = py::isinstance<py::dict>(overrides) ? overrides.attr("items")()
                                                         : py::reinterpret_borrow<py::object>(overrides);
  for (py::handle item : items) {
    auto pair = item.cast<py::tuple>();
    if (pair.size() != 2) throw py::value_error("an override is a (name, value) pair");
    const std::string name = pair[0].cast<std::string>();
    if (py::isinstance<py::str>(pair[1]))
      throw py::value_error(name + ": give a number or a sequence of numbers, not a string");
    out.emplace_back(name, py::hasattr(pair[1], "__len__") ? pair[1].cast<std::vector<double>>()
                                                           : std::vector<double>{pair[1].cast<double>()});
  }
  return out;
}

Scene overriddenScene(const Scene& base, const OverrideList& overrides, OverrideReport& report) {
  Scene scene = base;
  for (const auto& [name, values] : overrides) applyOverride(scene, name, values, report);
  completeVelocities(scene, report);
  return scene;
}

RunOptions caseRunOptions(const Scene& scene, const RunKnobs& k) {
  SimulationSettings settings = scene.settings;
  if (k.duration) settings.duration = *k.duration;
  if (k.dt) settings.dt = *k.dt;
  if (k.tol) settings.tol = *k.tol;
  if (k.integrator) settings.integrator = *k.integrator;
  if (k.formulation) settings.formulation = *k.formulation;
  RunOptions o = runOptions(settings);
  o.max_energy_error = k.max_energy_error;
  o.max_residual = k.max_residual;
  if (!(k.settle_time >= 0) || !std::isfinite(k.settle_time))
    throw std::invalid_argument("settle_time must be a finite number ≥ 0, not " + std::to_string(k.settle_time));
  o.settle_time = k.settle_time;
  o.project_positions = o.project_velocities = k.project;
  o.output_every = 1 << 30;  // only the first and last states are sampled
  return o;
}

RunResult runWithEvents(const Scene& scene, const RunOptions& o) {
  RunResult r;
  double t_prev = 0;
  VecX q_prev = scene.q0, v_prev = scene.v0;  // sized once: assignments reuse them
  auto note_events = [&](const Simulator& sim, double t_before, const VecX& q_before, const VecX& v_before) {
    for (std::size_t k = 0; k < sim.events().size(); ++k) {
      r.t_before.push_back(t_before);
      r.q_before.push_back(q_before);
      r.v_before.push_back(v_before);
      r.q_after.push_back(sim.q());
      r.v_after.push_back(sim.v());
    }
    t_prev = sim.time();
    q_prev = sim.q();
    v_prev = sim.v();
  };
  auto on_step = [&](const Simulator& sim) { note_events(sim, t_prev, q_prev, v_prev); };
  bool first = true;
  auto on_sample = [&](const Simulator& sim) {
    if (first) {  // t = 0: events of the initial state (a contact opening at once)
      note_events(sim, 0, scene.q0, scene.v0);
      first = false;
    }
    r.q = sim.q();
    r.v = sim.v();
    r.energy = sim.energy();
    r.kinetic = sim.kineticEnergy();
  };
  r.summary = runScene(scene, o, on_sample, on_step);
  r.nq = scene.model.nq;
  r.nv = scene.model.nv;
  return r;
}

RunResult runCase(const Scene& base, const OverrideList& overrides, const RunKnobs& knobs, bool check,
                  std::vector<std::string>* lines) {
  OverrideReport report;
  Scene scene = overriddenScene(base, overrides, report);
  if (lines) *lines = describe(scene, report);
  const RunOptions o = caseRunOptions(scene, knobs);
  // project_initial: the run starts from the projected state.
  if (check) checkInitialState(scene, knobs.project_initial, LoadOptions().initial_state_tolerance);
  return runWithEvents(scene, o);
}

LinearizationResult linearizeScene(const Scene& s, const VecX& q, const VecX& v, const LinearizeKnobs& k) {
  LinearizationOptions o;
  o.tau = k.tau ? *k.tau : sceneTau(s);
  o.time = k.time;
  o.cyclic = k.cyclic;
  o.fd_step = k.fd_step;
  o.rank_tolerance = k.rank_tolerance;
  const Formulation f = formulationFromString(k.formulation.value_or(s.settings.formulation));
  auto solver = makeSolver(f, s.model, s.constraints);
  return linearize(s.model, s.constraints, *solver, q, v, o);
}

std::vector<int> cyclicIndices(const Scene& s, const py::iterable& cyclic) {
  std::vector<int> out;
  for (py::handle c : cyclic) {
    if (py::isinstance<py::str>(c)) {
      const std::string n = c.cast<std::string>();
      int k;
      try {
        k = localCoordinateIndex(s.model, n);
      } catch (const std::invalid_argument& e) {
        throw py::key_error(e.what());
      }
      if (k < 0) throw py::key_error("no coordinate named '" + n + "'");
      out.push_back(k);
    } else {
      out.push_back(c.cast<int>());
    }
  }
  return out;
}

}  // namespace appell::python
