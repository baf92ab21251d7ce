// appell sweep: many cases of one scene through `run` or `linearize` — a grid
// of override values (several names: every combination) or seeded random
// draws — on N threads, one row per case in case order, as CSV or JSON.
// Each case is the computation of `appell run` / `appell linearize` with the
// same --set options and its values added as --set NAME=VALUE: a copy of the
// scene as loaded, the fixed overrides then the case's, the velocities
// completed once, the initial state checked; so a row equals that single
// run bit for bit, whatever -j. A case that fails is a row with its status
// and message; the sweep goes on.
#include "commands.hpp"
#include "linearize_analysis.hpp"
#include "run_options.hpp"
#include "sweep_command.hpp"
#include "sweep_engine.hpp"
#include "sweep_table.hpp"

#include <appell/output.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>

namespace appell::cli {

namespace {

const char* kSweepHelp = R"(usage: appell sweep SCENE.urdf --vary NAME=SPEC [--vary …] [options]

Runs one case per value (or combination of values) of scene overrides
through `appell run` (default) or `appell linearize`, on -j threads, and
writes one row per case — the values, how the case ended, its numbers —
as CSV (default) or JSON on standard output (or --out FILE).

  --vary NAME=START:STOP:COUNT   COUNT evenly spaced values (a grid axis);
                      several grid axes: every combination, the last varying
                      fastest
  --vary NAME=uniform(LOW,HIGH)  a random value in [LOW, HIGH) per case
  --vary NAME=normal(MEAN,SD)    a normal random value per case
                      (quote the parentheses from the shell:
                      --vary 'speed=uniform(1,3)')
  --samples N         draws of the random axes (for each grid point; default 1)
  --seed S            the random stream's seed (default 0): the same seed, the
                      same cases on every machine (mt19937_64, 53-bit uniforms,
                      Box–Muller)
                      NAME is any one-number name of --set: speed,
                      <joint>.position, <joint>.velocity, <joint>.effort,
                      <contact>.mu, a coordinate by its CSV name
  --set NAME=VALUE    a fixed override for every case (repeatable), applied
                      before the varied ones
  --analysis A        run (default) or linearize
  -j N, --jobs N      threads (default: the cores); the rows and their numbers
                      do not depend on N
  --format F          csv (default) or json;  --json is --format json
  --out FILE          write the table to FILE instead of standard output
  --no-timing         leave out the wall_seconds column: the output is then
                      byte for byte the same for every -j

