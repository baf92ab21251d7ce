// Equilibria (equilibria.hpp) and linearization (linearization.hpp) of a
// scene, with the GIL released while they run.
#include "case_runs.hpp"

#include <appell/equilibria.hpp>
#include <appell/linearization.hpp>

#include <pybind11/complex.h>
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <optional>

namespace appell::python {

using namespace pybind11::literals;

namespace {

EquilibriumOptions equilibriumOptions(const Scene& s, const std::optional<VecX>& tau, double time,
                                      double tolerance, double force_scale, double length_scale,
                                      int max_iterations, double fd_step, double rank_tolerance) {
  EquilibriumOptions o;
  o.tau = tau ? *tau : sceneTau(s);
  o.time = time;
  o.tolerance = tolerance;
  o.force_scale = force_scale;
  o.length_scale = length_scale;
  o.max_iterations = max_iterations;
  o.fd_step = fd_step;
  o.rank_tolerance = rank_tolerance;
  return o;
}

void bindResults(py::module_& m) {
  py::class_<EquilibriumResult>(m, "EquilibriumResult")
      .def_readonly("converged", &EquilibriumResult::converged)
      .def_readonly("message", &EquilibriumResult::message)
      .def_readonly("q", &EquilibriumResult::q)
      .def_readonly("lambdas", &EquilibriumResult::lambda, "One multiplier per row (minimum norm).")
      .def_readonly("reaction", &EquilibriumResult::reaction)
      .def_readonly("generalized_force", &EquilibriumResult::generalized_force)
      .def_readonly("residual", &EquilibriumResult::residual)
      .def_readonly("force_residual", &EquilibriumResult::force_residual)
      .def_readonly("gap_residual", &EquilibriumResult::gap_residual)
      .def_readonly("motion_residual", &EquilibriumResult::motion_residual)
      .def_readonly("iterations", &EquilibriumResult::iterations)
      .def_readonly("rank_A", &EquilibriumResult::rank_A)
      .def_readonly("redundant_rows", &EquilibriumResult::redundant_rows)
      .def_readonly("manifold_dimension", &EquilibriumResult::manifold_dimension)
      .def_readonly("second_kind", &EquilibriumResult::second_kind,
                    "Held only with nonholonomic reactions (Emelyanova & Fufaev's second kind).")
      .def_readonly("holonomic_residual", &EquilibriumResult::holonomic_residual,
                    "min over the holonomic rows' λ of |Q + A_hᵀ λ_h|∞.")
      .def_readonly("tangent", &EquilibriumResult::tangent)
      .def_readonly("row_labels", &EquilibriumResult::row_labels)
      .def("__bool__", [](const EquilibriumResult& r) { return r.converged; })
      .def("__repr__", [](const EquilibriumResult& r) { return "<EquilibriumResult: " + r.message + ">"; });
  py::class_<MultiStartResult>(m, "MultiStartResult")
      .def_readonly("runs", &MultiStartResult::runs, "One EquilibriumResult per guess, in order.")
      .def_readonly("distinct", &MultiStartResult::distinct, "Indices of converged runs, duplicates removed.")
      .def_readonly("set", &MultiStartResult::set, "Per distinct equilibrium, the equilibrium set it lies on.")
      .def_readonly("sets", &MultiStartResult::sets, "Number of equilibrium sets found.");
  py::class_<LinearizationResult>(m, "LinearizationResult")
      .def_readonly("dimension", &LinearizationResult::dimension)
      .def_readonly("retained", &LinearizationResult::retained)
      .def_readonly("basis", &LinearizationResult::basis)
      .def_readonly("matrix", &LinearizationResult::matrix)
      .def_readonly("eigenvalues", &LinearizationResult::eigenvalues)
      .def_readonly("drift", &LinearizationResult::drift)
      .def_readonly("steady_residual", &LinearizationResult::steady_residual)
      .def_readonly("symmetry_residual", &LinearizationResult::symmetry_residual)
      .def_readonly("constraint_residual", &LinearizationResult::constraint_residual)
      .def("count_zero_eigenvalues", &countZeroEigenvalues, "tol"_a,
           "Number of eigenvalues with |μ| ≤ tol.");
}

}  // namespace

void bindAnalysis(py::module_& m) {
  bindResults(m);
  m.def("find_equilibrium", [](const Scene& s, std::optional<VecX> q_guess, std::optional<VecX> tau,
                               double time, double tolerance, double force_scale, double length_scale,
                               int max_iterations, double fd_step, double rank_tolerance) {
        const EquilibriumOptions o = equilibriumOptions(s, tau, time, tolerance, force_scale, length_scale,
                                                        max_iterations, fd_step, rank_tolerance);
        const VecX guess = q_guess ? *q_guess : s.q0;
        py::gil_scoped_release release;
        return findEquilibrium(s.model, s.constraints, guess, o);
      }, "scene"_a, "q_guess"_a = py::none(), py::kw_only(), "tau"_a = py::none(), "time"_a = 0.0,
        "tolerance"_a = 1e-12, "force_scale"_a = -1.0, "length_scale"_a = 1.0, "max_iterations"_a = 100,
        "fd_step"_a = 1e-6, "rank_tolerance"_a = 1e-6,
        "Equilibrium Q(q) + Aᵀλ = 0, g(q) = 0 near q_guess (default q0), λ kept among the unknowns. "
        "tau defaults to the scene's joint forces.");
  m.def("find_equilibria", [](const Scene& s, const std::vector<VecX>& guesses, std::optional<VecX> tau,
                              double time, double tolerance, double force_scale, double length_scale,
                              int max_iterations, double fd_step, double rank_tolerance, double same_tol) {
        const EquilibriumOptions o = equilibriumOptions(s, tau, time, tolerance, force_scale, length_scale,
                                                        max_iterations, fd_step, rank_tolerance);
        py::gil_scoped_release release;
        return findEquilibria(s.model, s.constraints, guesses, o, same_tol);
      }, "scene"_a, "guesses"_a, py::kw_only(), "tau"_a = py::none(), "time"_a = 0.0,
        "tolerance"_a = 1e-12, "force_scale"_a = -1.0, "length_scale"_a = 1.0, "max_iterations"_a = 100,
        "fd_step"_a = 1e-6, "rank_tolerance"_a = 1e-6, "same_tol"_a = 1e-6,
        "find_equilibrium from every guess; converged runs within same_tol of an earlier one are duplicates.");
  m.def("linearize", [](const Scene& s, std::optional<VecX> q, std::optional<VecX> v,
                        std::optional<std::string> formulation, std::optional<VecX> tau, double time,
                        const py::iterable& cyclic, double fd_step, double rank_tolerance) {
        LinearizeKnobs knobs;
        knobs.formulation = formulation;
        knobs.tau = tau;
        knobs.time = time;
        knobs.cyclic = cyclicIndices(s, cyclic);
        knobs.fd_step = fd_step;
        knobs.rank_tolerance = rank_tolerance;
        const VecX qq = q ? *q : s.q0, vv = v ? *v : s.v0;
        py::gil_scoped_release release;
        return linearizeScene(s, qq, vv, knobs);
      }, "scene"_a, "q"_a = py::none(), "v"_a = py::none(), py::kw_only(), "formulation"_a = py::none(),
        "tau"_a = py::none(), "time"_a = 0.0, "cyclic"_a = py::tuple(), "fd_step"_a = 1e-5,
        "rank_tolerance"_a = 1e-9,
        "Linearization on the constraint manifold about (q, v) (default q0, v0). cyclic: velocity "
        "indices or names of cyclic coordinates for a steady motion.");
}

}  // namespace appell::python
