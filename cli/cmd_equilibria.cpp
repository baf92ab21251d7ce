// appell equilibria: static equilibria from several starting guesses.
#include "commands.hpp"

#include <appell/appell.hpp>
#include <appell/equilibria.hpp>
#include <appell/output.hpp>

#include <iomanip>
#include <iostream>
#include <random>

namespace appell::cli {

namespace {

const char* kHelp = R"(usage: appell equilibria SCENE.urdf [options]

Solves Q(q) + Aᵀ(q) λ = 0 with the holonomic gaps g(q) = 0 for (q, λ), keeping
the multipliers as unknowns, so equilibria held only by nonholonomic reactions
(of the "second kind", Emelyanova & Fufaev) are found too. Starts from the
scene's initial configuration and from random perturbations of it.

  --starts N        number of starting guesses (default 8; the first is q0)
  --spread S        size of the perturbations in local coordinates (default 0.5)
  --seed K          random seed (default 1)
  --tol TOL         scaled residual tolerance (default 1e-10)
  --package-path DIRS
)";

}  // namespace

int equilibria(int argc, char** argv) {
  Args args(argc, argv, 2, {"starts", "spread", "seed", "tol", "package-path"},
            {"help", "project-initial", "no-joint-limits"});
  if (args.has("help")) {
    std::cout << kHelp;
    return 0;
  }
  const Scene scene = loadFromArgs(args, false);
  const Model& m = scene.model;
  const int starts = args.integer("starts", 8);
  const double spread = args.positiveNumber("spread", 0.5);
  if (starts < 1) throw UsageError("option --starts must be at least 1");

  std::mt19937 rng(static_cast<unsigned>(args.integer("seed", 1)));
  std::uniform_real_distribution<double> u(-spread, spread);
  std::vector<VecX> guesses{scene.q0};
  VecX theta(m.nv), q(m.nq);
  for (int k = 1; k < starts; ++k) {
    for (int i = 0; i < m.nv; ++i) theta[i] = u(rng);
    retract(m, scene.q0, theta, q);
    guesses.push_back(q);
  }
  EquilibriumOptions opt;
  opt.tolerance = args.positiveNumber("tol", opt.tolerance);
  if (scene.tau.size() == m.nv) opt.tau = scene.tau;
  const MultiStartResult res = findEquilibria(m, scene.constraints, guesses, opt);

  const std::vector<std::string> cols = trajectoryColumns(m, scene.constraints);
  std::cout << "scene " << scene.source << ": " << starts << " starting guesses, "
            << res.distinct.size() << " distinct equilibria found\n";
  for (size_t n = 0; n < res.distinct.size(); ++n) {
    const EquilibriumResult& e = res.runs[res.distinct[n]];
    std::cout << "\nequilibrium " << n + 1 << " (from guess " << res.distinct[n] + 1 << ", "
              << e.iterations << " iterations, residual " << e.residual << ")\n"
              << "  local dimension of the equilibrium set: " << e.manifold_dimension
              << "; rank A = " << e.rank_A << " (" << e.redundant_rows << " redundant rows)\n  q:";
    for (int i = 0; i < m.nq; ++i)
      std::cout << (i % 4 == 0 ? "\n    " : "  ") << std::setw(22) << std::left
                << cols[1 + i].substr(2) << std::right << std::setw(12) << e.q[i];
    std::cout << "\n  reactions λ:";
    for (int r = 0; r < e.lambda.size(); ++r)
      std::cout << (r % 3 == 0 ? "\n    " : "  ") << std::setw(26) << std::left
                << e.row_labels[r] << std::right << std::setw(12) << e.lambda[r];
    std::cout << "\n";
    if (e.motion_residual > 1e-9)
      std::cout << "  note: the support moves here (|b| + |abias| = " << e.motion_residual << ")\n";
  }
  if (res.distinct.empty()) {
    double best = std::numeric_limits<double>::infinity();
    std::string why;
    for (const EquilibriumResult& e : res.runs)
      if (e.residual < best) {
        best = e.residual;
        why = e.message;
      }
    std::cout << "no equilibrium near any guess; best attempt: " << why << "\n";
  }
  return 0;
}

}  // namespace appell::cli
