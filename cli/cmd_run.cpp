// appell run: the options of a run (run.hpp) from the command line, and its
// summary printed.
#include "commands.hpp"
#include "overrides.hpp"
#include "plot.hpp"
#include "run_options.hpp"
#include "sigint.hpp"
#include "sweep_command.hpp"
#include "sweep_engine.hpp"

#include <appell/output.hpp>
#include <appell/run.hpp>

#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>

namespace appell::cli {

namespace {

const char* kRunHelp = R"(usage: appell run SCENE.urdf [options]

  --duration T        simulated time in seconds (default: the scene's)
  --dt H              fixed step (euler, leapfrog, rk4), first step (dopri5,
                      dop853)
  --tol TOL           relative tolerance of the adaptive integrators (dopri5,
                      dop853); giving --tol without --integrator selects
                      dopri5 unless the scene's integrator is adaptive
  --integrator NAME   {integrators}
  --formulation F     {formulations}   (default: the scene's, else tree)
  --contacts S        {contact_schemes}   how unilateral contacts are
                      handled (default: the scene's, else auto): events
                      locates every touchdown, lift-off, slip and stick and is
                      exact between them; timestepping takes Moreau–Jean
                      impulse steps of 1 ms (never stalls, O(h)); auto runs
                      events and switches to time-stepping windows where a
                      mode decision fails, events pile up or the steps
                      collapse (docs/contacts.md §10)
  --out FILE.csv      write the trajectory (every step, or every --every N)
  --every N           write every N-th step to the CSV (default 1)
  --plot              plot the trajectory at the end (as `appell plot`, into
                      the folder FILE_plots beside --out FILE.csv)
  --no-projection     do not project onto the constraints after each step
  --package-path DIRS colon/comma-separated folders for package:// meshes
  --project-initial   project an initial state that violates the constraints
  --no-joint-limits   ignore the URDF position limits of revolute and prismatic
                      joints (by default each finite one is a unilateral
                      constraint: the joint stops or bounces there)
  --snap-angles TOL   snap origin angles within TOL rad of a multiple of π/2
                      (CAD rounding: rpy="-1.57"), each change reported
)" APPELL_INERTIA_HELP R"(  --quiet             no progress (a bar on a terminal, else a line every 10 s)
  --max-energy-error E  stop when the work balance (E + impact and friction
                      losses − work of joint forces and moving supports − E0)
                      is off by more than E relative, keeping the last state
                      within it: the integration is diverging (default 0.05;
                      inf switches the watch off)
  --max-residual R    stop when the constraint residual (max |Av+b|, |gap|)
                      exceeds R, keeping the last state within it (default
                      1e-6; inf switches the watch off)
  --settle-time T     a sliding contact whose slip direction settles faster
                      than T seconds slides on its settled direction (a
                      misaligned axle's scrub, a slip just starting; error
                      about T times that direction's turning rate); 0: the
                      exact sliding law throughout (default 1e-4)
  --sweep NAME=START:STOP:COUNT
                      one run per value of a one-number override, on every
                      core (no trajectory): the table of `appell sweep SCENE
                      --vary NAME=START:STOP:COUNT` (see appell sweep --help:
                      grids of several names, random draws, -j, its columns)
  --format F          with --sweep: text (default), csv or json at full precision
  --set NAME=VALUE    override the initial state or a parameter (repeatable):
                      gravity=gx,gy,gz, speed=V (a floating base's forward
                      speed), <joint>.position=…, <joint>.velocity=…,
                      <joint>.effort=… (constant joint forces), <contact>.mu=μ,
                      or a coordinate by its CSV name; velocities set are kept
                      and the others change as little as the constraints
                      allow; the summary lists each override and every
                      velocity the constraints changed

Exit status: 0 success, 1 bad input or an output that could not be written,
130 interrupted (SIGINT: the summary and the trajectory up to the state reached
are written), 2 usage, 3 the simulation failed (the
summary says why and at what time; the trajectory up to there is written).
)";

// Progress on stderr: on a terminal a bar with the simulated time, the rate
// (simulated seconds per wall second) and the time left at that rate; into a
// file or pipe a line every 10 s of wall time — a long run is never silent.
class Progress {
 public:
  Progress(double total, bool enabled)
      : total_(total), enabled_(enabled), tty_(isatty(2) != 0), start_(Clock::now()), last_line_(start_) {}
  void update(double t) {
    if (!enabled_) return;
    const Clock::time_point now = Clock::now();
    const double wall = std::chrono::duration<double>(now - start_).count();
    const double rate = wall > 0 ? t / wall : 0;
    const double eta = rate > 0 ? (total_ - t) / rate : 0;
    if (!tty_) {
      if (std::chrono::duration<double>(now - last_line_).count() < 10) return;
      last_line_ = now;
      std::cerr << "appell: t = " << t << " s of " << total_ << " s, " << rate
                << " x real time, about " << eta << " s left\n" << std::flush;
      return;
    }
    const int pct = static_cast<int>(100.0 * t / total_);
    if (pct == last_ && std::chrono::duration<double>(now - last_line_).count() < 1) return;
    last_ = pct;
    last_line_ = now;
    const int w = 30, filled = w * std::clamp(pct, 0, 100) / 100;
    std::cerr << "\r[" << std::string(filled, '#') << std::string(w - filled, ' ') << "] "
              << std::setw(3) << pct << "%  t = " << std::setprecision(4) << t << " s  "
              << rate << "x  ETA " << std::setprecision(3) << eta << " s   " << std::flush;
  }
  void done() {
    if (enabled_ && tty_ && last_ >= 0) std::cerr << "\r" << std::string(78, ' ') << "\r";
  }

 private:
  using Clock = std::chrono::steady_clock;
  double total_;
  bool enabled_, tty_;
  int last_ = -1;
  Clock::time_point start_, last_line_;
};

// The per-contact lines of the summary.
void printContacts(std::ostream& out, const RunSummary& r) {
  if (r.contacts.empty()) return;
  out << "contacts (over " << r.samples << " samples):\n";
  // Constraints never closed (a joint limit the motion never reached) are
  // one line, not one each: a robot has two limits per joint.
  auto never_closed = [](const ContactStats& e) {
    return e.normal_row >= 0 && !e.normal_held && e.min_normal > e.max_normal;
  };
  int open = 0;
  std::string open_names;
  for (const ContactStats& e : r.contacts) {
    if (!never_closed(e)) continue;
    if (++open <= 4) open_names += (open_names.empty() ? "" : ", ") + e.name;
  }
  for (const ContactStats& e : r.contacts) {
    if (never_closed(e)) continue;
    out << "  " << std::left << std::setw(24) << e.name << std::right;
    if (e.normal_row < 0) {
      if (e.reaction_row >= 0 && e.min_reaction <= e.max_reaction)
        out << std::setprecision(4) << " reaction " << e.min_reaction << " … " << e.max_reaction
            << " (generalized force on its joint: N·m or N)\n";
      else
        out << " (no normal row)\n";
      continue;
    }
    if (e.normal_held) {
      out << " normal held by the joints (its row moves nothing: redundant by construction)\n";
      continue;
    }
    out << std::setprecision(4) << " normal load " << e.min_normal << " … " << e.max_normal << " N";
    if (!e.tangential_rows.empty()) {
      out << ", friction demand max " << e.max_demand << " at t=" << e.t_max_demand;
      if (std::isfinite(e.mu) && e.creep_speed > 0)
        out << " (μ = " << e.mu << ", creeping below " << e.creep_speed << " m/s)";
      else if (std::isfinite(e.mu))
        out << " (μ = " << e.mu << ")";
    }
    if (e.sliding_samples)
      out << "; sliding in " << e.sliding_samples << " samples, slip speed max " << e.max_slip
          << " m/s";
    if (e.over_mu)
      out << "  ⚠ exceeds μ in " << e.over_mu << " samples from t=" << e.first_slip << ": would slip";
    if (e.pulling)
      out << "  ⚠ normal pulls in " << e.pulling << " samples from t=" << e.first_pull
          << ": would lift off";
    if (e.open_samples) out << "; open in " << e.open_samples << " samples";
    out << "\n";
  }
  if (open > 0)
    out << "  open throughout: " << open << (open == 1 ? " constraint (" : " constraints (")
        << open_names << (open > 4 ? ", …" : "") << ")\n";
}

// A work term as the summary prints it: in full (the shortest text that
// reads back as the same double), so a balance can be checked from the
// printout.
std::string joule(double x) {
  char buf[40];
  const auto end = std::to_chars(buf, buf + sizeof buf, x).ptr;
  return std::string(buf, end) + " J";
}

// The kinetic energy the impacts took: 0 exactly when no event had an
// impulse (lift-offs, slips, sticks and piece changes take none; the
// engine's sum over them is round-off, −1e-32 J and the like).
double impactLoss(const RunSummary& r) {
  const bool any_impulse = std::any_of(r.events.begin(), r.events.end(),
                                       [](const RunEvent& e) { return e.normal_impulse != 0; });
  return any_impulse ? r.impact_energy_loss : 0.0;
}

// One line per contact event (at most the first 50, then a count).
void printEvents(std::ostream& out, const RunSummary& r) {
  if (r.events.empty()) return;
  out << "contact events (" << r.events.size() << "; impacts took " << joule(impactLoss(r)) << "):\n";
  const std::size_t shown = std::min<std::size_t>(r.events.size(), 50);
  for (std::size_t k = 0; k < shown; ++k) {
    const RunEvent& e = r.events[k];
    out << "  t = " << std::setprecision(12) << std::left << std::setw(16) << e.t << std::right
        << std::setprecision(6) << std::setw(10) << toString(e.kind) << "  " << e.contact;
    if (e.kind != ContactEventKind::LiftOff && e.speed_before < 0)
      out << "  normal speed " << e.speed_before << " → " << e.speed_after << " m/s, impulse "
          << e.normal_impulse << " N·s";
    if (!e.piece.empty()) out << "  onto " << e.piece;
    if (e.outside_friction_cone)
      out << "  ⚠ tangential impulse " << e.tangential_impulse
          << " outside the friction cone: would slip";
    out << "\n";
  }
  if (shown < r.events.size()) out << "  … " << r.events.size() - shown << " more\n";
}

void printSummary(std::ostream& out, const Scene& scene, const RunSummary& r,
                  const std::vector<std::string>& overrides) {
  const RunOptions& o = r.options;
  const SimulatorCounters& c = r.counters;
  const bool adaptive = adaptiveIntegrator(o.integrator);
  out << std::setprecision(6) << "scene        " << scene.source << "\n";
  if (scene.robot_source != scene.source) out << "robot        " << scene.robot_source << "\n";
  for (const std::string& line : overrides) out << "override     " << line << "\n";
  out
      << "model        " << scene.model.nbodies << " bodies, nv = " << scene.model.nv << ", "
      << scene.contacts.size() << " contacts, ";
  if (!scene.joint_limits.empty()) out << scene.joint_limits.size() << " joint limits, ";
  if (!scene.couplings.empty()) out << scene.couplings.size() << " mimic couplings, ";
  out << scene.constraintRows() << " rows\n";
  // The load's warnings (an inertia loaded with a defect or repaired, a
  // missing visual mesh) went to stderr before the run; the summary counts them.
  if (!scene.warnings.empty())
    out << "warnings     " << scene.warnings.size() << " at load, printed before the run\n";
  out << "method       " << toString(o.integrator) << (adaptive ? " (tol " : " (dt ")
      << (adaptive ? o.tol : o.dt) << "), formulation " << toString(o.formulation) << "\n"
      << "simulated    " << r.time << " s in " << c.steps << " steps";
  if (c.rejected) out << " (" << c.rejected << " rejected)";
  out << ", " << c.evaluations << " dynamics solves\n";
  if (c.timestepping_steps > 0 || o.contacts != ContactScheme::Auto)
    out << "contacts     " << toString(o.contacts) << " scheme: " << c.timestepping_steps
        << " time-stepping steps in " << c.windows << " windows, contact problems to "
        << c.max_contact_residual << " m/s"
        << (c.unconverged ? " (" + std::to_string(c.unconverged) + " at max sweeps)" : std::string())
        << ", closed gaps within " << c.max_contact_gap << " m\n";
  out << "wall time    " << r.wall_seconds << " s, "
      << 1e6 * r.wall_seconds / std::max<long>(1, c.steps) << " µs per step\n"
      << "energy       E0 = " << r.energy0 << " J, max |E "
      << (r.events.empty() && impactLoss(r) == 0 ? "" : "+ impact losses ")
      << (r.friction_work > 0 ? "+ friction work " : "")
      << (r.scheme_energy_loss != 0 ? "+ time-stepping loss " : "")
      << (r.passive ? "" : "− work in ") << "− E0| = " << r.max_energy_deviation
      << " J (" << r.relativeEnergyDeviation() << " relative)\n";
  if (!r.passive || r.friction_work > 0 || impactLoss(r) > 0)
    out << "work         joint forces " << joule(r.joint_work) << ", moving supports "
        << joule(r.support_work) << " in; impacts " << joule(impactLoss(r)) << ", friction "
        << joule(r.friction_work)
        << (r.scheme_energy_loss != 0 ? ", time-stepping (θ) " + joule(r.scheme_energy_loss) : std::string())
        << " out\n";
  out
      << "residuals    max |Av+b| = " << r.max_velocity_residual
      << ", max |gap| = " << r.max_gap_residual
      << (o.project_velocities ? "" : "  [projection off]") << "\n"
      << "redundant    " << r.max_redundant << " rows\n"
      << "freedom      " << r.free_velocities << " independent velocities at t = 0";
  if (r.free_velocities == 0 && scene.model.nv > 0 && r.can_slip)
    out << " while its contacts stick: it moves only by slipping where μ is finite";
  else if (r.free_velocities == 0 && scene.model.nv > 0)
    out << "  ⚠ the constraints hold every body still: nothing can move (an over-constrained "
           "vehicle — axles out of line by a CAD export's round-off make its no-slip rows "
           "independent; give its wheels a friction coefficient 'mu' so they can scrub, or "
           "align them)";
  out << "\n";
  if (const NearDependency& d = r.near_dependency; d.found) {
    out << "margin       ⚠ rows";
    for (std::size_t k = 0; k < d.rows.size(); ++k) out << (k ? ", " : " ") << d.rows[k];
    out << " are independent only by σ = " << d.sigma << " (" << d.margin()
        << " × the rank threshold " << d.threshold << ") at t = " << d.t << " s (first at t = "
        << d.t_first << " s; " << d.samples << " of " << d.checks
        << " checks): they lock the motion";
    for (const auto& [name, share] : d.freedom) out << " " << name << " " << share;
    out << " — CAD rounding? (--snap-angles)\n";
  }
  out << "events       ";
  int events = 0;
  if (r.partition_changes) {
    out << r.partition_changes << " re-choices of the velocity partition; ";
    ++events;
  }
  if (!r.events.empty()) {
    out << r.events.size() << " contact events (below); ";
    ++events;
  }
  if (r.flaggedContacts()) {
    out << r.flaggedContacts() << " contacts flagged (below); ";
    ++events;
  }
  if (!r.ok) {
    out << "FAILED at t = " << r.time << " s: " << r.failure << " (last good state kept)";
    ++events;
  }
  out << (events ? "\n" : "none\n");
  printEvents(out, r);
  printContacts(out, r);
  if (!r.actuators.empty()) {
    out << "actuators (over " << r.samples << " samples):\n";
    for (const RunSummary::ActuatorStats& a : r.actuators) {
      out << "  " << std::left << std::setw(24) << a.name << std::right << std::setprecision(4)
          << " |τ| up to " << a.max_force;
      if (std::isfinite(a.effort_limit)) out << " of " << a.effort_limit;
      if (a.saturated)
        out << ", saturated in " << a.saturated << " samples (t = " << a.first_saturated << " … "
            << a.last_saturated << ")";
      out << "\n";
    }
  }
}

}  // namespace

// --sweep NAME=START:STOP:COUNT: appell sweep's table (sweep_command.hpp)
// for one grid axis, its columns included, printed as text (a line per run),
// csv or json.
int runSweep(const Args& args, const std::string& format) {
  if (args.has("out") || args.has("plot")) throw UsageError("--sweep writes a table, not a trajectory (--out, --plot)");
  // Each run's state is checked after its overrides, not at load.
  SweepSetup setup = oneAxisSetup(loadFromArgs(args, false), args);
  setup.run = runOptionsFromArgs(setup.base, args);
  return runSweepTable(setup, defaultJobs(setup.cases.size()), format, args, std::cout);
}

int run(int argc, char** argv) {
  Args args(argc, argv, 2,
            {"duration", "dt", "tol", "integrator", "formulation", "out", "every", "package-path",
             "bound-inertia", "bound-mass",
             "max-energy-error", "max-residual", "settle-time", "set", "sweep", "format", "snap-angles",
             "contacts"},
            {"project-initial", "no-joint-limits", "balance-inertia", "help", "no-projection", "quiet", "plot"});
  if (args.has("help")) {
    std::cout << helpText(kRunHelp);
    return 0;
  }
  const std::string format = args.text("format", "text");
  if (format != "text" && format != "csv" && format != "json")
    throw UsageError("--format must be text, csv or json, not '" + format + "'");
  if (args.has("format") && !args.has("sweep"))
    throw UsageError("--format applies to a --sweep's table (a single run's numbers are in --out's CSV)");
  if (args.has("sweep")) return runSweep(args, format);
  // Overrides change the state: check it after them, not at load.
  const bool overrides = !args.all("set").empty();
  Scene scene = loadFromArgs(args, !overrides);
  OverrideReport kept;
  if (overrides) {
    kept = applyOverrides(scene, args);
    checkInitialState(scene, args.has("project-initial"), LoadOptions().initial_state_tolerance);
  }
  if (args.has("plot") && !args.has("out")) throw UsageError("--plot plots the trajectory: give --out FILE.csv");
  RunOptions options = runOptionsFromArgs(scene, args);

  // SIGINT stops the run after the current step: the state reached is written
  // and flushed, the summary printed, and the exit status is 130.
  const SigintGuard sigint_guard;
  options.stop = &sigint_guard.flag();
  Progress progress(options.duration, !args.has("quiet"));
  auto on_step = [&](const Simulator& sim) { progress.update(sim.time()); };
  RunSummary summary;
  std::ofstream csv;
  std::unique_ptr<TrajectoryWriter> writer;
  if (args.has("out")) {
    refuseOverwritingInputs("out", args.text("out"), scene);
    csv.open(args.text("out"));
    if (!csv) throw std::runtime_error("cannot write '" + args.text("out") + "'");
    writer = std::make_unique<TrajectoryWriter>(csv, scene);
    summary = runScene(scene, options, *writer, on_step);
  } else {
    summary = runScene(scene, options, {}, on_step);
  }
  progress.done();

  printSummary(std::cout, scene, summary, describe(scene, kept));
  if (summary.free_velocities == 0 && scene.model.nv > 0 && !summary.can_slip)
    std::cerr << "appell run: warning: " << scene.source
              << ": the constraints leave 0 independent velocities — nothing in this scene can move "
                 "(see 'freedom' in the summary)\n";
  if (summary.interrupted)
    std::cout << "interrupted  at t = " << summary.time << " s (SIGINT): the summary and the trajectory "
              << "end there\n";
  if (writer) {
    csv.flush();
    // Every write is checked here, once: a full disk or a closed pipe is an
    // error naming the file, never a silent short trajectory.
    if (!csv) throw std::runtime_error("writing the trajectory '" + args.text("out") +
                                       "' failed (disk full or not writable): " +
                                       std::to_string(writer->samples()) + " rows were not all written");
    std::cout << "trajectory   " << args.text("out") << " (" << writer->samples() << " rows, "
              << writer->columns().size() << " columns)\n";
  }
  if (args.has("plot")) {
    csv.close();
    for (const std::string& png : writePlots(args.text("out"), defaultPlotDir(args.text("out")), &scene))
      std::cout << "plot         " << png << "\n";
  }
  if (summary.interrupted) return kInterrupted;
  return summary.ok ? 0 : 3;
}

}  // namespace appell::cli
