// appell run: simulate a scene, summarise it, write its trajectory.
#include "commands.hpp"
#include "contact_report.hpp"
#include "plot.hpp"

#include <appell/appell.hpp>
#include <appell/output.hpp>
#include <appell/simulator.hpp>

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>

namespace appell::cli {

namespace {

const char* kHelp = R"(usage: appell run SCENE.urdf [options]

  --duration T        simulated time in seconds (default: the scene's)
  --dt H              fixed step (euler, rk4), first step (dopri5)
  --tol TOL           relative tolerance of the adaptive integrator (dopri5);
                      giving --tol without --integrator selects dopri5
  --integrator NAME   {integrators}
  --formulation F     {formulations}   (default: the scene's, else tree)
  --out FILE.csv      write the trajectory (every step, or every --every N)
  --every N           write every N-th step to the CSV (default 1)
  --plot              plot the trajectory at the end (as `appell plot`, into
                      the folder FILE_plots beside --out FILE.csv)
  --no-projection     do not project onto the constraints after each step
  --package-path DIRS colon/comma-separated folders for package:// meshes
  --project-initial   project an initial state that violates the constraints
  --quiet             no progress bar

Exit status: 0 success, 1 bad input, 2 usage, 3 the simulation failed (the
summary says why and at what time; the trajectory up to there is written).
)";

bool passiveScene(const Scene& scene) {
  if (scene.tau.size() && scene.tau.cwiseAbs().maxCoeff() > 0) return false;
  for (const Support& s : scene.supports)
    if (isMoving(s.motion)) return false;
  return true;
}

class Progress {
 public:
  Progress(double total, bool enabled) : total_(total), enabled_(enabled && isatty(2)) {}
  void update(double t) {
    if (!enabled_) return;
    const int pct = static_cast<int>(100.0 * t / total_);
    if (pct == last_) return;
    last_ = pct;
    const int w = 40, filled = w * pct / 100;
    std::cerr << "\r[" << std::string(filled, '#') << std::string(w - filled, ' ') << "] "
              << std::setw(3) << pct << "%  t = " << t << " s" << std::flush;
  }
  void done() {
    if (enabled_ && last_ >= 0) std::cerr << "\r" << std::string(70, ' ') << "\r";
  }

 private:
  double total_;
  bool enabled_;
  int last_ = -1;
};

}  // namespace

int run(int argc, char** argv) {
  Args args(argc, argv, 2,
            {"duration", "dt", "tol", "integrator", "formulation", "out", "every", "package-path"},
            {"project-initial", "help", "no-projection", "quiet", "plot"});
  if (args.has("help")) {
    std::cout << helpText(kHelp);
    return 0;
  }
  Scene scene = loadFromArgs(args);
  SimulationSettings s = scene.settings;
  s.duration = args.positiveNumber("duration", s.duration);
  s.dt = args.positiveNumber("dt", s.dt);
  s.tol = args.positiveNumber("tol", s.tol);
  if (args.has("tol") && !args.has("integrator"))
    s.integrator = toString(IntegratorType::DormandPrince54);
  s.integrator = args.text("integrator", s.integrator);
  s.formulation = args.text("formulation", s.formulation);
  const int every = args.integer("every", 1);
  if (args.has("plot") && !args.has("out")) throw UsageError("--plot plots the trajectory: give --out FILE.csv");
  if (every < 1) throw UsageError("option --every must be at least 1");
  IntegratorType itype;
  Formulation form;
  try {
    itype = integratorFromString(s.integrator);
    form = formulationFromString(s.formulation);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }

  IntegratorOptions iopt;
  iopt.rtol = s.tol;
  iopt.atol = s.tol * 1e-2;
  iopt.h_max = std::max(s.dt, s.duration / 20);
  SimulatorOptions sopt;
  sopt.project_positions = sopt.project_velocities = !args.has("no-projection");
  Simulator sim(scene.model, scene.constraints, makeSolver(form, scene.model, scene.constraints),
                itype, iopt, sopt);
  if (scene.tau.size() == scene.model.nv) {
    const VecX tau = scene.tau;
    sim.setJointForces([tau](double, const VecX&, const VecX&, VecX& out) { out = tau; });
  }
  sim.setState(0.0, scene.q0, scene.v0);  // after the forces: the t = 0 reactions include them

  std::ofstream csv;
  std::unique_ptr<TrajectoryWriter> writer;
  std::vector<ContactFrame> frames(scene.constraints.size());
  auto record = [&] {
    if (!writer) return;
    for (size_t k = 0; k < frames.size(); ++k) frames[k] = sim.contactFrame(static_cast<int>(k));
    writer->write(sim.time(), sim.q(), sim.v(), sim.energy(),
                  std::max(sim.velocityResidual(), sim.gapResidual()), frames, sim.lambda());
  };
  if (args.has("out")) {
    csv.open(args.text("out"));
    if (!csv) throw std::runtime_error("cannot write '" + args.text("out") + "'");
    writer = std::make_unique<TrajectoryWriter>(csv, scene);
  }

  ContactReport contacts(scene);
  const double E0 = sim.energy();
  const double energy_scale = std::max({std::abs(E0), sim.kineticEnergy(), 1e-12});
  double max_energy_dev = 0, max_vel_res = sim.velocityResidual(), max_gap_res = sim.gapResidual();
  int max_redundant = sim.redundantRows();
  contacts.sample(sim.time(), sim.lambda());
  record();

  Progress progress(s.duration, !args.has("quiet"));
  const auto wall0 = std::chrono::steady_clock::now();
  StepStatus status;
  double h = s.dt;
  long step = 0;
  while (sim.time() < s.duration * (1 - 1e-12)) {
    const double h_try = std::min(h, s.duration - sim.time());
    status = sim.step(h_try);
    if (!status.ok) break;
    ++step;
    if (itype == IntegratorType::DormandPrince54) h = status.h_next;
    max_energy_dev = std::max(max_energy_dev, std::abs(sim.energy() - E0));
    max_vel_res = std::max(max_vel_res, sim.velocityResidual());
    max_gap_res = std::max(max_gap_res, sim.gapResidual());
    max_redundant = std::max(max_redundant, sim.redundantRows());
    contacts.sample(sim.time(), sim.lambda());
    if (step % every == 0) record();
    progress.update(sim.time());
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  progress.done();
  if (writer && step % every != 0) record();

  const SimulatorCounters& c = sim.counters();
  std::cout << std::setprecision(6) << "scene        " << scene.source << "\n"
            << "model        " << scene.model.nbodies << " bodies, nv = " << scene.model.nv << ", "
            << scene.constraints.size() << " contacts, " << scene.constraintRows() << " rows\n"
            << "method       " << toString(itype)
            << (itype == IntegratorType::DormandPrince54 ? " (tol " : " (dt ")
            << (itype == IntegratorType::DormandPrince54 ? s.tol : s.dt)
            << "), formulation " << toString(form) << "\n"
            << "simulated    " << sim.time() << " s in " << c.steps << " steps";
  if (c.rejected) std::cout << " (" << c.rejected << " rejected)";
  std::cout << ", " << c.evaluations << " dynamics solves\n"
            << "wall time    " << wall << " s, " << 1e6 * wall / std::max<long>(1, c.steps)
            << " µs per step\n"
            << "energy       E0 = " << E0 << " J, max |E − E0| = " << max_energy_dev << " J ("
            << max_energy_dev / energy_scale << " relative)"
            << (passiveScene(scene) ? "" : "  [driven scene: energy is not conserved]") << "\n"
            << "residuals    max |Av+b| = " << max_vel_res << ", max |gap| = " << max_gap_res
            << (sopt.project_velocities ? "" : "  [projection off]") << "\n"
            << "redundant    " << max_redundant << " rows\n";
  std::cout << "events       ";
  int events = 0;
  if (sim.partitionChanges()) {
    std::cout << sim.partitionChanges() << " re-choices of the velocity partition; ";
    ++events;
  }
  if (contacts.flagged()) {
    std::cout << contacts.flagged() << " contacts flagged (below); ";
    ++events;
  }
  if (!status.ok) {
    std::cout << "FAILED at t = " << sim.time() << " s: " << status.message
              << " (last good state kept)";
    ++events;
  }
  std::cout << (events ? "\n" : "none\n");
  contacts.print(std::cout);
  if (writer) std::cout << "trajectory   " << args.text("out") << " (" << writer->samples() << " rows, "
                        << writer->columns().size() << " columns)\n";
  if (args.has("plot")) {
    csv.close();
    for (const std::string& png : writePlots(args.text("out"), defaultPlotDir(args.text("out")), &scene))
      std::cout << "plot         " << png << "\n";
  }
  return status.ok ? 0 : 3;
}

}  // namespace appell::cli
