// Scenes: loading (file or string, LoadOptions as keywords), the model's
// names, the initial state, and configuration-space helpers.
#include "arguments.hpp"
#include "bindings.hpp"

#include <appell/configuration.hpp>
#include <appell/constrained_dynamics.hpp>
#include <appell/contact_events.hpp>
#include <appell/dynamics.hpp>
#include <appell/integrators.hpp>
#include <appell/output.hpp>
#include <appell/simulator.hpp>
#include <appell/urdf.hpp>

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <optional>
#include <sstream>

namespace appell::python {

using namespace pybind11::literals;

int constraintIndex(const Scene& scene, py::handle which) {
  const int n = static_cast<int>(scene.constraints.size());
  if (py::isinstance<py::str>(which)) {
    const std::string name = which.cast<std::string>();
    for (int c = 0; c < n; ++c)
      if (scene.constraints[c]->name() == name) return c;
    throw py::key_error("no constraint named '" + name + "'");
  }
  int c = which.cast<int>();
  if (c < 0) c += n;
  if (c < 0 || c >= n)
    throw py::index_error("constraint index out of range (the scene has " + std::to_string(n) +
                          " constraints)");
  return c;
}

int bodyIndex(const Scene& scene, py::handle which) {
  const int n = scene.model.nbodies;
  if (py::isinstance<py::str>(which)) {
    const std::string name = which.cast<std::string>();
    const int b = scene.model.bodyIndex(name);
    if (b < 0) throw py::key_error("no body named '" + name + "'");
    return b;
  }
  int b = which.cast<int>();
  if (b < 0) b += n;
  if (b < 0 || b >= n)
    throw py::index_error("body index out of range (the model has " + std::to_string(n) + " bodies)");
  return b;
}

VecX sceneTau(const Scene& scene) {
  return scene.tau.size() == scene.model.nv ? scene.tau : VecX();
}

namespace {

// The inertia repairs as keywords (None: the scene's <simulation> decides).
struct InertiaKeywords {
  std::optional<bool> balance;
  std::optional<double> bound_inertia, bound_mass;
};

LoadOptions loadOptions(const std::vector<std::string>& package_paths, bool use_ros_package_path,
                        bool load_meshes, bool check_initial_state, bool project_initial_state,
                        bool joint_limits, double initial_state_tolerance,
                        const InertiaKeywords& inertia) {
  LoadOptions o;
  o.balance_inertia = inertia.balance;
  o.bound_inertia = inertia.bound_inertia;
  o.bound_mass = inertia.bound_mass;
  o.package_paths = package_paths;
  o.use_ros_package_path = use_ros_package_path;
  o.load_meshes = load_meshes;
  o.check_initial_state = check_initial_state;
  o.project_initial_state = project_initial_state;
  o.joint_limits = joint_limits;
  o.initial_state_tolerance = initial_state_tolerance;
  return o;
}

std::string fspath(py::handle path) {
  return py::module_::import("os").attr("fspath")(path).cast<std::string>();
}

void checkSize(const VecX& x, int n, const char* what) {
  if (x.size() != n)
    throw std::invalid_argument(std::string(what) + " must have size " + std::to_string(n) +
                                ", not " + std::to_string(x.size()));
}

std::vector<std::string> constraintNames(const Scene& s) {
  std::vector<std::string> names;
  for (const auto& c : s.constraints) names.push_back(c->name());
  return names;
}

/// "<constraint>.<row label>" per λ entry (the CSV's lambda: columns).
std::vector<std::string> rowLabels(const Scene& s) {
  std::vector<std::string> labels;
  for (const auto& c : s.constraints)
    for (int k = 0; k < c->rows(); ++k) labels.push_back(c->name() + "." + c->rowLabel(k));
  return labels;
}

template <class E>
py::list nameTable(std::span<const NamedValue<E>> table) {
  py::list out;
  for (const NamedValue<E>& e : table) {
    std::vector<std::string> aliases(e.aliases.begin(), e.aliases.end());
    out.append(py::dict("name"_a = e.name, "aliases"_a = aliases, "description"_a = e.description));
  }
  return out;
}

void bindSettings(py::module_& m) {
  py::class_<SimulationSettings>(m, "SimulationSettings",
                                 "The scene's <simulation> defaults (integrator, dt, tol, "
                                 "duration, formulation).")
      .def_readwrite("integrator", &SimulationSettings::integrator)
      .def_property("dt", [](const SimulationSettings& s) { return s.dt; },
                    [](SimulationSettings& s, double x) { s.dt = positiveArgument(x, 0, "settings.dt"); })
      .def_property("tol", [](const SimulationSettings& s) { return s.tol; },
                    [](SimulationSettings& s, double x) { s.tol = positiveArgument(x, 0, "settings.tol"); })
      .def_property("duration", [](const SimulationSettings& s) { return s.duration; },
                    [](SimulationSettings& s, double x) {
                      s.duration = positiveArgument(x, 0, "settings.duration");
                    })
      .def_readwrite("formulation", &SimulationSettings::formulation)
      .def("__repr__", [](const SimulationSettings& s) {
        std::ostringstream o;
        o << "SimulationSettings(integrator='" << s.integrator << "', dt=" << s.dt << ", tol=" << s.tol
          << ", duration=" << s.duration << ", formulation='" << s.formulation << "')";
        return o.str();
      });
}

}  // namespace

void bindScene(py::module_& m) {
  bindSettings(m);
  py::class_<Scene, std::shared_ptr<Scene>> scene(
      m, "Scene", "A loaded scene: model, constraints (contacts, then joint limits), initial state.");
  scene.def_readonly("source", &Scene::source)
      .def_readonly("robot_source", &Scene::robot_source,
                    "The robot description: source itself for a URDF; for a scene file "
                    "(<appell robot=...>), the URDF it names, resolved.")
      .def_readonly("warnings", &Scene::warnings,
                    "What the loader left out and why (a missing visual mesh): file:line: element: reason.")
      .def_property_readonly("nq", [](const Scene& s) { return s.model.nq; })
      .def_property_readonly("nv", [](const Scene& s) { return s.model.nv; })
      .def_property_readonly("nbodies", [](const Scene& s) { return s.model.nbodies; })
      .def_property_readonly("nrows", &Scene::constraintRows, "Total constraint rows (size of λ).")
      .def_property_readonly("body_names", [](const Scene& s) { return pythonTexts(s.model.body_names); })
      .def_property_readonly("joint_names", [](const Scene& s) { return pythonTexts(s.model.joint_names); })
      .def_property_readonly("joint_types", [](const Scene& s) {
        std::vector<std::string> t;
        for (const Joint& j : s.model.joints) t.push_back(toString(j.type));
        return t;
      })
      .def_property_readonly("position_names", [](const Scene& s) { return pythonTexts(coordinateNames(s.model, false)); })
      .def_property_readonly("velocity_names", [](const Scene& s) { return pythonTexts(coordinateNames(s.model, true)); })
      .def_property_readonly("constraint_names", [](const Scene& s) { return pythonTexts(constraintNames(s)); })
      .def_property_readonly("contact_names", [](const Scene& s) {
        std::vector<std::string> n;
        for (const auto& c : s.contacts) n.push_back(c->name());
        return pythonTexts(n);
      })
      .def_property_readonly("joint_limit_names", [](const Scene& s) {
        std::vector<std::string> n;
        for (const auto& c : s.joint_limits) n.push_back(c->name());
        return pythonTexts(n);
      })
      .def_property_readonly("actuator_names", [](const Scene& s) {
        std::vector<std::string> n;
        for (const Actuator& a : s.actuators) n.push_back(a.name);
        return pythonTexts(n);
      })
      .def_property_readonly("mimic_names", [](const Scene& s) {
        std::vector<std::string> n;
        for (const auto& c : s.couplings) n.push_back(c->name());
        return pythonTexts(n);
      })
      .def_property_readonly("support_names", [](const Scene& s) {
        std::vector<std::string> n;
        for (const Support& sp : s.supports) n.push_back(sp.name);
        return pythonTexts(n);
      })
      .def_property_readonly("constraint_sizes", [](const Scene& s) {
        std::vector<int> r;
        for (const auto& c : s.constraints) r.push_back(c->rows());
        return r;
      })
      .def_property_readonly("unilateral", [](const Scene& s) {
        std::vector<bool> u;
        for (const auto& c : s.constraints) u.push_back(c->unilateral());
        return u;
      })
      .def_property_readonly("row_labels", [](const Scene& s) { return pythonTexts(rowLabels(s)); })
      .def_property_readonly("row_kinds", [](const Scene& s) {
        std::vector<std::string> k;
        for (const auto& c : s.constraints)
          for (int r = 0; r < c->rows(); ++r) k.push_back(toString(c->rowKind(r)));
        return k;
      })
      .def_property_readonly("row_constraint", [](const Scene& s) {
        std::vector<int> owner;
        for (size_t c = 0; c < s.constraints.size(); ++c)
          for (int r = 0; r < s.constraints[c]->rows(); ++r) owner.push_back(static_cast<int>(c));
        return owner;
      })
      .def("constraint_index", [](const Scene& s, py::handle c) { return constraintIndex(s, c); },
           "which"_a, "Index of a constraint given by name or index.")
      .def("body_index", [](const Scene& s, py::handle b) { return bodyIndex(s, b); }, "which"_a)
      .def("constraint_rows", [](const Scene& s, py::handle which) {
        const int c = constraintIndex(s, which);
        int o = 0;
        for (int k = 0; k < c; ++k) o += s.constraints[k]->rows();
        std::vector<int> rows;
        for (int r = 0; r < s.constraints[c]->rows(); ++r) rows.push_back(o + r);
        return rows;
      }, "which"_a, "Indices into λ of a constraint's rows.")
      .def("row_index", [](const Scene& s, py::handle which, const std::string& kind) {
        const int c = constraintIndex(s, which);
        int o = 0;
        for (int k = 0; k < c; ++k) o += s.constraints[k]->rows();
        for (int r = 0; r < s.constraints[c]->rows(); ++r)
          if (kind == toString(s.constraints[c]->rowKind(r)) || kind == s.constraints[c]->rowLabel(r))
            return o + r;
        throw py::key_error("constraint '" + s.constraints[c]->name() + "' has no row '" + kind + "'");
      }, "which"_a, "kind"_a,
           "Index into λ of a constraint's row of this kind or label ('normal', 'tangent1', …).")
      .def_property("q0", [](const Scene& s) { return s.q0; },
                    [](Scene& s, const VecX& q) { checkVector(q, s.model.nq, "q0"); s.q0 = q; })
      .def_property("v0", [](const Scene& s) { return s.v0; },
                    [](Scene& s, const VecX& v) { checkVector(v, s.model.nv, "v0"); s.v0 = v; })
      .def_property("tau", [](const Scene& s) { return sceneTau(s); },
                    [](Scene& s, const VecX& t) { checkVector(t, s.model.nv, "tau"); s.tau = t; },
                    "Constant joint forces (nv) from <effort>; empty when none.")
      .def_readwrite("settings", &Scene::settings)
      .def_property_readonly("gravity", [](const Scene& s) { return Vec3(s.model.gravity); })
      .def_property_readonly("masses", [](const Scene& s) {
        std::vector<double> ms;
        for (const Inertia& i : s.model.inertias) ms.push_back(i.mass);
        return ms;
      })
      .def_property_readonly("total_mass", [](const Scene& s) { return s.model.totalMass(); })
      .def("check_initial_state", [](Scene& s, bool project, double tol) {
        const InitialStateReport r = checkInitialState(s, project, tol);
        return py::dict("velocity_residual"_a = r.velocity_residual, "gap_residual"_a = r.gap_residual,
                        "projected"_a = r.projected, "iterations"_a = r.iterations);
      }, "project"_a = false, "tol"_a = 1e-8,
           "Checks (q0, v0) against the constraints; with project=True puts it on them. "
           "Raises SceneError naming the worst row otherwise.")
      .def("neutral_configuration", [](const Scene& s) { return neutralConfiguration(s.model); })
      .def("retract", [](const Scene& s, const VecX& q0, const VecX& theta) {
        checkSize(q0, s.model.nq, "q0");
        checkSize(theta, s.model.nv, "theta");
        VecX q(s.model.nq);
        retract(s.model, q0, theta, q);
        return q;
      }, "q0"_a, "theta"_a, "q = retract(q0, θ): move by local coordinates θ (size nv).")
      .def("difference", [](const Scene& s, const VecX& q0, const VecX& q1) {
        checkSize(q0, s.model.nq, "q0");
        checkSize(q1, s.model.nq, "q1");
        VecX theta(s.model.nv);
        difference(s.model, q0, q1, theta);
        return theta;
      }, "q0"_a, "q1"_a, "θ with retract(q0, θ) = q1.")
      .def("configuration_rate", [](const Scene& s, const VecX& q, const VecX& v) {
        checkSize(q, s.model.nq, "q");
        checkSize(v, s.model.nv, "v");
        VecX qdot(s.model.nq);
        configurationRate(s.model, q, v, qdot);
        return qdot;
      }, "q"_a, "v"_a, "q̇ = G(q) v.")
      .def("energy", [](const Scene& s, const VecX& q, const VecX& v) {
        checkSize(q, s.model.nq, "q");
        checkSize(v, s.model.nv, "v");
        Data d(s.model);
        return py::make_tuple(kineticEnergy(s.model, d, q, v), potentialEnergy(s.model, d, q));
      }, "q"_a, "v"_a, "(kinetic, potential) energy at (q, v).")
      .def("__repr__", [](const Scene& s) {
        return "<appell.Scene '" + s.source + "': " + std::to_string(s.model.nbodies) + " bodies, nq " +
               std::to_string(s.model.nq) + ", nv " + std::to_string(s.model.nv) + ", " +
               std::to_string(s.constraints.size()) + " constraints>";
      });

  m.def("load_scene", [](py::handle path, const std::vector<std::string>& package_paths,
                         bool use_ros_package_path, bool load_meshes, bool check_initial_state,
                         bool project_initial_state, bool joint_limits, double tol,
                         std::optional<bool> balance, std::optional<double> bound_inertia,
                         std::optional<double> bound_mass) {
        const std::string p = fspath(path);
        const LoadOptions o = loadOptions(package_paths, use_ros_package_path, load_meshes,
                                          check_initial_state, project_initial_state, joint_limits, tol,
                                          {balance, bound_inertia, bound_mass});
        py::gil_scoped_release release;
        return std::make_shared<Scene>(loadScene(p, o));
      }, "path"_a, py::kw_only(), "package_paths"_a = std::vector<std::string>{},
        "use_ros_package_path"_a = true, "load_meshes"_a = true, "check_initial_state"_a = true,
        "project_initial_state"_a = false, "joint_limits"_a = true,
        "initial_state_tolerance"_a = 1e-8, "balance_inertia"_a = py::none(),
        "bound_inertia"_a = py::none(), "bound_mass"_a = py::none(),
        "Loads a URDF with an <appell> block, or a scene file (<appell robot=\"URI\">) around a\n"
        "description left as published. Raises SceneError naming the file, line and reason.\n"
        "balance_inertia, bound_inertia (kg m^2), bound_mass (kg): inertia repairs as MuJoCo's\n"
        "compiler options; None leaves the scene's <simulation> attribute in force. Repaired\n"
        "bodies and inertias loaded with a defect are listed in Scene.warnings.");
  m.def("load_scene_from_string", [](const std::string& xml, py::handle base_dir, const std::string& name,
                                     const std::vector<std::string>& package_paths,
                                     bool use_ros_package_path, bool load_meshes, bool check_initial_state,
                                     bool project_initial_state, bool joint_limits, double tol,
                                     std::optional<bool> balance, std::optional<double> bound_inertia,
                                     std::optional<double> bound_mass) {
        const std::string dir = fspath(base_dir);
        const LoadOptions o = loadOptions(package_paths, use_ros_package_path, load_meshes,
                                          check_initial_state, project_initial_state, joint_limits, tol,
                                          {balance, bound_inertia, bound_mass});
        py::gil_scoped_release release;
        return std::make_shared<Scene>(loadSceneFromString(xml, dir, name, o));
      }, "xml"_a, "base_dir"_a = ".", "name"_a = "<string>", py::kw_only(),
        "package_paths"_a = std::vector<std::string>{}, "use_ros_package_path"_a = true,
        "load_meshes"_a = true, "check_initial_state"_a = true, "project_initial_state"_a = false,
        "joint_limits"_a = true, "initial_state_tolerance"_a = 1e-8, "balance_inertia"_a = py::none(),
        "bound_inertia"_a = py::none(), "bound_mass"_a = py::none(),
        "Loads a scene from URDF text; base_dir resolves relative mesh paths (keywords as load_scene).");

  m.def("integrators", [] { return nameTable(integratorTable()); },
        "Integrator names, aliases and descriptions.");
  m.def("formulations", [] { return nameTable(formulationTable()); },
        "Formulation names, aliases and descriptions.");
  m.def("contact_event_kinds", [] { return nameTable(contactEventKindTable()); });
  m.def("contact_schemes", [] { return nameTable(contactSchemeTable()); },
        "Contact scheme names (Simulation(contacts=…)), aliases and descriptions.");
}

}  // namespace appell::python
