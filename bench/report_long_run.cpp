// Fixed steps over a long time: the leapfrog (a time-reversible RATTLE-type
// scheme, leapfrog.cpp) against RK4 and symplectic Euler at equal cost.
//
//   build/bench/report_long_run [--steps N] [--dt H] [--out DIR]
//
// Three problems, each run for N leapfrog steps of H (default 10⁶ × 10 ms =
// 10⁴ s of simulated time):
//   disk       the rolling disk (m 1 kg, R 0.5 m, lean 0.3 rad,
//              5 rad/s about the axle) — reversible and integrable;
//   sleigh     the Chaplygin sleigh on a 0.35 rad incline, moving and turning
//              — reversible (its motion has attracting and repelling parts);
//   turntable  a ball rolling on a turntable turning at 2 rad/s — a moving
//              support (b ≠ 0), so not reversible under v → −v: the case where,
//              after Modin & Verdier (Numer. Math. 145 (2020) 405–435),
//              reversible methods lose their advantage. It keeps a reversing
//              symmetry of another kind, though: a reflection through a
//              vertical plane through the axis reverses the table's turning,
//              and time reversal turns it back;
//   springs    the same ball held by two horizontal springs anchored in the
//              world at points not in one plane with the axis, stiffnesses
//              3 and 5 N/m: no reflection maps the springs onto themselves,
//              so no reversing symmetry is left.
// The quantity watched is the work balance E + losses − work in − E₀ (the
// energy for the first two; for the turntable the energy minus the table's
// work), relative to E₀. Equal cost: each method's step is chosen from a
// calibration run so that its CPU time per simulated second equals the
// leapfrog's. Writes DIR/long_run.md, DIR/long_run.csv (the error over time)
// and, with gnuplot, DIR/long_run.png.
#include <appell/appell.hpp>
#include <appell/simulator.hpp>

#include "ball.hpp"
#include "rolling_disk.hpp"
#include "sleigh.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

using namespace appell;
using namespace appell::scenes;

