// appell's time-stepping contact solver against Siconos' fc3d solvers on
// the very problems appell's Moreau–Jean steps make (docs/contacts.md §10,
// "Against Siconos' fc3d solvers").
//
// Each scene is run time-stepped (h = 1 ms) and the contact problem of
// every k-th step recorded (Simulator::contactProblem). Those made only of
// three-row Coulomb blocks — one normal, two friction rows, no equality
// row — are exactly Siconos' FrictionContactProblem, u = W r + q with
// q = u_free − target (the targets are zero but on the normal rows). Each is
// solved by
//   - appell: ContactProblemSolver (the step's own Gauss–Seidel and
//     active-set finish), from the step's warm start and from zero, at the
//     step's tolerance (residual_tol 1e-10 of max(1, |u_free|∞) m/s);
//   - Siconos 4.4 (libsiconos-numerics, Debian's build): NSGS (its default
//     local solver), the Alart–Curnier and the Fischer–Burmeister
//     semismooth Newton methods, at their relative tolerance `--tol`
//     (default 1e-10), from the same starts.
// Every answer is then measured by both criteria — appell's natural-map
// residual in m/s (ContactProblemSolver::residual) and Siconos' own error
// (fc3d_compute_error, relative to |q|) — with the time per problem
// (median of `--repeats` passes over all problems), the iterations and the
// largest difference of the contact velocities u from appell's answer
// (the impulses of redundant contacts are not unique; u is, where the
// problem's solution set is a face of the cone product).
// Writes the tables (markdown) to stdout and, with --out DIR, to DIR/fc3d.md.
// (Siconos' Newton solvers print their failed LU factorizations to stdout.)
// Usage: report_fc3d [--repeats N] [--tol T] [--every K] [--out DIR]
#include <appell/appell.hpp>
#include <appell/contact_problem.hpp>
#include <appell/run.hpp>
#include <appell/urdf.hpp>

#include "corner_box.hpp"

// (Siconos' C headers declare themselves extern "C".)
#include <FrictionContactProblem.h>
#include <Friction_cst.h>
#include <NonSmoothDrivers.h>
#include <NumericsMatrix.h>
#include <NumericsVerbose.h>
#include <SolverOptions.h>
#include <fc3d_compute_error.h>

#include <algorithm>
#include <chrono>
#include <cstdarg>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

using namespace appell;

