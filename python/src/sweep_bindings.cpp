// Batches of a sweep (python/appell/sweep.py): run_batch and
// linearize_batch run a list of cases of one scene in C++ with the GIL
// released for the whole batch, and return its table as NumPy columns, one
// entry per case in the order given. The cases are read from Python once
// before the batch, the columns built once after it: nothing per case takes
// the GIL, so threads running batches side by side never wait for each
// other, and a Dask or process worker pays one call per batch.
//
// Each case is computed by the code of the single-case calls
// (case_runs.hpp) — `run(scene, overrides, …)`, or `apply_overrides` then
// `linearize` at the overridden scene's initial state — so its numbers equal
// those bit for bit. A case that throws (a bad override value, a state off
// its constraints, a failing solver) gets status "error", the message, and
// NaN numbers; the batch goes on.
#include "case_runs.hpp"

#include <appell/contact_events.hpp>
#include <appell/urdf.hpp>

#include <pybind11/complex.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <chrono>
#include <complex>
#include <limits>
#include <map>

namespace appell::python {

using namespace pybind11::literals;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// What every row has: how the case ended and its wall time.
struct RowBase {
  std::string status = "error", message;
  double wall_seconds = kNaN;
};

struct RunRow : RowBase {
  double time = kNaN, energy0 = kNaN, energy = kNaN, impact_energy_loss = kNaN, friction_work = kNaN,
         joint_work = kNaN, support_work = kNaN, max_energy_deviation = kNaN, relative_energy_deviation = kNaN,
         max_velocity_residual = kNaN, max_gap_residual = kNaN;
  long steps = 0, events = 0;
  std::map<std::string, long> event_counts;  ///< every kind, by name (the columns' order)
  VecX q, v;
};

struct LinearizeRow : RowBase {
  long dimension = 0;
  Eigen::VectorXcd eigenvalues;
  double max_real = kNaN, steady_residual = kNaN, symmetry_residual = kNaN, constraint_residual = kNaN;
  VecX q, v;
};

std::vector<OverrideList> readCases(const py::iterable& cases) {
  std::vector<OverrideList> out;
  for (py::handle c : cases) out.push_back(readOverrides(c));
  return out;
}

/// Runs `compute(case, row)` for every case without the GIL, timing each; a
/// case that throws keeps only its status "error" and message (memory
/// exhaustion ends the batch: MemoryError). With `check_signals` (a batch
/// run by the main thread: a serial sweep, the pilot case), Ctrl-C between
/// two cases ends the batch with KeyboardInterrupt — taking the GIL for a
/// moment per case, which a worker thread's batch does not.
template <class Row, class Compute>
std::vector<Row> runCases(const std::vector<OverrideList>& cases, bool check_signals, const Compute& compute) {
  std::vector<Row> rows(cases.size());
  py::gil_scoped_release release;
  for (std::size_t k = 0; k < cases.size(); ++k) {
    if (check_signals && k > 0) {
      py::gil_scoped_acquire acquire;
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    }
    const auto start = std::chrono::steady_clock::now();
    try {
      compute(cases[k], rows[k]);
    } catch (const std::bad_alloc&) {
      throw;
    } catch (const std::exception& e) {
      rows[k] = Row{};
      rows[k].message = e.what();
    }
    rows[k].wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  return rows;
}

template <class Row, class Get>
py::array_t<double> numbers(const std::vector<Row>& rows, Get get) {
  py::array_t<double> out(static_cast<py::ssize_t>(rows.size()));
  auto w = out.mutable_unchecked<1>();
  for (std::size_t k = 0; k < rows.size(); ++k) w(static_cast<py::ssize_t>(k)) = get(rows[k]);
  return out;
}

template <class Row, class Get>
py::array_t<long long> counts(const std::vector<Row>& rows, Get get) {
  py::array_t<long long> out(static_cast<py::ssize_t>(rows.size()));
  auto w = out.mutable_unchecked<1>();
  for (std::size_t k = 0; k < rows.size(); ++k) w(static_cast<py::ssize_t>(k)) = get(rows[k]);
  return out;
}

/// n × width, row k the state of case k (NaN for a case that has none).
template <class Row>
py::array_t<double> states(const std::vector<Row>& rows, const VecX Row::*member, int width) {
  py::array_t<double> out({static_cast<py::ssize_t>(rows.size()), static_cast<py::ssize_t>(width)});
  auto w = out.mutable_unchecked<2>();
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const VecX& x = rows[k].*member;
    for (int i = 0; i < width; ++i)
      w(static_cast<py::ssize_t>(k), i) = x.size() == width ? x[i] : kNaN;
  }
  return out;
}

/// status, message: lists of str (the messages as pythonText makes them).
template <class Row>
void putTexts(py::dict& d, const std::vector<Row>& rows) {
  py::list status, message;
  for (const Row& r : rows) {
    status.append(py::str(r.status));
    message.append(pythonText(r.message));
  }
  d["status"] = status;
  d["message"] = message;
}

py::dict runColumns(const std::vector<RunRow>& rows, const Scene& base) {
  py::dict d;
  putTexts(d, rows);
  d["time"] = numbers(rows, [](const RunRow& r) { return r.time; });
  d["q"] = states(rows, &RunRow::q, base.model.nq);
  d["v"] = states(rows, &RunRow::v, base.model.nv);
  d["energy0"] = numbers(rows, [](const RunRow& r) { return r.energy0; });
  d["energy"] = numbers(rows, [](const RunRow& r) { return r.energy; });
  d["impact_energy_loss"] = numbers(rows, [](const RunRow& r) { return r.impact_energy_loss; });
  d["friction_work"] = numbers(rows, [](const RunRow& r) { return r.friction_work; });
  d["joint_work"] = numbers(rows, [](const RunRow& r) { return r.joint_work; });
  d["support_work"] = numbers(rows, [](const RunRow& r) { return r.support_work; });
  d["max_energy_deviation"] = numbers(rows, [](const RunRow& r) { return r.max_energy_deviation; });
  d["relative_energy_deviation"] = numbers(rows, [](const RunRow& r) { return r.relative_energy_deviation; });
  d["max_velocity_residual"] = numbers(rows, [](const RunRow& r) { return r.max_velocity_residual; });
  d["max_gap_residual"] = numbers(rows, [](const RunRow& r) { return r.max_gap_residual; });
  d["steps"] = counts(rows, [](const RunRow& r) { return r.steps; });
  d["events"] = counts(rows, [](const RunRow& r) { return r.events; });
  std::vector<std::string> kinds;  // by name, as RunResult.event_counts lists them
  for (const auto& k : contactEventKindTable()) kinds.emplace_back(k.name);
  std::sort(kinds.begin(), kinds.end());
  for (const std::string& name : kinds)
    d[py::str("events_" + name)] = counts(rows, [&](const RunRow& r) {
      const auto it = r.event_counts.find(name);
      return it == r.event_counts.end() ? 0L : it->second;
    });
  d["wall_seconds"] = numbers(rows, [](const RunRow& r) { return r.wall_seconds; });
  return d;
}

void fillRunRow(const RunResult& r, RunRow& row) {
  const RunSummary& s = r.summary;
  row.status = s.ok ? "ok" : "failed";
  row.message = s.failure;
  row.time = s.time;
  row.q = r.q;
  row.v = r.v;
  row.energy0 = s.energy0;
  row.energy = r.energy;
  row.impact_energy_loss = s.impact_energy_loss;
  row.friction_work = s.friction_work;
  row.joint_work = s.joint_work;
  row.support_work = s.support_work;
  row.max_energy_deviation = s.max_energy_deviation;
  row.relative_energy_deviation = s.relativeEnergyDeviation();
  row.max_velocity_residual = s.max_velocity_residual;
  row.max_gap_residual = s.max_gap_residual;
  row.steps = s.counters.steps;
  row.events = static_cast<long>(s.events.size());
  for (const RunEvent& e : s.events) ++row.event_counts[toString(e.kind)];
}

/// The largest real part (NaN if any is NaN, −∞ for none), as NumPy's max.
double maxReal(const Eigen::VectorXcd& eig) {
  double m = -std::numeric_limits<double>::infinity();
  for (const auto& z : eig) {
    if (std::isnan(z.real())) return kNaN;
    m = std::max(m, z.real());
  }
  return m;
}

py::dict linearizeColumns(const std::vector<LinearizeRow>& rows, const Scene& base) {
  py::dict d;
  putTexts(d, rows);
  d["q"] = states(rows, &LinearizeRow::q, base.model.nq);
  d["v"] = states(rows, &LinearizeRow::v, base.model.nv);
  d["dimension"] = counts(rows, [](const LinearizeRow& r) { return r.dimension; });
  Eigen::Index width = 0;
  for (const LinearizeRow& r : rows) width = std::max(width, r.eigenvalues.size());
  py::array_t<std::complex<double>> eig({static_cast<py::ssize_t>(rows.size()), static_cast<py::ssize_t>(width)});
  auto w = eig.mutable_unchecked<2>();
  for (std::size_t k = 0; k < rows.size(); ++k)
    for (Eigen::Index i = 0; i < width; ++i)
      w(static_cast<py::ssize_t>(k), i) = i < rows[k].eigenvalues.size() ? rows[k].eigenvalues[i]
                                                                          : std::complex<double>(kNaN, 0);
  d["eigenvalues"] = eig;
  d["max_real"] = numbers(rows, [](const LinearizeRow& r) { return r.max_real; });
  d["steady_residual"] = numbers(rows, [](const LinearizeRow& r) { return r.steady_residual; });
  d["symmetry_residual"] = numbers(rows, [](const LinearizeRow& r) { return r.symmetry_residual; });
  d["constraint_residual"] = numbers(rows, [](const LinearizeRow& r) { return r.constraint_residual; });
  d["wall_seconds"] = numbers(rows, [](const LinearizeRow& r) { return r.wall_seconds; });
  return d;
}

void bindRunBatch(py::module_& m) {
  m.def("run_batch", [](const Scene& base, const py::iterable& cases, std::optional<double> duration,
                        std::optional<double> dt, std::optional<double> tol, std::optional<std::string> integrator,
                        std::optional<std::string> formulation, double max_energy_error, double max_residual,
                        double settle_time, bool project, bool project_initial, bool check_signals) {
        const RunKnobs knobs{duration, dt, tol, integrator, formulation, max_energy_error, max_residual,
                             settle_time, project, project_initial};
        const std::vector<OverrideList> list = readCases(cases);
        const auto rows = runCases<RunRow>(list, check_signals, [&](const OverrideList& overrides, RunRow& row) {
          fillRunRow(runCase(base, overrides, knobs, true), row);
        });
        return runColumns(rows, base);
      }, "scene"_a, "cases"_a, py::kw_only(), "duration"_a = py::none(), "dt"_a = py::none(),
      "tol"_a = py::none(), "integrator"_a = py::none(), "formulation"_a = py::none(),
      "max_energy_error"_a = 5e-2, "max_residual"_a = 1e-6, "settle_time"_a = ContactEventOptions{}.settle_time,
      "project"_a = true, "project_initial"_a = false, "check_signals"_a = false,
      "run(scene, case, …) of every case (a list of (name, value) overrides each), the GIL released for the "
      "whole batch: a dict of columns, one entry per case (appell.sweep's batches).");
}

void bindLinearizeBatch(py::module_& m) {
  m.def("linearize_batch", [](const Scene& base, const py::iterable& cases, std::optional<std::string> formulation,
                              std::optional<VecX> tau, double time, const py::iterable& cyclic, double fd_step,
                              double rank_tolerance, bool check_signals) {
        LinearizeKnobs knobs;
        knobs.formulation = formulation;
        knobs.tau = tau;
        knobs.time = time;
        knobs.cyclic = cyclicIndices(base, cyclic);  // overrides change no coordinate
        knobs.fd_step = fd_step;
        knobs.rank_tolerance = rank_tolerance;
        const std::vector<OverrideList> list = readCases(cases);
        const auto rows = runCases<LinearizeRow>(list, check_signals, [&](const OverrideList& overrides,
                                                                          LinearizeRow& row) {
          OverrideReport report;
          Scene scene = overriddenScene(base, overrides, report);
          checkInitialState(scene, false, 1e-8);  // apply_overrides' check, its defaults
          const LinearizationResult lin = linearizeScene(scene, scene.q0, scene.v0, knobs);
          row.status = "ok";
          row.q = scene.q0;
          row.v = scene.v0;
          row.dimension = lin.dimension;
          row.eigenvalues = lin.eigenvalues;
          row.max_real = maxReal(lin.eigenvalues);
          row.steady_residual = lin.steady_residual;
          row.symmetry_residual = lin.symmetry_residual;
          row.constraint_residual = lin.constraint_residual;
        });
        return linearizeColumns(rows, base);
      }, "scene"_a, "cases"_a, py::kw_only(), "formulation"_a = py::none(), "tau"_a = py::none(),
      "time"_a = 0.0, "cyclic"_a = py::tuple(), "fd_step"_a = 1e-5, "rank_tolerance"_a = 1e-9,
      "check_signals"_a = false,
      "apply_overrides(scene, case) then linearize at its initial state, for every case, the GIL released "
      "for the whole batch: a dict of columns, one entry per case (appell.sweep's batches).");
}

}  // namespace

void bindSweep(py::module_& m) {
  bindRunBatch(m);
  bindLinearizeBatch(m);
}

}  // namespace appell::python