namespace {

double cpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

struct Problem {
  std::string name, what;
  BuiltScene scene;
  Simulator::JointForces forces;  // empty: none
};

/// Two world-anchored springs on the ball's centre (the floating joint's
/// origin): τ = (0, Rᵀ F), F = −Σ kᵢ (p − aᵢ), anchors at the centre's height.
Simulator::JointForces twoSprings() {
  return [](double, const VecX& q, const VecX&, VecX& tau) {
    const Vec3 p = q.head<3>();
    const Quat R(q[6], q[3], q[4], q[5]);
    const Vec3 F = -3.0 * (p - Vec3(0.5, 0.0, 0.1)) - 5.0 * (p - Vec3(0.0, -0.4, 0.1));
    tau.setZero();
    tau.segment<3>(3) = R.conjugate() * F;
  };
}

std::vector<Problem> problems() {
  RollingDiskParams d;
  d.radius = 0.5;
  d.mass = 1.0;
  d.lean = 0.3;
  d.axle_rate = 5.0;
  SleighParams s = lateralSleighParams();
  s.speed = 0.6;
  s.turn_rate = 0.8;
  return {{"disk", "rolling disk, reversible integrable", rollingDisk(d), {}},
          {"sleigh", "Chaplygin sleigh on a 0.35 rad incline, reversible", sleigh(s), {}},
          {"turntable", "ball on a turntable at 2 rad/s, moving support: not reversible under v → −v",
           ballOnTurntable(2.0), {}},
          {"springs", "the same ball held by two asymmetric world-anchored springs: no reversing symmetry",
           ballOnTurntable(2.0), twoSprings()}};
}

double balance(const Simulator& sim) {
  return sim.energy() + sim.impactEnergyLoss() + sim.frictionWork() - sim.jointWork() -
         sim.supportWork();
}

struct Trace {
  std::vector<double> t, err;  // sampled relative balance errors
  double cpu = 0;              // CPU seconds of the whole run
  long steps = 0, evaluations = 0;
  double max_residual = 0;
  std::string failure;         // empty when it ran to the end
};

std::unique_ptr<Simulator> makeSim(const Problem& p, IntegratorType type) {
  const BuiltScene& s = p.scene;
  auto sim = std::make_unique<Simulator>(
      s.model, s.constraints, makeSolver(Formulation::Tree, s.model, s.constraints), type);
  if (p.forces) sim->setJointForces(p.forces);
  sim->setState(0, s.q0, s.v0);
  return sim;
}

/// Runs `steps` steps of h, sampling the balance error `samples` times on a
/// logarithmic time grid (so every decade is seen).
Trace run(const Problem& s, IntegratorType type, double h, long steps, int samples) {
  auto sim = makeSim(s, type);
  const double E0 = balance(*sim);
  const double scale = std::max(1e-12, std::abs(E0));
  Trace tr;
  std::vector<long> at;
  for (int k = 0; k <= samples; ++k) {
    const long n = std::lround(std::pow(static_cast<double>(steps), static_cast<double>(k) / samples));
    if (at.empty() || n > at.back()) at.push_back(n);
  }
  size_t next = 0;
  double worst = 0;
  const double c0 = cpuSeconds();
  for (long k = 1; k <= steps; ++k) {
    const StepStatus st = sim->step(h);
    if (!st.ok) {
      std::ostringstream os;
      os << "failed at t = " << sim->time() << " s: " << st.message.substr(0, 160);
      tr.failure = os.str();
      break;
    }
    ++tr.steps;
    tr.evaluations += st.evaluations;
    worst = std::max(worst, std::abs(balance(*sim) - E0) / scale);
    tr.max_residual = std::max({tr.max_residual, sim->velocityResidual(), sim->gapResidual()});
    if (next < at.size() && k == at[next]) {
      tr.t.push_back(sim->time());
      tr.err.push_back(worst);  // the largest error so far: the envelope
      ++next;
    }
  }
  tr.cpu = cpuSeconds() - c0;
  return tr;
}

/// The CPU time per step of `type` relative to the leapfrog's at the same h:
/// the median of five ratios, each from the two methods run back to back
/// (10⁴ steps each), so that a change in the machine's load between the
/// calibration runs does not end up in the equal-cost step.
double costRatio(const Problem& s, IntegratorType type, double h) {
  std::vector<double> r;
  for (int k = 0; k < 5; ++k) {
    const Trace a = run(s, type, h, 10000, 1);
    const Trace b = run(s, IntegratorType::Leapfrog, h, 10000, 1);
    r.push_back((a.cpu / std::max<long>(1, a.steps)) / (b.cpu / std::max<long>(1, b.steps)));
  }
  std::sort(r.begin(), r.end());
  return r[2];
}

std::string sci(double x, int p = 2) {
  std::ostringstream os;
  os << std::scientific << std::setprecision(p) << x;
  return os.str();
}

/// The envelope at time T (the largest error up to T), or "—" past a failure.
std::string envelopeAt(const Trace& tr, double T) {
  double e = -1;
  for (size_t k = 0; k < tr.t.size(); ++k)
    if (tr.t[k] <= T * (1 + 1e-3)) e = tr.err[k];
  // Past the last sample (a failure, or a step count that stops a step short
  // of T): no figure.
  if (e < 0 || tr.t.empty() || tr.t.back() < T * (1 - 1e-3)) return "—";
  return sci(e);
}

}  // namespace

