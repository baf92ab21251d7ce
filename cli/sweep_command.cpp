// A sweep's cases run and tabulated (sweep_command.hpp): one row per case,
// the columns of `appell sweep --help`.
#include "sweep_command.hpp"

#include "linearize_analysis.hpp"
#include "overrides.hpp"
#include "sigint.hpp"
#include "sweep_table.hpp"

#include <appell/contact_events.hpp>
#include <appell/joint_types.hpp>
#include <appell/urdf.hpp>

#include <algorithm>
#include <chrono>
#include <iomanip>
#include <iostream>

namespace appell::cli {

std::vector<std::pair<std::string, std::string>> fixedOverrides(const Args& args) {
  std::vector<std::pair<std::string, std::string>> out;
  for (const std::string& set : args.all("set")) {
    const auto eq = set.find('=');
    if (eq == std::string::npos || eq == 0) throw UsageError("--set expects NAME=VALUE, got '" + set + "'");
    out.emplace_back(set.substr(0, eq), set.substr(eq + 1));
  }
  return out;
}

SweepSetup oneAxisSetup(Scene loaded, const Args& args) {
  SweepSetup setup;
  setup.axes = {parseSweepAxis("--sweep", args.text("sweep"))};
  if (setup.axes[0].random())
    throw UsageError("--sweep " + setup.axes[0].name + ": takes START:STOP:COUNT; random draws are appell sweep's "
                     "--vary NAME=uniform(LOW,HIGH)");
  setup.cases = sweepCases(setup.axes, 1, 0);
  setup.fixed = fixedOverrides(args);
  setup.base = std::move(loaded);
  checkSweepNames(setup, "--sweep");
  setup.project_initial = args.has("project-initial");
  return setup;
}

Scene caseScene(const SweepSetup& s, const SweepCase& c, bool check) {
  Scene scene = s.base;
  OverrideReport report;
  for (const auto& [name, value] : s.fixed) applyOverride(scene, name, value, report);
  for (std::size_t i = 0; i < s.axes.size(); ++i) appell::applyOverride(scene, s.axes[i].name, {c[i]}, report);
  completeSetVelocities(scene, report);
  if (check) checkInitialState(scene, s.project_initial, LoadOptions().initial_state_tolerance);
  return scene;
}

void checkSweepNames(const SweepSetup& s, const std::string& option) {
  Scene probe = s.base;
  OverrideReport report;
  for (const auto& [name, value] : s.fixed) applyOverride(probe, name, value, report);
  for (std::size_t i = 0; i < s.axes.size(); ++i) {
    try {
      appell::applyOverride(probe, s.axes[i].name, {s.cases.front()[i]}, report);
    } catch (const std::invalid_argument& e) {
      throw UsageError(option + " " + e.what());
    }
  }
}

namespace {

void putState(SweepRow& row, const Model& model, const VecX& q, const VecX& v) {
  const std::vector<std::string> qn = coordinateNames(model, false), vn = coordinateNames(model, true);
  for (int i = 0; i < q.size(); ++i) row["q:" + qn[i]] = Cell::of(q[i]);
  for (int i = 0; i < v.size(); ++i) row["v:" + vn[i]] = Cell::of(v[i]);
}

// One run: the summary's numbers and the final state.
void runCase(const SweepSetup& s, const SweepCase& c, const std::atomic<bool>& stop, SweepRow& row) {
  const Scene scene = caseScene(s, c, true);
  RunOptions options = s.run;
  options.stop = &stop;
  VecX q(scene.model.nq), v(scene.model.nv);  // assigned in place: no allocation per sample
  double energy = 0;
  const RunSummary r = runScene(scene, options, [&](const Simulator& sim) {
    q = sim.q();
    v = sim.v();
    energy = sim.energy();
  });
  row["status"] = Cell::ofText(r.interrupted ? "interrupted" : r.ok ? "ok" : "failed");
  row["message"] = Cell::ofText(r.failure);
  row["time"] = Cell::of(r.time);
  row["steps"] = Cell::ofCount(r.counters.steps);
  row["events"] = Cell::ofCount(static_cast<long>(r.events.size()));
  for (const auto& kind : contactEventKindTable())
    row[std::string("events_") + kind.name] = Cell::ofCount(std::count_if(
        r.events.begin(), r.events.end(), [&](const RunEvent& e) { return e.kind == kind.value; }));
  row["energy0"] = Cell::of(r.energy0);
  row["energy"] = Cell::of(energy);
  row["joint_work"] = Cell::of(r.joint_work);
  row["support_work"] = Cell::of(r.support_work);
  row["impact_energy_loss"] = Cell::of(r.impact_energy_loss);
  row["friction_work"] = Cell::of(r.friction_work);
  row["max_energy_deviation"] = Cell::of(r.max_energy_deviation);
  row["relative_energy_deviation"] = Cell::of(r.relativeEnergyDeviation());
  row["max_velocity_residual"] = Cell::of(r.max_velocity_residual);
  row["max_gap_residual"] = Cell::of(r.max_gap_residual);
  putState(row, scene.model, q, v);
}

// One linearization at the case's state: the verdict, the residuals, the eigenvalues.
void linearizeCase(const SweepSetup& s, const SweepCase& c, const Args& args, SweepRow& row) {
  const Scene scene = caseScene(s, c, !args.has("equilibrium"));
  const Analysis a = analyse(scene, args, s.cyclic, s.form, false);
  row["status"] = Cell::ofText(a.ok ? "ok" : "failed");
  row["message"] = Cell::ofText(a.message);
  row["verdict"] = Cell::ofText(verdict(a));
  row["max_real"] = Cell::of(a.max_real);
  row["zero_eigenvalues"] = Cell::ofCount(a.zeros);
  row["dimension"] = Cell::ofCount(a.result.dimension);
  row["constraint_residual"] = Cell::of(a.result.constraint_residual);
  row["steady_residual"] = Cell::of(a.result.steady_residual);
  row["symmetry_residual"] = Cell::of(a.result.symmetry_residual);
  if (a.family) row["family_residual"] = Cell::of(a.family_residual);
  putState(row, scene.model, scene.q0, scene.v0);
  for (std::size_t i = 0; i < a.eigenvalues.size(); ++i) {
    row["re" + std::to_string(i)] = Cell::of(a.eigenvalues[i].real());
    row["im" + std::to_string(i)] = Cell::of(a.eigenvalues[i].imag());
  }
}

std::vector<std::string> columnsOf(const SweepSetup& s, const Args& args, const std::vector<SweepRow>& rows) {
  std::vector<std::string> cols;
  for (const SweepAxis& a : s.axes) cols.push_back(a.name);
  cols.insert(cols.end(), {"status", "message"});
  if (s.linearize) {
    cols.insert(cols.end(), {"verdict", "max_real", "zero_eigenvalues", "dimension", "constraint_residual",
                             "steady_residual", "symmetry_residual"});
    if (args.has("family")) cols.push_back("family_residual");
  } else {
    cols.insert(cols.end(), {"time", "steps", "events"});
    for (const auto& kind : contactEventKindTable()) cols.push_back(std::string("events_") + kind.name);
    cols.insert(cols.end(), {"energy0", "energy", "joint_work", "support_work", "impact_energy_loss",
                             "friction_work", "max_energy_deviation", "relative_energy_deviation",
                             "max_velocity_residual", "max_gap_residual"});
  }
  for (const std::string& n : coordinateNames(s.base.model, false)) cols.push_back("q:" + n);
  for (const std::string& n : coordinateNames(s.base.model, true)) cols.push_back("v:" + n);
  std::size_t eigen = 0;  // the widest spectrum of any case
  while (std::any_of(rows.begin(), rows.end(), [&](const SweepRow& r) { return r.count("re" + std::to_string(eigen)); }))
    ++eigen;
  for (std::size_t i = 0; i < eigen; ++i) cols.insert(cols.end(), {"re" + std::to_string(i), "im" + std::to_string(i)});
  if (s.timing) cols.push_back("wall_seconds");
  return cols;
}

// run --sweep's text table: a line per case.
void writeText(const SweepSetup& s, unsigned jobs, const SweepTable& t, std::ostream& out) {
  const std::string& name = s.axes.front().name;
  out << "scene " << s.base.source << ": " << t.rows.size() << " runs of " << name << " on " << jobs << " threads\n";
  for (std::size_t k = 0; k < t.rows.size(); ++k) {
    const SweepRow& r = t.rows[k];
    const std::string status = r.at("status").text, message = r.count("message") ? r.at("message").text : "";
    out << "  " << name << " = " << std::setprecision(8) << s.cases[k][0] << ": " << status;
    if (status == "error") out << " (" << message << ")";
    else if (status == "failed") out << " at t = " << r.at("time").number << " (" << message << ")";
    else if (status != "not run")
      out << ", |E balance| ≤ " << r.at("max_energy_deviation").number << " J, residual ≤ "
          << std::max(r.at("max_velocity_residual").number, r.at("max_gap_residual").number);
    out << "\n";
  }
}

}  // namespace

int runSweepTable(const SweepSetup& s, unsigned jobs, const std::string& format, const Args& args,
                  std::ostream& out) {
  const SigintGuard sigint_guard;
  SweepTable table;
  table.rows.resize(s.cases.size());
  const CaseOutcome done = forEachCase(s.cases.size(), jobs, [&](std::size_t k) {
    const auto start = std::chrono::steady_clock::now();
    SweepRow& row = table.rows[k];
    try {
      if (s.linearize) linearizeCase(s, s.cases[k], args, row);
      else runCase(s, s.cases[k], sigint_guard.flag(), row);
    } catch (const std::exception&) {
      row.clear();  // a case that threw has no numbers, only its error (CaseOutcome)
      throw;
    }
    row["wall_seconds"] = Cell::of(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }, &sigint_guard.flag());
  bool all_ok = true;
  for (std::size_t k = 0; k < s.cases.size(); ++k) {
    SweepRow& row = table.rows[k];
    for (std::size_t i = 0; i < s.axes.size(); ++i) row[s.axes[i].name] = Cell::of(s.cases[k][i]);
    if (!done.started[k]) row["status"] = Cell::ofText("not run");
    if (!done.errors[k].empty()) {
      row["status"] = Cell::ofText("error");
      row["message"] = Cell::ofText(done.errors[k]);
    }
    if (!s.timing) row.erase("wall_seconds");
    all_ok = all_ok && row.at("status").text == "ok";
  }
  table.columns = columnsOf(s, args, table.rows);
  if (format == "text") writeText(s, jobs, table, out);
  else if (format == "csv") table.writeCsv(out);
  else {
    std::vector<std::pair<std::string, std::string>> head = {
        {"scene", jsonString(s.base.source)}, {"analysis", s.linearize ? "\"linearize\"" : "\"run\""}};
    if (s.random) head.emplace_back("seed", std::to_string(s.seed));
    table.writeJson(out, head);
  }
  if (sigint_guard.flag().load()) {
    std::cerr << "appell: interrupted (SIGINT): the cases finished before it are listed\n";
    return kInterrupted;
  }
  return all_ok ? 0 : 3;
}

}  // namespace appell::cli