namespace {

struct Options {
  int repeats = 3, every = 10;
  double tol = 1e-10;
  std::string out;
};

// printf onto a string.
__attribute__((format(printf, 2, 3))) void add(std::string& md, const char* format, ...) {
  char line[512];
  va_list args;
  va_start(args, format);
  std::vsnprintf(line, sizeof line, format, args);
  va_end(args);
  md += line;
}

bool isFc3d(const ContactProblemData& d) {
  if (d.blocks.empty()) return false;
  for (const ContactProblemBlock& b : d.blocks)
    if (b.friction_rows != 2 || b.equality_rows != 0) return false;
  return true;
}

// A scene's problems: every `every`-th time-stepped step's, fc3d-shaped.
struct Problems {
  std::vector<ContactProblemData> fc3d;
  long recorded = 0;  // all recorded, fc3d-shaped or not
};

void keep(const Simulator& sim, long& step, int every, Problems& out) {
  if (step++ % every != 0) return;
  ContactProblemData d;
  if (!sim.contactProblem(d)) return;
  ++out.recorded;
  if (isFc3d(d)) out.fc3d.push_back(std::move(d));
}

Problems exampleProblems(const char* path, double duration, int every) {
  const Scene scene = loadScene(std::string(APPELL_SOURCE_DIR) + path);
  RunOptions o = runOptions(scene.settings);
  o.contacts = ContactScheme::TimeStepping;
  o.duration = duration;
  Problems p;
  long step = 0;
  const RunSummary s = runScene(scene, o, {}, [&](const Simulator& sim) { keep(sim, step, every, p); });
  if (!s.ok) std::fprintf(stderr, "%s: %s\n", path, s.failure.c_str());
  return p;
}

// The box of bench/report_contact_schemes: four corners, μ 0.5, pushed by F = 30 t N.
Problems pushedBoxProblems(int every) {
  const scenes::BuiltScene s = scenes::cornerBox({.half = Vec3(0.2, 0.1, 0.05), .mass = 2, .h = 0,
                                                  .R = Mat3::Identity(), .kind = ContactKind::Rolling,
                                                  .mu = 0.5});
  SimulatorOptions so;
  so.scheme = ContactScheme::TimeStepping;
  Simulator sim(s.model, s.constraints, makeSolver(Formulation::Tree, s.model, s.constraints),
                IntegratorType::DormandPrince54, IntegratorOptions{}, so);
  sim.setJointForces([](double t, const VecX& q, const VecX&, VecX& tau) {
    tau.tail<3>() = scenes::floatingRotation(q, 0).transpose() * Vec3(30 * t, 0, 0);
  });
  sim.setState(0, s.q0, s.v0);
  Problems p;
  long step = 0;
  while (sim.time() < 0.7 - 1e-12) {
    if (!sim.step(1e-3).ok) break;
    keep(sim, step, every, p);
  }
  return p;
}

// One problem in Siconos' form (it owns copies of W, q and μ).
struct SiconosProblem {
  FrictionContactProblem* fcp = nullptr;
  double norm_q = 0;
  explicit SiconosProblem(const ContactProblemData& d) {
    const int n = d.rows(), nc = static_cast<int>(d.blocks.size());
    NumericsMatrix* W = NM_create(NM_DENSE, n, n);
    std::memcpy(W->matrix0, d.W.data(), sizeof(double) * n * n);  // (both column-major)
    auto* q = static_cast<double*>(std::malloc(sizeof(double) * n));
    auto* mu = static_cast<double*>(std::malloc(sizeof(double) * nc));
    for (int i = 0; i < n; ++i) q[i] = d.u_free[i] - d.target[i];
    for (int c = 0; c < nc; ++c) mu[c] = d.blocks[c].mu;
    fcp = frictionContactProblem_new_with_data(3, nc, W, q, mu);
    norm_q = (d.u_free - d.target).norm();
  }
  ~SiconosProblem() { frictionContactProblem_free(fcp); }
  SiconosProblem(const SiconosProblem&) = delete;
  SiconosProblem& operator=(const SiconosProblem&) = delete;
};

struct Answer {
  VecX P, u;
  int iterations = 0;
  bool reported_ok = false;  // the solver's own verdict
};

struct Solver {
  const char* name;
  int siconos_id;  // 0: appell
  bool cold;
};

Answer solveOnce(const Solver& s, const ContactProblemData& d, ContactProblemSolver& mine,
                 SiconosProblem& theirs, double tol) {
  Answer a;
  const VecX start = s.cold ? VecX::Zero(d.rows()) : d.warm_start;
  if (s.siconos_id == 0) {
    const SimulatorOptions defaults;
    const auto r = mine.solve(start, defaults.timestepping.residual_tol, defaults.timestepping.max_sweeps, a.P, a.u);
    a.iterations = r.sweeps;
    a.reported_ok = r.converged;
    return a;
  }
  a.P = start;
  a.u = VecX::Zero(d.rows());
  ::SolverOptions* o = solver_options_create(s.siconos_id);
  o->dparam[SICONOS_DPARAM_TOL] = tol;
  o->iparam[SICONOS_IPARAM_MAX_ITER] = 2000;
  const int info = fc3d_driver(theirs.fcp, a.P.data(), a.u.data(), o);
  a.iterations = o->iparam[SICONOS_IPARAM_ITER_DONE];
  a.reported_ok = info == 0;
  solver_options_delete(o);
  return a;
}

struct Row {
  std::vector<double> pass_seconds;
  std::vector<double> iterations, appell_residual, siconos_error, u_gap;
  long meets_appell = 0, reported_ok = 0, problems = 0;
};

double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}
double maxOf(const std::vector<double>& v) { return v.empty() ? std::nan("") : *std::max_element(v.begin(), v.end()); }

