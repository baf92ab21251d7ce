// appell linearize: eigenvalues of the constrained dynamics about an
// equilibrium or a steady motion, in independent coordinates — once, or over
// a sweep of a parameter (the stability diagram).
#include "commands.hpp"
#include "overrides.hpp"
#include "plot.hpp"

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

struct Analysis {
  bool ok = false;             ///< a verdict: the reference is an equilibrium / steady motion
  std::string message;         ///< why not, when !ok
  LinearizationResult result;
  std::vector<std::complex<double>> eigenvalues;  ///< largest real part first
  double tol = 0, max_real = 0;
  int zeros = 0;
  bool family = false;         ///< --family: the family's direction removed
  double family_residual = 0;  ///< |L z₀| / |L|, z₀ the family's direction
  /// The threshold of growth: the zero tolerance, or 0 once a family's own
  /// null direction is removed (its boundaries are where a real part crosses 0).
  double growthThreshold() const { return family ? 0.0 : tol; }
  bool unstable() const { return max_real > growthThreshold(); }
};

// The eigenvalues of the quotient by a family of steady motions along the
// reference velocity v: z₀ = Zᵀ (0, v/|v|) in the tangent basis Z, U an
// orthonormal basis of z₀'s complement (Householder), the spectrum of Uᵀ L U.
std::vector<std::complex<double>> familyQuotient(const LinearizationResult& r, const VecX& v, double& residual) {
  // Below 1e-9 in every coordinate the velocity is the constraints' round-off
  // (a bicycle set to rest keeps a front spin of 1e-15): no direction at all.
  if (!(v.lpNorm<Eigen::Infinity>() > 1e-9))
    throw UsageError("--family: the reference velocity is zero, so it spans no family");
  VecX x0 = VecX::Zero(r.basis.rows());
  x0.tail(v.size()) = v.normalized();
  const VecX z0 = r.basis.transpose() * x0;
  if (!(z0.norm() > 0.5))
    throw UsageError("--family: the reference velocity leaves the tangent space of the constraints");
  residual = (r.matrix * z0).norm() / std::max(r.matrix.norm(), 1e-300);
  const MatX q = Eigen::HouseholderQR<MatX>(z0).householderQ();
  const MatX u = q.rightCols(r.dimension - 1);
  const Eigen::VectorXcd e = Eigen::EigenSolver<MatX>(u.transpose() * r.matrix * u, false).eigenvalues();
  return {e.data(), e.data() + e.size()};
}

// One linearization of `scene` as the options say.
Analysis analyse(const Scene& scene, const Args& args, const std::vector<int>& cyclic, Formulation form,
                 bool print) {
  Analysis a;
  const Model& m = scene.model;
  VecX q = scene.q0, v = scene.v0;
  if (args.has("equilibrium")) {
    EquilibriumOptions eo;
    if (scene.tau.size() == m.nv) eo.tau = scene.tau;
    const EquilibriumResult e = findEquilibrium(m, scene.constraints, scene.q0, eo);
    if (!e.converged) {
      a.message = e.message;
      return a;
    }
    q = e.q;
    v.setZero();
    if (print)
      std::cout << "equilibrium found (residual " << e.residual << ", local dimension "
                << e.manifold_dimension << ")\n";
  }
  LinearizationOptions lo;
  if (scene.tau.size() == m.nv) lo.tau = scene.tau;
  lo.cyclic = cyclic;
  lo.fd_step = args.positiveNumber("fd-step", lo.fd_step);
  auto solver = makeSolver(form, m, scene.constraints);
  a.result = linearize(m, scene.constraints, *solver, q, v, lo);
  const LinearizationResult& r = a.result;
  a.family = args.has("family");
  if (a.family)
    a.eigenvalues = familyQuotient(r, v, a.family_residual);
  else
    a.eigenvalues.assign(r.eigenvalues.data(), r.eigenvalues.data() + r.eigenvalues.size());
  std::sort(a.eigenvalues.begin(), a.eigenvalues.end(), [](auto x, auto y) {
    return x.real() != y.real() ? x.real() > y.real() : x.imag() > y.imag();
  });
  // Relative to the eigenvalues' scale: round-off in a fast system's
  // eigenvalues is larger than 1e-4 in absolute terms, and is not instability.
  double scale = 1.0;
  for (const auto& z : a.eigenvalues) scale = std::max(scale, std::abs(z));
  a.tol = args.positiveNumber("zero-tol", 1e-4) * scale;
  a.zeros = static_cast<int>(std::count_if(a.eigenvalues.begin(), a.eigenvalues.end(),
                                            [&](const auto& z) { return std::abs(z) <= a.tol; }));
  a.max_real = a.eigenvalues.empty() ? 0.0 : a.eigenvalues.front().real();
  if (r.steady_residual > 1e-6 * scale || r.constraint_residual > 1e-8) {
    std::ostringstream s;
    s << "the reference state is not an equilibrium or steady motion (steady residual "
      << r.steady_residual << ")";
    a.message = s.str();
    return a;
  }
  if (a.family && a.family_residual > 1e-6) {
    std::ostringstream s;
    s << "the reference velocity is not the direction of a family of steady motions (|L z0| / |L| = "
      << a.family_residual << "): drop --family";
    a.message = s.str();
    return a;
  }
  a.ok = true;
  return a;
}

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

