// A whole run and named overrides, as `appell run --set …` does them:
//   apply_overrides(scene, overrides) → (a new Scene, the lines saying what
//     changed) — run/include/appell/overrides.hpp's names and rules;
//   run(scene, …) → RunResult: runScene (run.hpp) with the GIL released —
//     how it ended, the work terms of the energy balance
//       E(t) + impact losses + friction work − joint work − support work = E₀,
//     the residuals, the final state, and every contact event with the states
//     around it, as NumPy arrays.
// A sweep's batches (sweep_bindings.cpp) run the same cases by the same code
// (case_runs.cpp).
#include "case_runs.hpp"

#include <appell/contact_events.hpp>
#include <appell/overrides.hpp>
#include <appell/run.hpp>
#include <appell/urdf.hpp>

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <cmath>
#include <map>
#include <optional>

namespace appell::python {

using namespace pybind11::literals;

namespace {

MatX rows(const std::vector<VecX>& x, int n) {
  MatX out(x.size(), n);
  for (std::size_t k = 0; k < x.size(); ++k) out.row(k) = x[k].transpose();
  return out;
}

py::dict eventTable(const RunResult& r) {
  const auto& ev = r.summary.events;
  const std::size_t n = ev.size();
  VecX t(n), sb(n), sa(n), ni(n), ti(n);
  std::vector<std::string> names, kinds;
  std::vector<bool> outside;
  for (std::size_t k = 0; k < n; ++k) {
    t[k] = ev[k].t;
    sb[k] = ev[k].speed_before;
    sa[k] = ev[k].speed_after;
    ni[k] = ev[k].normal_impulse;
    ti[k] = ev[k].tangential_impulse;
    names.push_back(ev[k].contact);
    kinds.push_back(toString(ev[k].kind));
    outside.push_back(ev[k].outside_friction_cone);
  }
  py::dict d;
  d["t"] = t;
  d["contact"] = names;
  d["kind"] = kinds;
  d["speed_before"] = sb;
  d["speed_after"] = sa;
  d["normal_impulse"] = ni;
  d["tangential_impulse"] = ti;
  d["outside_friction_cone"] = outside;
  d["t_before"] = Eigen::Map<const VecX>(r.t_before.data(), static_cast<Eigen::Index>(r.t_before.size())).eval();
  d["q_before"] = rows(r.q_before, r.nq);
  d["v_before"] = rows(r.v_before, r.nv);
  d["q_after"] = rows(r.q_after, r.nq);
  d["v_after"] = rows(r.v_after, r.nv);
  return d;
}

void bindRunResult(py::module_& m) {
  py::class_<RunResult>(m, "RunResult",
                        "A run's summary (run.hpp RunSummary), final state, work terms and events.")
      .def_property_readonly("ok", [](const RunResult& r) { return r.summary.ok; })
      .def_property_readonly("failure", [](const RunResult& r) { return r.summary.failure; })
      .def_property_readonly("time", [](const RunResult& r) { return r.summary.time; })
      .def_readonly("q", &RunResult::q)
      .def_readonly("v", &RunResult::v)
      .def_readonly("energy", &RunResult::energy, "E at the end (J)")
      .def_readonly("kinetic_energy", &RunResult::kinetic)
      .def_property_readonly("energy0", [](const RunResult& r) { return r.summary.energy0; })
      .def_property_readonly("impact_energy_loss", [](const RunResult& r) { return r.summary.impact_energy_loss; })
      .def_property_readonly("friction_work", [](const RunResult& r) { return r.summary.friction_work; })
      .def_property_readonly("joint_work", [](const RunResult& r) { return r.summary.joint_work; })
      .def_property_readonly("support_work", [](const RunResult& r) { return r.summary.support_work; })
      .def_property_readonly("passive", [](const RunResult& r) { return r.summary.passive; })
      .def_property_readonly("max_energy_deviation", [](const RunResult& r) { return r.summary.max_energy_deviation; })
      .def_property_readonly("relative_energy_deviation",
                             [](const RunResult& r) { return r.summary.relativeEnergyDeviation(); })
      .def_property_readonly("max_velocity_residual", [](const RunResult& r) { return r.summary.max_velocity_residual; })
      .def_property_readonly("max_gap_residual", [](const RunResult& r) { return r.summary.max_gap_residual; })
      .def_property_readonly("wall_seconds", [](const RunResult& r) { return r.summary.wall_seconds; })
      .def_property_readonly("steps", [](const RunResult& r) { return r.summary.counters.steps; })
      .def_property_readonly("rejected", [](const RunResult& r) { return r.summary.counters.rejected; })
      .def_property_readonly("evaluations", [](const RunResult& r) { return r.summary.counters.evaluations; })
      .def_property_readonly("partition_changes", [](const RunResult& r) { return r.summary.partition_changes; })
      .def_readonly("overrides", &RunResult::overrides, "What the overrides set and what they changed.")
      .def_property_readonly("event_counts", [](const RunResult& r) {
        std::map<std::string, int> counts;
        for (const auto& k : contactEventKindTable()) counts[k.name] = 0;
        for (const RunEvent& e : r.summary.events) ++counts[toString(e.kind)];
        return counts;
      }, "Number of events of each kind (every kind present, 0 when none).")
      .def_property_readonly("events", &eventTable,
                             "The contact events as arrays, one entry per event: t, contact, kind, "
                             "speed_before, speed_after, normal_impulse, tangential_impulse, "
                             "outside_friction_cone, and the states around it — q_before, v_before "
                             "at t_before (the last state the run passed before it) and q_after, "
                             "v_after (at the event, after its impulse).")
      .def("__bool__", [](const RunResult& r) { return r.summary.ok; })
      .def("__repr__", [](const RunResult& r) {
        return "<RunResult: " + std::string(r.summary.ok ? "ok" : "failed: " + r.summary.failure) +
               ", t = " + std::to_string(r.summary.time) + ">";
      });
}

}  // namespace

void bindRun(py::module_& m) {
  bindRunResult(m);
  m.def("apply_overrides", [](const Scene& s, py::handle overrides, bool check_initial_state, bool project,
                              double tol) {
        const OverrideList list = readOverrides(overrides);
        std::shared_ptr<Scene> scene;
        std::vector<std::string> lines;
        {  // the scene's copy (model, constraints, meshes) too: threads do not take turns here
          py::gil_scoped_release release;
          OverrideReport report;
          scene = std::make_shared<Scene>(overriddenScene(s, list, report));
          lines = describe(*scene, report);
          if (check_initial_state) checkInitialState(*scene, project, tol);
        }
        return py::make_tuple(scene, lines);
      }, "scene"_a, "overrides"_a, py::kw_only(), "check_initial_state"_a = true, "project"_a = false,
      "tol"_a = 1e-8,
      "A copy of the scene with overrides applied, as `appell run --set` does (docs/python.md), and "
      "the lines saying what they set and which velocities the constraints changed.");
  m.def("run", [](const Scene& s, py::handle overrides, std::optional<double> duration, std::optional<double> dt,
                  std::optional<double> tol, std::optional<std::string> integrator,
                  std::optional<std::string> formulation, double max_energy_error, double max_residual,
                  double settle_time, bool project, bool project_initial) {
        const RunKnobs knobs{duration, dt, tol, integrator, formulation, max_energy_error, max_residual,
                             settle_time, project, project_initial};
        const OverrideList list = readOverrides(overrides);
        const bool check = !overrides.is_none();  // the loader checked the scene's own state
        RunResult r;
        std::vector<std::string> lines;
        {
          py::gil_scoped_release release;
          r = runCase(s, list, knobs, check, &lines);
        }
        r.overrides = lines;
        return r;
      }, "scene"_a, "overrides"_a = py::none(), py::kw_only(), "duration"_a = py::none(), "dt"_a = py::none(),
      "tol"_a = py::none(), "integrator"_a = py::none(), "formulation"_a = py::none(),
      "max_energy_error"_a = 5e-2, "max_residual"_a = 1e-6, "settle_time"_a = ContactEventOptions{}.settle_time,
      "project"_a = true, "project_initial"_a = false,
      "Runs the scene as `appell run` does (the GIL released) and returns a RunResult.");
}

}  // namespace appell::python