void report(const char* scene, const Problems& p, const Options& opt, std::string& md) {
  const Solver solvers[] = {
      {"appell (warm)", 0, false},
      {"appell (cold)", 0, true},
      {"Siconos NSGS (warm)", SICONOS_FRICTION_3D_NSGS, false},
      {"Siconos NSGS (cold)", SICONOS_FRICTION_3D_NSGS, true},
      {"Siconos NSN-AC (warm)", SICONOS_FRICTION_3D_NSN_AC, false},
      {"Siconos NSN-AC (cold)", SICONOS_FRICTION_3D_NSN_AC, true},
  };
  const int np = static_cast<int>(p.fc3d.size());
  int blocks = 0, rows_max = 0;
  for (const auto& d : p.fc3d) {
    blocks += static_cast<int>(d.blocks.size());
    rows_max = std::max(rows_max, d.rows());
  }
  add(md, "\n**%s**: %ld problems recorded, %d fc3d-shaped (%.1f contacts each, ≤ %d rows)\n\n", scene,
      p.recorded, np, np ? double(blocks) / np : 0.0, rows_max);
  add(md, "| solver | µs/problem | iterations (median) | appell residual median, max (m/s) | Siconos error max | max abs(u − u_appell) (m/s) | meet tol |\n");
  add(md, "|---|---:|---:|---|---:|---:|---:|\n");
  std::vector<ContactProblemSolver> mine;
  std::vector<std::unique_ptr<SiconosProblem>> theirs;
  std::vector<VecX> reference_u(np);
  for (const auto& d : p.fc3d) {
    mine.emplace_back(d);
    theirs.push_back(std::make_unique<SiconosProblem>(d));
  }
  for (const Solver& s : solvers) {
    Row row;
    for (int rep = 0; rep < opt.repeats; ++rep) {
      const auto t0 = std::chrono::steady_clock::now();
      for (int i = 0; i < np; ++i) solveOnce(s, p.fc3d[i], mine[i], *theirs[i], opt.tol);
      row.pass_seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    for (int i = 0; i < np; ++i) {  // the answers, measured outside the timing
      const ContactProblemData& d = p.fc3d[i];
      Answer a = solveOnce(s, d, mine[i], *theirs[i], opt.tol);
      const double res = mine[i].residual(a.P);
      const VecX u = d.W * a.P + d.u_free;
      VecX w = u - d.target;  // Siconos' velocity
      VecX r = a.P;
      double err = 0;
      ::SolverOptions* o = solver_options_create(SICONOS_FRICTION_3D_NSGS);
      fc3d_compute_error(theirs[i]->fcp, r.data(), w.data(), opt.tol, o, theirs[i]->norm_q, &err);
      solver_options_delete(o);
      if (&s == &solvers[0]) reference_u[i] = u;
      row.iterations.push_back(a.iterations);
      row.appell_residual.push_back(res);
      row.siconos_error.push_back(err);
      row.u_gap.push_back((u - reference_u[i]).lpNorm<Eigen::Infinity>());
      const SimulatorOptions defaults;
      row.meets_appell += res <= defaults.timestepping.residual_tol * std::max(1.0, d.u_free.lpNorm<Eigen::Infinity>());
      row.reported_ok += a.reported_ok;
    }
    add(md, "| %s | %.1f | %.0f | %.1e, %.1e | %.1e | %.1e | %.1f %% |\n", s.name,
        1e6 * median(row.pass_seconds) / std::max(np, 1), median(row.iterations),
        median(row.appell_residual), maxOf(row.appell_residual), maxOf(row.siconos_error),
        maxOf(row.u_gap), np ? 100.0 * row.meets_appell / np : 0.0);
  }
}

}  // namespace

int main(int argc, char** argv) {
  Options opt;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--repeats") opt.repeats = std::max(1, std::atoi(argv[i + 1]));
    else if (a == "--tol") opt.tol = std::atof(argv[i + 1]);
    else if (a == "--every") opt.every = std::max(1, std::atoi(argv[i + 1]));
    else if (a == "--out") opt.out = argv[i + 1];
    else {
      std::fprintf(stderr, "usage: report_fc3d [--repeats N] [--tol T] [--every K] [--out DIR]\n");
      return 2;
    }
  }
  numerics_set_verbose(0);
  std::string md = "# appell's contact solver against Siconos 4.4 fc3d\n\n";
  add(md, "    build/bench/peers/report_fc3d --repeats %d --tol %g --every %d\n\n", opt.repeats, opt.tol, opt.every);
  add(md, "Siconos at relative tolerance %g; appell at the step's own (residual_tol 1e-10). "
          "µs/problem: the median of %d passes over all problems. *meet tol*: the answer's appell "
          "residual ≤ 1e-10 · max(1, |u_free|∞) m/s, the criterion a time-stepping step stops on. "
          "u_appell: appell's warm-started answer.\n", opt.tol, opt.repeats);
  report("box on 4 corners pushed (0.7 s), every step", pushedBoxProblems(1), opt, md);
  report("skid_steer_step (10 s)", exampleProblems("/examples/skid_steer_step/skid_steer_step.urdf", 10, opt.every), opt, md);
  report("cad_car (10 s)", exampleProblems("/examples/cad_car/cad_car.urdf", 10, opt.every), opt, md);
  std::fflush(stdout);
  std::fputs(md.c_str(), stdout);
  if (!opt.out.empty()) {
    const std::string path = opt.out + "/fc3d.md";
    FILE* f = std::fopen(path.c_str(), "w");
    if (!f) {
      std::fprintf(stderr, "report_fc3d: cannot write %s\n", path.c_str());
      return 1;
    }
    std::fputs(md.c_str(), f);
    std::fclose(f);
  }
  return 0;
}