int sweep(const Scene& base, const OverrideReport& kept_base, const Args& args,
          const std::vector<int>& cyclic, Formulation form, const std::string& format) {
  const Sweep sw = parseSweep(args.text("sweep"));
  std::vector<Analysis> out(sw.values.size());
  std::vector<std::string> errors(sw.values.size());
  // One value per task, on every core; each task its own scene copy and solver.
  const unsigned workers = std::max(1u, std::min<unsigned>(std::thread::hardware_concurrency(),
                                                           static_cast<unsigned>(sw.values.size())));
  std::vector<std::thread> pool;
  for (unsigned w = 0; w < workers; ++w)
    pool.emplace_back([&, w] {
      for (std::size_t k = w; k < sw.values.size(); k += workers) {
        try {
          Scene s = base;
          OverrideReport kept;
          kept.kept = kept_base.kept;
          applyOverride(s, sw.name, full(sw.values[k]), kept);
          completeSetVelocities(s, kept);
          out[k] = analyse(s, args, cyclic, form, false);
        } catch (const std::exception& e) {
          errors[k] = e.what();
        }
      }
    });
  for (std::thread& t : pool) t.join();
  for (std::size_t k = 0; k < errors.size(); ++k)
    if (!errors[k].empty()) throw UsageError(sw.name + "=" + full(sw.values[k]) + ": " + errors[k]);

  // Where the verdict changes between neighbours, found by bisection to
  // 1e-9 relative: the largest real part vanishes like a square root at a
  // threshold (a real pair becoming imaginary), so interpolating it would be
  // off by a good part of the step.
  auto unstable = [&](double value) {
    Scene s = base;
    OverrideReport kept;
    kept.kept = kept_base.kept;
    applyOverride(s, sw.name, full(value), kept);
    completeSetVelocities(s, kept);
    const Analysis a = analyse(s, args, cyclic, form, false);
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
    std::cout << "{\"scene\": \"" << base.source << "\", \"parameter\": \"" << sw.name << "\", \"results\": [";
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
    std::cout << "scene " << base.source << ": " << out.size() << " values of " << sw.name << " on "
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
  const OverrideReport kept = applyOverrides(scene, args);
  if (overrides && !args.has("equilibrium"))
    checkInitialState(scene, args.has("project-initial"), LoadOptions().initial_state_tolerance);
  std::vector<int> cyclic;
  for (const std::string& c : args.list("cyclic")) {
    int k;
    try {
      k = localCoordinateIndex(scene.model, c);
    } catch (const std::invalid_argument& e) {
      throw UsageError(std::string("--cyclic: ") + e.what());
    }
    if (k < 0) throw UsageError("--cyclic: no coordinate named '" + c + "' (names as the CSV's q: and v: columns)");
    cyclic.push_back(k);
  }
  Formulation form;
  try {
    form = formulationFromString(args.text("formulation", scene.settings.formulation));
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  if (args.has("sweep")) return sweep(scene, kept, args, cyclic, form, format);
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
