// appell linearize: eigenvalues of the constrained dynamics about an
// equilibrium or a steady motion, in independent coordinates — once, or over
// a sweep of a parameter (the stability diagram).
#include "commands.hpp"
#include "linearize_analysis.hpp"
#include "overrides.hpp"
#include "plot.hpp"
#include "sweep_command.hpp"
#include "sweep_engine.hpp"

#include <appell/appell.hpp>
#include <appell/equilibria.hpp>
#include <appell/linearization.hpp>
#include <appell/output.hpp>

#include <Eigen/QR>

#include <algorithm>
#include <complex>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <thread>

namespace appell::cli {

namespace {

const char* kLinearizeHelp = R"(usage: appell linearize SCENE.urdf [options]

Linearizes the constrained dynamics on the constraint manifold about the
scene's initial state and prints the eigenvalues.

  --equilibrium       first find the equilibrium nearest the initial configuration
                      (v = 0) and linearize there
  --cyclic C1,C2,...  cyclic (ignorable) coordinates for a steady motion, by
                      name as the CSV's q: or v: columns name them: a joint
                      (revolute, prismatic), root_joint.x or root_joint.vx
                      (the floating base's world x), a planar joint's .theta
                      or .omega; rotations of a floating base by .wx .wy .wz
  --formulation F     {formulations} (default: the scene's)
  --zero-tol TOL      |μ| below TOL × max(1, max |μ|) counts as zero, and a real
                      part below it is not growth (default 1e-4)
  --fd-step H         finite-difference step in the local coordinates (default 1e-5)
  --set NAME=VALUE    override before linearizing (repeatable): gravity=gx,gy,gz,
                      speed=V (a floating base's forward speed, the other velocities
                      changed as little as the constraints allow), <joint>.position=…,
                      <joint>.velocity=…, <joint>.effort=…, <contact>.mu=μ, or a
                      coordinate by its CSV name
  --sweep NAME=START:STOP:COUNT
                      linearize at COUNT values of a one-number override, on all
                      cores; prints the largest real part per value and the values
                      where stability changes
  --family            the reference is one of a family of steady motions along
                      its own velocity (a bicycle running straight is steady at
                      any speed): that direction, (0, v) in the reduced state, is
                      a null vector of the linearization; it is removed (the
                      eigenvalues of the quotient Uᵀ L U, U spanning its
                      orthogonal complement) and a --sweep's stability changes
                      are located where the largest real part crosses 0, to
                      1e-9 relative, not where it crosses the zero tolerance
  --format F          text (default), csv or json — full precision
  --plot FILE.png     with --sweep: the stability diagram (largest real part
                      against the swept parameter), drawn by gnuplot

Exit status 3 when the reference is not an equilibrium / steady motion.
  --package-path DIRS
)" APPELL_INERTIA_HELP;

std::string full(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

int printOne(const Scene& scene, const Analysis& a, const std::vector<int>& cyclic, const std::string& format) {
  const LinearizationResult& r = a.result;
  if (format == "json") {
    std::cout << "{\"scene\": \"" << scene.source << "\", \"dimension\": " << r.dimension
              << ", \"constraint_residual\": " << full(r.constraint_residual)
              << ", \"steady_residual\": " << full(r.steady_residual) << ", \"eigenvalues\": [";
    for (std::size_t k = 0; k < a.eigenvalues.size(); ++k)
      std::cout << (k ? ", " : "") << "[" << full(a.eigenvalues[k].real()) << ", " << full(a.eigenvalues[k].imag()) << "]";
    std::cout << "]";
    if (a.family) std::cout << ", \"family_residual\": " << full(a.family_residual);
    std::cout << ", \"zero_eigenvalues\": " << a.zeros << ", \"max_real\": " << full(a.max_real)
              << ", \"verdict\": \"" << (!a.ok ? "none" : a.unstable() ? "unstable" : "not growing") << "\"}\n";
    return a.ok ? 0 : 3;
  }
  if (format == "csv") {
    std::cout << "real,imag\n";
    for (const auto& z : a.eigenvalues) std::cout << full(z.real()) << "," << full(z.imag()) << "\n";
    return a.ok ? 0 : 3;
  }
  std::cout << "scene " << scene.source << "\n"
            << "reduced state dimension " << r.dimension << " (tangent space of the constraint manifold)\n"
            << "reference: constraint residual " << r.constraint_residual << ", steady residual "
            << r.steady_residual;
  if (!cyclic.empty()) std::cout << ", symmetry residual " << r.symmetry_residual;
  std::cout << "\neigenvalues (real, imag):\n" << std::setprecision(8);
  for (const auto& z : a.eigenvalues)
    std::cout << "  " << std::setw(16) << z.real() << "  " << std::setw(16) << z.imag() << "\n";
  if (a.family)
    std::cout << "the family's direction (0, v) removed: |L z0| / |L| = " << a.family_residual
              << "; growth is a real part above 0\n";
  std::cout << a.zeros << " zero eigenvalues (|μ| < " << a.tol << " = zero-tol × max(1, max |μ|))\n";
  if (!a.ok) {
    std::cout << "no stability verdict: " << a.message << "; try --equilibrium or --cyclic\n";
    return 3;
  }
  std::cout << (a.unstable() ? "unstable: largest real part " + std::to_string(a.max_real)
                                   : std::string("no exponentially growing mode (to within the zero tolerance)"))
            << "\n";
  return 0;
}

int sweep(const SweepSetup& setup, const Args& args,
          const std::vector<int>& cyclic, Formulation form, const std::string& format) {
  const SweepAxis& sw = setup.axes[0];
  std::vector<Analysis> out(sw.values.size());
  // One task per value on every core (the sweep engine), each its own scene copy and solver.
  const unsigned workers = defaultJobs(sw.values.size());
  const CaseOutcome done = forEachCase(sw.values.size(), workers, [&](std::size_t k) {
    out[k] = analyse(caseScene(setup, {sw.values[k]}, false), args, cyclic, form, false);
  });
  for (std::size_t k = 0; k < done.errors.size(); ++k)
    if (!done.errors[k].empty()) throw UsageError(sw.name + "=" + full(sw.values[k]) + ": " + done.errors[k]);

  // Where the verdict changes between neighbours, found by bisection to
  // 1e-9 relative: the largest real part vanishes like a square root at a
  // threshold (a real pair becoming imaginary), so interpolating it would be
  // off by a good part of the step.
  auto unstable = [&](double value) {
    const Analysis a = analyse(caseScene(setup, {value}, false), args, cyclic, form, false);
    return std::pair<bool, bool>(a.ok, a.unstable());
  };
  std::vector<double> changes;
  for (std::size_t k = 1; k < out.size(); ++k) {
    const Analysis &a = out[k - 1], &b = out[k];
    if (!a.ok || !b.ok || (a.unstable()) == (b.unstable())) continue;
    double lo = sw.values[k - 1], hi = sw.values[k];
    const bool lo_unstable = a.unstable();
    for (int it = 0; it < 60 && std::abs(hi - lo) > 1e-9 * std::max(1.0, std::abs(lo)); ++it) {
      const double mid = 0.5 * (lo + hi);
      const auto [ok, u] = unstable(mid);
      if (!ok) break;
      (u == lo_unstable ? lo : hi) = mid;
    }
    changes.push_back(0.5 * (lo + hi));
  }
  if (format == "json") {
    std::cout << "{\"scene\": \"" << setup.base.source << "\", \"parameter\": \"" << sw.name << "\", \"results\": [";
    for (std::size_t k = 0; k < out.size(); ++k) {
      const Analysis& a = out[k];
      std::cout << (k ? ",\n  " : "\n  ") << "{\"value\": " << full(sw.values[k]) << ", \"verdict\": \""
                << (!a.ok ? "none" : a.unstable() ? "unstable" : "not growing")
                << "\", \"max_real\": " << full(a.max_real) << ", \"eigenvalues\": [";
      for (std::size_t i = 0; i < a.eigenvalues.size(); ++i)
        std::cout << (i ? ", " : "") << "[" << full(a.eigenvalues[i].real()) << ", " << full(a.eigenvalues[i].imag()) << "]";
      std::cout << "]}";
    }
    std::cout << "],\n \"stability_changes\": [";
    for (std::size_t k = 0; k < changes.size(); ++k) std::cout << (k ? ", " : "") << full(changes[k]);
    std::cout << "]}\n";
  } else if (format == "csv") {
    std::cout << sw.name << ",verdict,max_real";
    std::size_t n = 0;
    for (const Analysis& a : out) n = std::max(n, a.eigenvalues.size());
    for (std::size_t i = 0; i < n; ++i) std::cout << ",re" << i << ",im" << i;
    std::cout << "\n";
    for (std::size_t k = 0; k < out.size(); ++k) {
      const Analysis& a = out[k];
      std::cout << full(sw.values[k]) << "," << (!a.ok ? "none" : a.unstable() ? "unstable" : "stable")
                << "," << full(a.max_real);
      for (std::size_t i = 0; i < n; ++i)
        if (i < a.eigenvalues.size()) std::cout << "," << full(a.eigenvalues[i].real()) << "," << full(a.eigenvalues[i].imag());
        else std::cout << ",,";
      std::cout << "\n";
    }
  } else {
    std::cout << "scene " << setup.base.source << ": " << out.size() << " values of " << sw.name << " on "
              << workers << " threads\n"
              << std::setw(16) << sw.name << std::setw(18) << "largest Re" << "  verdict\n";
    for (std::size_t k = 0; k < out.size(); ++k) {
      const Analysis& a = out[k];
      std::cout << std::setprecision(8) << std::setw(16) << sw.values[k] << std::setw(18) << a.max_real << "  "
                << (!a.ok ? "no verdict: " + a.message : a.unstable() ? "unstable" : "no growing mode") << "\n";
    }
    if (changes.empty()) std::cout << "stability does not change over the sweep\n";
    for (double c : changes) std::cout << "stability changes at " << sw.name << " ≈ " << std::setprecision(10) << c << "\n";
  }
  if (args.has("plot")) {
    std::vector<double> x, y;
    for (std::size_t k = 0; k < out.size(); ++k)
      if (out[k].ok) {
        x.push_back(sw.values[k]);
        y.push_back(out[k].max_real);
      }
    writeStabilityPlot(args.text("plot"), sw.name, x, y);
    if (format == "text") std::cout << "stability diagram " << args.text("plot") << "\n";
  }
  return std::any_of(out.begin(), out.end(), [](const Analysis& a) { return a.ok; }) ? 0 : 3;
}

}  // namespace

int linearize(int argc, char** argv) {
  Args args(argc, argv, 2,
            {"cyclic", "formulation", "zero-tol", "package-path", "fd-step", "set", "sweep", "format", "plot",
             "bound-inertia", "bound-mass"},
            {"help", "equilibrium", "project-initial", "no-joint-limits", "balance-inertia", "family"});
  if (args.has("help")) {
    std::cout << helpText(kLinearizeHelp);
    return 0;
  }
  const std::string format = args.text("format", "text");
  if (format != "text" && format != "csv" && format != "json")
    throw UsageError("--format must be text, csv or json, not '" + format + "'");
  if (args.has("plot") && !args.has("sweep")) throw UsageError("--plot draws a --sweep's stability diagram");
  if (args.has("family") && args.has("equilibrium"))
    throw UsageError("--family removes a steady motion's own direction; an equilibrium (v = 0) has none");
  // Overrides change the state: check it after them, not at load.
  const bool overrides = !args.all("set").empty();
  Scene scene = loadFromArgs(args, !args.has("equilibrium") && !overrides);
  // --sweep: each value's case from the scene as loaded, the --set options
  // then the value, as `appell sweep` and a single linearize build it.
  const SweepSetup sweep_setup = args.has("sweep") ? oneAxisSetup(scene, args) : SweepSetup{};
  const OverrideReport kept = applyOverrides(scene, args);
  if (overrides && !args.has("equilibrium"))
    checkInitialState(scene, args.has("project-initial"), LoadOptions().initial_state_tolerance);
  const std::vector<int> cyclic = cyclicCoordinates(scene, args);
  const Formulation form = linearizeFormulation(scene, args);
  if (args.has("sweep")) return sweep(sweep_setup, args, cyclic, form, format);
  if (format == "text")
    for (const std::string& line : describe(scene, kept)) std::cout << "override     " << line << "\n";
  const Analysis a = analyse(scene, args, cyclic, form, format == "text");
  if (!a.ok && a.message.rfind("the reference", 0) != 0) {  // no equilibrium found
    std::cout << a.message << "\n";
    return 3;
  }
  return printOne(scene, a, cyclic, format);
}

}  // namespace appell::cli
