// Simulation: state in and out as NumPy arrays, stepping with the GIL
// released, per-contact reports, events, recorded trajectories, joint forces.
#include "bindings.hpp"
#include "arguments.hpp"
#include "simulation.hpp"

#include <appell/contact_problem.hpp>

#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <exception>
#include <limits>
#include <optional>

namespace appell::python {

using namespace pybind11::literals;

namespace {

/// A failed step or an undecidable state (SimulationError in Python).
struct SimulationFailure : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// The Python-facing simulation: a Simulation plus the Python error a
/// joint-force callback raised during a step (rethrown after it).
struct PySimulation : Simulation {
  using Simulation::Simulation;
  std::shared_ptr<std::exception_ptr> force_error = std::make_shared<std::exception_ptr>();

  void rethrowForceError() {
    if (!*force_error) return;
    std::exception_ptr e = *force_error;
    *force_error = nullptr;
    std::rethrow_exception(e);
  }
};

/// A recorded run: the samples and the status of the last step.
struct Trajectory {
  Recording rec;
  StepStatus status;
  std::vector<NamedEvent> events;
};

MatX stack(const std::vector<VecX>& rows, Eigen::Index cols) {
  MatX out(static_cast<Eigen::Index>(rows.size()), cols);
  for (size_t i = 0; i < rows.size(); ++i) out.row(static_cast<Eigen::Index>(i)) = rows[i].transpose();
  return out;
}

VecX vec(const std::vector<double>& x) {
  return Eigen::Map<const VecX>(x.data(), static_cast<Eigen::Index>(x.size()));
}

StepStatus checked(PySimulation& s, const StepStatus& st, bool check) {
  s.rethrowForceError();
  if (check && !st.ok) throw SimulationFailure(st.message);
  return st;
}

/// Steps with the GIL released; only one thread at a time per simulation.
template <class F>
StepStatus stepping(PySimulation& s, bool check, F&& f) {
  StepStatus st;
  {
    Simulation::Guard guard(s);
    py::gil_scoped_release release;
    st = f();
  }
  return checked(s, st, check);
}

void setJointForces(PySimulation& s, py::object tau) {
  Simulation::Guard guard(s);
  const int nv = s.scene().model.nv;
  // The forces given replace all the scene's, its servos' too (as before
  // servos were the simulator's own).
  s.simulator().setActuators({});
  if (tau.is_none()) {
    s.simulator().setJointForces({});
  } else if (PyCallable_Check(tau.ptr())) {
    // τ(t, q, v) → array of nv. Runs inside step() with the GIL taken back; a
    // Python error makes τ NaN (the step fails, its state is restored) and is
    // raised once step() returns.
    auto err = s.force_error;
    s.simulator().setJointForces([tau, err, nv](double t, const VecX& q, const VecX& v, VecX& out) {
      py::gil_scoped_acquire gil;
      if (*err) {
        out.setConstant(std::numeric_limits<double>::quiet_NaN());
        return;
      }
      try {
        const py::object returned = tau(t, q, v);
        VecX r;
        try {
          r = returned.cast<VecX>();
        } catch (const py::cast_error&) {
          throw py::type_error("joint forces: the callback returned " +
                               py::str(py::type::of(returned).attr("__name__")).cast<std::string>() +
                               ", not an array of nv = " + std::to_string(nv) + " numbers");
        }
        if (r.size() != nv)
          throw std::invalid_argument("joint forces: the callback returned " + std::to_string(r.size()) +
                                      " values, the model has nv = " + std::to_string(nv));
        out = r;
      } catch (...) {
        *err = std::current_exception();
        out.setConstant(std::numeric_limits<double>::quiet_NaN());
      }
    });
  } else {
    VecX c;
    try {
      c = tau.cast<VecX>();
    } catch (const py::cast_error&) {
      throw py::type_error("joint forces: expected None, an array of nv = " + std::to_string(nv) +
                           " numbers or a callable tau(t, q, v), not " +
                           py::str(py::type::of(tau).attr("__name__")).cast<std::string>());
    }
    checkVector(c, nv, "joint forces");
    s.simulator().setJointForces([c](double, const VecX&, const VecX&, VecX& out) { out = c; });
  }
  // Reports of the current state (λ, v̇) include the new forces.
  const Simulator& sm = s.simulator();
  s.setState(sm.time(), sm.q(), sm.v());
  s.rethrowForceError();
}

/// Per-constraint report, one row per constraint: F(frame) → 3-vector.
template <class F>
MatX perConstraint(const Simulation& s, F&& f) {
  const int n = static_cast<int>(s.scene().constraints.size());
  MatX out(n, 3);
  for (int c = 0; c < n; ++c) out.row(c) = f(s.simulator().contactFrame(c)).transpose();
  return out;
}

void bindReports(py::class_<StepStatus>& status, py::class_<NamedEvent>& event,
                 py::class_<Trajectory>& traj) {
  status.def_readonly("ok", &StepStatus::ok)
      .def_readonly("message", &StepStatus::message)
      .def_readonly("h_taken", &StepStatus::h_taken)
      .def_readonly("h_next", &StepStatus::h_next)
      .def_readonly("rejected", &StepStatus::rejected)
      .def_readonly("evaluations", &StepStatus::evaluations)
      .def_readonly("projection_iterations", &StepStatus::projection_iterations)
      .def_readonly("events", &StepStatus::events)
      .def("__bool__", [](const StepStatus& s) { return s.ok; })
      .def("__repr__", [](const StepStatus& s) {
        return s.ok ? "StepStatus(ok, h_taken=" + std::to_string(s.h_taken) + ")"
                    : "StepStatus(failed: " + s.message + ")";
      });
  event.def_property_readonly("t", [](const NamedEvent& e) { return e.event.t; })
      .def_property_readonly("constraint", [](const NamedEvent& e) { return e.event.constraint; })
      .def_readonly("name", &NamedEvent::constraint_name)
      .def_property_readonly("kind", [](const NamedEvent& e) { return std::string(toString(e.event.kind)); })
      .def_property_readonly("speed_before", [](const NamedEvent& e) { return e.event.speed_before; })
      .def_property_readonly("speed_after", [](const NamedEvent& e) { return e.event.speed_after; })
      .def_property_readonly("normal_impulse", [](const NamedEvent& e) { return e.event.normal_impulse; })
      .def_property_readonly("tangential_impulse", [](const NamedEvent& e) { return e.event.tangential_impulse; })
      .def("__repr__", [](const NamedEvent& e) {
        return "ContactEvent(t=" + std::to_string(e.event.t) + ", " + e.constraint_name + ", " +
               toString(e.event.kind) + ")";
      });
  traj.def_property_readonly("t", [](const Trajectory& r) { return vec(r.rec.t); })
      .def_property_readonly("q", [](const Trajectory& r) {
        return stack(r.rec.q, r.rec.q.empty() ? 0 : r.rec.q.front().size());
      })
      .def_property_readonly("v", [](const Trajectory& r) {
        return stack(r.rec.v, r.rec.v.empty() ? 0 : r.rec.v.front().size());
      })
      .def_property_readonly("lambdas", [](const Trajectory& r) {
        return stack(r.rec.lambda, r.rec.lambda.empty() ? 0 : r.rec.lambda.front().size());
      })
      .def_property_readonly("energy", [](const Trajectory& r) { return vec(r.rec.energy); })
      .def_property_readonly("velocity_residual", [](const Trajectory& r) { return vec(r.rec.velocity_residual); })
      .def_property_readonly("gap_residual", [](const Trajectory& r) { return vec(r.rec.gap_residual); })
      .def_readonly("status", &Trajectory::status)
      .def_readonly("events", &Trajectory::events)
      .def("__len__", [](const Trajectory& r) { return r.rec.t.size(); });
}

}  // namespace

void bindSimulation(py::module_& m) {
  py::register_exception<SimulationFailure>(m, "SimulationError", PyExc_RuntimeError);
  py::class_<StepStatus> status(m, "StepStatus", "Outcome of step() / advance_to() (truthy when ok).");
  py::class_<NamedEvent> event(m, "ContactEvent", "A touchdown, bounce, lift-off, slip or stick.");
  py::class_<Trajectory> traj(m, "Trajectory", "States sampled by Simulation.record(), as arrays.");
  bindReports(status, event, traj);

  py::class_<PySimulation> sim(m, "Simulation",
      "A Simulator for a scene. Options left None take the scene's <simulation> settings.");
  sim.def(py::init([](std::shared_ptr<Scene> scene, std::optional<std::string> integrator,
                      std::optional<std::string> formulation, std::optional<double> dt,
                      std::optional<double> rtol, std::optional<double> atol, double h_min, double h_max,
                      bool project_positions, bool project_velocities, bool contact_events,
                      double settle_time, double max_energy_error,
                      std::optional<std::string> contacts) {
             SimulationOptions o;
             o.integrator = integrator.value_or("");
             o.formulation = formulation.value_or("");
             o.dt = dt;
             o.rtol = rtol;
             o.atol = atol;
             o.h_min = h_min;
             o.h_max = h_max;
             o.project_positions = project_positions;
             o.project_velocities = project_velocities;
             o.contact_events = contact_events;
             o.settle_time = settle_time;
             o.max_energy_error = max_energy_error;
             o.contacts = contacts.value_or("");
             return std::make_unique<PySimulation>(std::move(scene), o);
           }),
           "scene"_a, py::kw_only(), "integrator"_a = py::none(), "formulation"_a = py::none(),
           "dt"_a = py::none(), "rtol"_a = py::none(), "atol"_a = py::none(), "h_min"_a = 1e-14,
           "h_max"_a = 0.1, "project_positions"_a = true, "project_velocities"_a = true,
           "contact_events"_a = true, "settle_time"_a = ContactEventOptions{}.settle_time,
           "max_energy_error"_a = 5e-2, "contacts"_a = py::none())
      .def_property_readonly("scene", [](const PySimulation& s) { return std::const_pointer_cast<Scene>(s.scenePtr()); })
      .def_property_readonly("dt", &PySimulation::dt)
      .def_property_readonly("integrator", [](PySimulation& s) { return std::string(toString(s.simulator().integrator().type())); })
      .def_property_readonly("formulation", [](PySimulation& s) { return std::string(toString(s.simulator().solver().formulation())); })
      // State.
      .def_property_readonly("t", [](const PySimulation& s) { Simulation::Guard g(s); return s.simulator().time(); })
      .def_property_readonly("q", [](const PySimulation& s) { Simulation::Guard g(s); return VecX(s.simulator().q()); })
      .def_property_readonly("v", [](const PySimulation& s) { Simulation::Guard g(s); return VecX(s.simulator().v()); })
      .def("set_state", [](PySimulation& s, std::optional<VecX> q, std::optional<VecX> v, std::optional<double> t) {
        Simulation::Guard g(s);
        const Simulator& sm = s.simulator();
        const bool ok = s.setState(t.value_or(sm.time()), q ? *q : VecX(sm.q()), v ? *v : VecX(sm.v()));
        s.rethrowForceError();
        if (!ok) throw SimulationFailure(sm.lastStateError());
      }, "q"_a = py::none(), "v"_a = py::none(), "t"_a = py::none(),
         "Sets (t, q, v) (omitted parts keep their value) and evaluates it; does not project. "
         "Raises ValueError on wrong sizes, SimulationError when no consistent contact mode exists "
         "(the state is set nonetheless).")
      .def("project_state", [](PySimulation& s, bool check) {
        return stepping(s, check, [&] { return s.simulator().projectState(); });
      }, "check"_a = true, "Projects the state onto the constraints (positions, then velocities).")
      .def("set_joint_forces", &setJointForces, "tau"_a,
           "None (no forces), a constant array of nv, or a callable tau(t, q, v) -> array of nv "
           "(called with the GIL held: it serialises threads); replaces the scene's efforts and "
           "servos.")
      // Stepping.
      .def("step", [](PySimulation& s, std::optional<double> h, bool check) {
        return stepping(s, check, [&] { return s.step(h); });
      }, "h"_a = py::none(), "check"_a = true,
         "One step of h (default: dt). Raises SimulationError on failure unless check=False.")
      .def("advance_to", [](PySimulation& s, double t_end, std::optional<double> h, bool check) {
        return stepping(s, check, [&] { return s.advanceTo(t_end, h); });
      }, "t_end"_a, "h"_a = py::none(), "check"_a = true,
         "Steps to t_end (fixed steps of h, or adaptive from h). Returns the last StepStatus.")
      .def("record", [](PySimulation& s, double t_end, std::optional<double> h, int every, bool check) {
        Trajectory tr;
        tr.status = stepping(s, false, [&] { return s.advanceTo(t_end, h, &tr.rec, every); });
        tr.events = s.events();
        checked(s, tr.status, check);
        return tr;
      }, "t_end"_a, "h"_a = py::none(), "every"_a = 1, "check"_a = true,
         "advance_to() that samples the start, every `every`-th step and the end into a Trajectory.")
      .def_property_readonly("events", [](const PySimulation& s) { Simulation::Guard g(s); return s.events(); },
                             "Contact events of the last set_state / step / advance_to / record.")
      // Reports of the current state.
      .def_property_readonly("lambdas", [](const PySimulation& s) { Simulation::Guard g(s); return VecX(s.simulator().lambda()); },
                             "λ, one multiplier per constraint row (Scene.row_labels).")
      .def("constraint_lambdas", [](const PySimulation& s, py::handle which) {
        Simulation::Guard g(s);
        const int c = constraintIndex(s.scene(), which);
        return VecX(s.simulator().lambda().segment(s.simulator().constraintData().offset[c],
                                                   s.scene().constraints[c]->rows()));
      }, "which"_a, "λ of one constraint's rows (by name or index).")
      .def_property_readonly("vdot", [](const PySimulation& s) { Simulation::Guard g(s); return VecX(s.simulator().dynamics().vdot); })
      .def_property_readonly("reaction", [](const PySimulation& s) { Simulation::Guard g(s); return VecX(s.simulator().dynamics().reaction); },
                             "Aᵀλ (nv).")
      .def_property_readonly("redundant_rows", [](const PySimulation& s) { Simulation::Guard g(s); return s.simulator().redundantRows(); })
      .def_property_readonly("contact_points", [](const PySimulation& s) {
        Simulation::Guard g(s);
        return perConstraint(s, [](const ContactFrame& f) { return f.point; });
      }, "Contact point of every constraint (rows), world frame.")
      .def_property_readonly("contact_normals", [](const PySimulation& s) {
        Simulation::Guard g(s);
        return perConstraint(s, [](const ContactFrame& f) { return f.normal; });
      }, "Unit normal of every constraint (rows), from the support toward the body.")
      .def_property_readonly("contact_gaps", [](const PySimulation& s) {
        Simulation::Guard g(s);
        const int n = static_cast<int>(s.scene().constraints.size());
        VecX gaps(n);
        for (int c = 0; c < n; ++c) gaps[c] = s.simulator().contactFrame(c).gap;
        return gaps;
      })
      .def_property_readonly("closed", [](const PySimulation& s) {
        Simulation::Guard g(s);
        std::vector<bool> closed;
        for (size_t c = 0; c < s.scene().constraints.size(); ++c)
          closed.push_back(s.simulator().isClosed(static_cast<int>(c)));
        return closed;
      }, "Per constraint: closed (True) or open (lifted off).")
      .def_property_readonly("sliding", [](const PySimulation& s) {
        Simulation::Guard g(s);
        std::vector<bool> sliding;
        for (size_t c = 0; c < s.scene().constraints.size(); ++c)
          sliding.push_back(s.simulator().constraintData().isSliding(static_cast<int>(c)));
        return sliding;
      })
      .def_property_readonly("kinetic_energy", [](const PySimulation& s) { Simulation::Guard g(s); return s.simulator().kineticEnergy(); })
      .def_property_readonly("potential_energy", [](const PySimulation& s) { Simulation::Guard g(s); return s.simulator().potentialEnergy(); })
      .def_property_readonly("energy", [](const PySimulation& s) { Simulation::Guard g(s); return s.simulator().energy(); })
      .def_property_readonly("impact_energy_loss", [](const PySimulation& s) { Simulation::Guard g(s); return s.simulator().impactEnergyLoss(); })
      .def_property_readonly("scheme_energy_loss", [](const PySimulation& s) { Simulation::Guard g(s); return s.simulator().schemeEnergyLoss(); })
      .def_property_readonly("friction_work", [](const PySimulation& s) { Simulation::Guard g(s); return s.simulator().frictionWork(); },
                             "Energy taken by sliding friction since the state was set (J).")
      .def_property_readonly("joint_work", [](const PySimulation& s) { Simulation::Guard g(s); return s.simulator().jointWork(); },
                             "Work of the joint forces since the state was set, ∫ τ·v dt (J).")
      .def_property_readonly("support_work", [](const PySimulation& s) { Simulation::Guard g(s); return s.simulator().supportWork(); },
                             "Work of constraints that move in time since the state was set, ∫ −λᵀb dt (J).")
      .def_property_readonly("velocity_residual", [](const PySimulation& s) { Simulation::Guard g(s); return s.simulator().velocityResidual(); },
                             "‖A v + b‖∞ over the closed rows.")
      .def_property_readonly("gap_residual", [](const PySimulation& s) { Simulation::Guard g(s); return s.simulator().gapResidual(); },
                             "max |g| over the closed holonomic rows.")
      .def("row_residuals", [](PySimulation& s) {
        Simulation::Guard g(s);
        VecX residual, gap;
        s.rowResiduals(residual, gap);
        return py::make_tuple(residual, gap);
      }, "(A v + b, g) per row at the current state, open constraints included.")
      .def("contact_problem", [](const PySimulation& s) -> py::object {
        Simulation::Guard g(s);
        ContactProblemData d;
        if (!s.simulator().contactProblem(d)) return py::none();
        py::list blocks;
        for (const ContactProblemBlock& b : d.blocks)
          blocks.append(py::dict("constraint"_a = b.constraint,
                                 "name"_a = s.scene().constraints[b.constraint]->name(), "first"_a = b.first,
                                 "friction_rows"_a = b.friction_rows, "equality_rows"_a = b.equality_rows,
                                 "mu"_a = b.mu));
        return py::dict("t"_a = d.t, "W"_a = d.W, "u_free"_a = d.u_free, "target"_a = d.target,
                        "warm_start"_a = d.warm_start, "P"_a = d.P, "blocks"_a = blocks,
                        "skipped_finish_modes"_a = d.skipped_finish_modes,
                        "sweeps"_a = d.sweeps, "residual"_a = d.residual, "converged"_a = d.converged);
      }, "The last step's contact problem u = W P + u_free (docs/contacts.md §10) as a dict, "
         "None when that step was not time-stepped or had no contact candidate.")
      .def("body_pose", [](PySimulation& s, py::handle body) {
        Simulation::Guard g(s);
        return s.bodyPose(bodyIndex(s.scene(), body));
      }, "body"_a, "4 × 4 world pose of a body (by name or index).")
      .def_property_readonly("counters", [](const PySimulation& s) {
        Simulation::Guard g(s);
        const SimulatorCounters& c = s.simulator().counters();
        return py::dict("steps"_a = c.steps, "rejected"_a = c.rejected, "evaluations"_a = c.evaluations,
                        "failed"_a = c.failed, "projection_iterations"_a = c.projection_iterations,
                        "events"_a = c.events, "event_steps"_a = c.event_steps);
      });
}

}  // namespace appell::python