int main(int argc, char** argv) {
  long steps = 1000000;
  double h = 1e-2;
  std::string out = "bench/results";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--steps" && i + 1 < argc) steps = std::max(10L, std::atol(argv[++i]));
    else if (a == "--dt" && i + 1 < argc) h = std::atof(argv[++i]);
    else if (a == "--out" && i + 1 < argc) out = argv[++i];
    else {
      std::cerr << "usage: report_long_run [--steps N] [--dt H] [--out DIR]\n";
      return 2;
    }
  }
  std::filesystem::create_directories(out);
  const double T = steps * h;
  std::ostringstream md;
  std::ofstream csv(out + "/long_run.csv");
  csv << "problem,method,dt,t,max_rel_error\n";
  md << "# Fixed steps over " << T << " s: the leapfrog against RK4 and symplectic Euler at "
     << "equal cost\n\n"
     << "Written by `bench/report_long_run.cpp`. Command (Release build):\n\n"
     << "    build/bench/report_long_run --steps " << steps << " --dt " << h << " --out " << out
     << "\n\n"
     << "The leapfrog runs " << steps << " steps of " << h << " s; RK4 and symplectic Euler run "
     << "the same simulated time with the step that gives them the leapfrog's CPU time per "
     << "simulated second (calibrated against the leapfrog: the median of five CPU ratios, each from the two run back to back for 10⁴ steps). Evaluations: calls "
     << "of the dynamics (for the leapfrog each also projects its velocity onto the rows, and "
     << "each iteration of its first kick projects once more). Error: the largest "
     << "relative work-balance error |E + losses − work in − E₀|/E₀ up to each time "
     << "(for the turntable the table's and the springs' work is the work in). CPU time of the process.\n\n";
  const std::vector<double> marks = {10, 100, 1000, 10000, 100000};
  const struct {
    IntegratorType type;
    const char* name;
  } methods[] = {{IntegratorType::Leapfrog, "leapfrog"},
                 {IntegratorType::RK4, "rk4"},
                 {IntegratorType::SymplecticEuler, "euler"}};
  for (const Problem& p : problems()) {
    md << "## " << p.name << " — " << p.what << "\n\n| method | dt [s] | steps | CPU [s] | "
       << "evaluations per step |";
    for (double m : marks)
      if (m <= T * (1 + 1e-9)) md << " error to " << static_cast<long>(m) << " s |";
    md << " max residual | end |\n|---|---|---|---|---|";
    for (double m : marks)
      if (m <= T * (1 + 1e-9)) md << "---|";
    md << "---|---|\n";
    for (const auto& m : methods) {
      double hm = h;
      if (m.type != IntegratorType::Leapfrog) {
        hm = h * costRatio(p, m.type, h);  // equal CPU per simulated second
      }
      const long n = std::lround(T / hm);
      std::cout << p.name << ", " << m.name << ": dt " << hm << ", " << n << " steps" << std::flush;
      const Trace tr = run(p, m.type, hm, n, 60);
      std::cout << ", " << tr.cpu << " s CPU" << (tr.failure.empty() ? "" : " — " + tr.failure)
                << "\n";
      md << "| " << m.name << " | " << sci(hm, 3) << " | " << tr.steps << " | "
         << std::fixed << std::setprecision(1) << tr.cpu << " | " << std::setprecision(2)
         << static_cast<double>(tr.evaluations) / std::max<long>(1, tr.steps) << " |";
      for (double mk : marks)
        if (mk <= T * (1 + 1e-9)) md << " " << envelopeAt(tr, mk) << " |";
      md << " " << sci(tr.max_residual, 1) << " | "
         << (tr.failure.empty() ? "ran to the end" : tr.failure) << " |\n";
      for (size_t k = 0; k < tr.t.size(); ++k)
        csv << p.name << "," << m.name << "," << hm << "," << tr.t[k] << "," << tr.err[k] << "\n";
    }
    md << "\n";
  }
  csv.close();
  std::ofstream(out + "/long_run.md") << md.str();
  if (std::system("command -v gnuplot > /dev/null 2>&1") == 0) {
    const std::string gp = out + "/long_run.gp";
    std::ofstream g(gp);
    g << "# long_run.png, made by bench/report_long_run (its data: long_run.csv):\n#  ";
    for (int i = 0; i < argc; ++i) g << " " << argv[i];
    g << "\nset terminal pngcairo size 1500,900 font ',10'\nset output '" << out << "/long_run.png'\n"
      << "set datafile separator ','\nset logscale xy\nset format y '10^{%L}'\nset format x '10^{%L}'\n"
      << "set xlabel 'simulated time [s]'\nset ylabel 'max relative work-balance error so far'\n"
      << "set key top left\nset multiplot layout 2,2\n";
    for (const char* p : {"disk", "sleigh", "turntable", "springs"}) {
      g << "set title '" << p << " (equal CPU per simulated second)'\nplot ";
      bool first = true;
      for (const char* m : {"leapfrog", "rk4", "euler"}) {
        g << (first ? "" : ", ") << "'" << out << "/long_run.csv' using (strcol(1) eq '" << p
          << "' && strcol(2) eq '" << m << "' ? $4 : 1/0):5 with linespoints title '" << m << "'";
        first = false;
      }
      g << "\n";
    }
    g << "unset multiplot\n";
    g.close();
    if (std::system(("gnuplot " + gp).c_str()) != 0) std::cerr << "gnuplot failed\n";
  }
  std::cout << "wrote " << out << "/long_run.md\n";
  return 0;
}