  with --analysis run: --duration, --dt, --tol, --integrator, --formulation,
  --contacts, --every, --max-energy-error, --max-residual, --settle-time,
  --no-projection, --project-initial as for `appell run`
  with --analysis linearize: --cyclic, --equilibrium, --family, --zero-tol,
  --fd-step, --formulation as for `appell linearize`
  loading: --package-path, --no-joint-limits, --snap-angles, --balance-inertia,
  --bound-inertia, --bound-mass

Columns (run): the varied names, status (ok, failed, error, interrupted, not
run), message, time, steps, events, events_<kind> per kind, energy0, energy
(at the end), joint_work, support_work, impact_energy_loss, friction_work,
max_energy_deviation, relative_energy_deviation, max_velocity_residual,
max_gap_residual, q:<coordinate>…, v:<coordinate>… (the final state),
wall_seconds. (linearize): the varied names, status, message, verdict
(unstable, not growing, none), max_real, zero_eigenvalues, dimension,
constraint_residual, steady_residual, symmetry_residual, family_residual
(with --family), q:…, v:… (the reference state), re0, im0, re1, im1, …
(eigenvalues, largest real part first), wall_seconds.

Exit status: 0 every case ok, 3 some case failed or raised an error (its row
says why), 1 bad input, 2 usage, 130 interrupted (rows of the cases not
started say "not run").
)";

// -j N and -jN as --jobs N: the one short option (make's, ninja's).
std::vector<std::string> withLongJobs(int argc, char** argv) {
  std::vector<std::string> out(argv, argv + argc);
  for (std::string& a : out)
    if (a == "-j") a = "--jobs";
    else if (a.rfind("-j", 0) == 0 && a.size() > 2 && a[2] != '-') a = "--jobs=" + a.substr(2);
  return out;
}

void refuseOtherAnalysisOptions(const Args& args, bool linearize) {
  static const std::set<std::string> run_only = {"duration", "dt", "tol", "integrator", "contacts", "every",
                                                 "max-energy-error", "max-residual", "settle-time",
                                                 "no-projection"};
  static const std::set<std::string> lin_only = {"cyclic", "equilibrium", "family", "zero-tol", "fd-step"};
  for (const std::string& o : linearize ? run_only : lin_only)
    if (args.has(o))
      throw UsageError("--" + o + " applies to --analysis " + (linearize ? "run" : "linearize"));
}

SweepSetup setupFromArgs(const Args& args) {
  SweepSetup s;
  const std::string analysis = args.text("analysis", "run");
  if (analysis != "run" && analysis != "linearize")
    throw UsageError("--analysis must be run or linearize, not '" + analysis + "'");
  s.linearize = analysis == "linearize";
  refuseOtherAnalysisOptions(args, s.linearize);
  if (args.all("vary").empty())
    throw UsageError("give at least one --vary NAME=START:STOP:COUNT (or NAME=uniform(LOW,HIGH))");
  for (const std::string& spec : args.all("vary")) {
    s.axes.push_back(parseSweepAxis("--vary", spec));
    for (std::size_t i = 0; i + 1 < s.axes.size(); ++i)
      if (s.axes[i].name == s.axes.back().name) throw UsageError("--vary " + s.axes.back().name + ": given twice");
  }
  const double samples = args.number("samples", 1), seed = args.number("seed", 0);
  if (samples != std::floor(samples) || samples < 1 || samples > 1e7)
    throw UsageError("--samples must be a whole number from 1 to 10000000, not '" + args.text("samples") + "'");
  if (seed != std::floor(seed) || seed < 0 || seed > 9.007199254740992e15)
    throw UsageError("--seed must be a whole number ≥ 0, not '" + args.text("seed") + "'");
  s.seed = static_cast<std::uint64_t>(seed);
  s.random = std::any_of(s.axes.begin(), s.axes.end(), [](const SweepAxis& a) { return a.random(); });
  if (args.has("seed") && !s.random) throw UsageError("--seed seeds random draws: no --vary is uniform(…) or normal(…)");
  s.cases = sweepCases(s.axes, static_cast<long>(samples), s.seed);
  s.fixed = fixedOverrides(args);
  s.base = loadFromArgs(args, false);  // each case's state is checked after its overrides
  checkSweepNames(s, "--vary");
  s.project_initial = args.has("project-initial");
  s.timing = !args.has("no-timing");
  if (s.linearize) {
    s.cyclic = cyclicCoordinates(s.base, args);
    s.form = linearizeFormulation(s.base, args);
    if (args.has("family") && args.has("equilibrium"))
      throw UsageError("--family removes a steady motion's own direction; an equilibrium (v = 0) has none");
  } else {
    s.run = runOptionsFromArgs(s.base, args);
  }
  return s;
}

}  // namespace

int sweep(int argc, char** argv) {
  std::vector<std::string> words = withLongJobs(argc, argv);
  std::vector<char*> argv_long;
  for (std::string& w : words) argv_long.push_back(w.data());
  std::set<std::string> valued = {"vary", "samples", "seed", "set", "analysis", "jobs", "format", "out",
                                  "cyclic", "zero-tol", "fd-step", "package-path", "bound-inertia",
                                  "bound-mass", "snap-angles"};
  valued.insert(kRunOptionNames.begin(), kRunOptionNames.end());
  const Args args(argc, argv_long.data(), 2, valued,
                  {"help", "json", "no-timing", "no-projection", "project-initial", "no-joint-limits",
                   "balance-inertia", "equilibrium", "family"});
  if (args.has("help")) {
    std::cout << kSweepHelp;
    return 0;
  }
  std::string format = args.text("format", "csv");
  if (args.has("json")) {
    if (args.has("format") && format != "json") throw UsageError("--json and --format " + format + " disagree");
    format = "json";
  }
  if (format != "csv" && format != "json") throw UsageError("--format must be csv or json, not '" + format + "'");
  const SweepSetup setup = setupFromArgs(args);
  const int jobs = args.integer("jobs", static_cast<int>(defaultJobs(setup.cases.size())));
  if (jobs < 1) throw UsageError("-j/--jobs must be at least 1, not " + args.text("jobs"));
  std::ofstream file;
  if (args.has("out")) {
    refuseOverwritingInputs("out", args.text("out"), setup.base);
    file.open(args.text("out"));
    if (!file) throw std::runtime_error("cannot write '" + args.text("out") + "'");
  }
  std::ostream& out = args.has("out") ? static_cast<std::ostream&>(file) : std::cout;
  const int status = runSweepTable(setup, static_cast<unsigned>(jobs), format, args, out);
  if (args.has("out")) {
    file.flush();
    if (!file) throw std::runtime_error("writing the table '" + args.text("out") + "' failed (disk full or not writable)");
  }
  return status;
}

}  // namespace appell::cli
