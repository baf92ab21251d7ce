// appell linearize: eigenvalues of the constrained dynamics about an
// equilibrium or a steady motion, in independent coordinates.
#include "commands.hpp"

#include <appell/output.hpp>

#include <appell/appell.hpp>
#include <appell/equilibria.hpp>
#include <appell/linearization.hpp>

#include <algorithm>
#include <iomanip>
#include <iostream>

namespace appell::cli {

namespace {

const char* kHelp = R"(usage: appell linearize SCENE.urdf [options]

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

Exit status 3 when the reference is not an equilibrium / steady motion.
  --package-path DIRS
)";

}  // namespace

int linearize(int argc, char** argv) {
  Args args(argc, argv, 2, {"cyclic", "formulation", "zero-tol", "package-path"},
            {"help", "equilibrium", "project-initial", "no-joint-limits"});
  if (args.has("help")) {
    std::cout << helpText(kHelp);
    return 0;
  }
  const Scene scene = loadFromArgs(args, !args.has("equilibrium"));
  const Model& m = scene.model;
  VecX q = scene.q0, v = scene.v0;
  if (args.has("equilibrium")) {
    EquilibriumOptions eo;
    if (scene.tau.size() == m.nv) eo.tau = scene.tau;
    const EquilibriumResult e = findEquilibrium(m, scene.constraints, scene.q0, eo);
    if (!e.converged) {
      std::cout << e.message << "\n";
      return 3;
    }
    q = e.q;
    v.setZero();
    std::cout << "equilibrium found (residual " << e.residual << ", local dimension "
              << e.manifold_dimension << ")\n";
  }
  LinearizationOptions lo;
  if (scene.tau.size() == m.nv) lo.tau = scene.tau;
  for (const std::string& c : args.list("cyclic")) {
    int k;
    try {
      k = localCoordinateIndex(m, c);
    } catch (const std::invalid_argument& e) {
      throw UsageError(std::string("--cyclic: ") + e.what());
    }
    if (k < 0) throw UsageError("--cyclic: no coordinate named '" + c + "' (names as the CSV's q: and v: columns)");
    lo.cyclic.push_back(k);
  }
  Formulation form;
  try {
    form = formulationFromString(args.text("formulation", scene.settings.formulation));
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  auto solver = makeSolver(form, m, scene.constraints);
  const LinearizationResult r = linearize(m, scene.constraints, *solver, q, v, lo);
  // Finite differences split a zero Jordan block by ~√(round-off): 1e-4 absorbs that.
  const double zero_tol = args.positiveNumber("zero-tol", 1e-4);

  std::vector<std::complex<double>> ev(r.eigenvalues.data(), r.eigenvalues.data() + r.eigenvalues.size());
  std::sort(ev.begin(), ev.end(), [](auto a, auto b) {
    return a.real() != b.real() ? a.real() > b.real() : a.imag() > b.imag();
  });
  std::cout << "scene " << scene.source << "\n"
            << "reduced state dimension " << r.dimension << " (tangent space of the constraint manifold)\n"
            << "reference: constraint residual " << r.constraint_residual << ", steady residual "
            << r.steady_residual;
  if (!lo.cyclic.empty()) std::cout << ", symmetry residual " << r.symmetry_residual;
  std::cout << "\neigenvalues (real, imag):\n" << std::setprecision(8);
  for (const auto& z : ev)
    std::cout << "  " << std::setw(16) << z.real() << "  " << std::setw(16) << z.imag() << "\n";
  // Relative to the eigenvalues' scale: round-off in a fast system's
  // eigenvalues is larger than 1e-4 in absolute terms, and is not instability.
  double scale = 1.0;
  for (const auto& z : ev) scale = std::max(scale, std::abs(z));
  const double tol = zero_tol * scale;
  const int zeros = countZeroEigenvalues(r, tol);
  const double max_re = ev.empty() ? 0.0 : ev.front().real();
  std::cout << zeros << " zero eigenvalues (|μ| < " << tol << " = zero-tol × max(1, max |μ|))\n";
  // A verdict needs a true equilibrium / steady motion; otherwise say why not.
  if (r.steady_residual > 1e-6 * scale || r.constraint_residual > 1e-8) {
    std::cout << "no stability verdict: the reference state is not an equilibrium or steady motion"
              << " (steady residual " << r.steady_residual << "); try --equilibrium or --cyclic\n";
    return 3;
  }
  std::cout << (max_re > tol ? "unstable: largest real part " + std::to_string(max_re)
                                  : std::string("no exponentially growing mode (to within the zero tolerance)"))
            << "\n";
  return 0;
}

}  // namespace appell::cli
