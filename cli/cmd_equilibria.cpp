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

const char* kEquilibriaHelp = R"(usage: appell equilibria SCENE.urdf [options]

Solves Q(q) + Aᵀ(q) λ = 0 with the holonomic gaps g(q) = 0 for (q, λ), keeping
the multipliers as unknowns, so equilibria held only by nonholonomic reactions
(of the "second kind", Emelyanova & Fufaev) are found too, and says of each
whether it is of the first kind (the holonomic reactions alone hold it) or of
the second. Starts from the scene's initial configuration, from it turned
half a turn (each rotation joint's angle + π, a floating base about the
vertical: a sleigh's two blade orientations) and from random perturbations.
Equilibria on one connected set of equilibria (a sleigh resting anywhere
along a line) are reported as one set.

  --starts N        number of random starting guesses (default 8; the first is q0)
  --spread S        size of the perturbations in local coordinates (default 0.5)
  --seed K          random seed (default 1)
  --tol TOL         scaled residual tolerance (default 1e-10)
  --package-path DIRS
)" APPELL_INERTIA_HELP;

}  // namespace

int equilibria(int argc, char** argv) {
  Args args(argc, argv, 2, {"starts", "spread", "seed", "tol", "package-path", "bound-inertia", "bound-mass"},
            {"help", "project-initial", "no-joint-limits", "balance-inertia"});
  if (args.has("help")) {
    std::cout << kEquilibriaHelp;
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
  // The symmetric guesses a user expects: half a turn of each rotation
  // coordinate (θ slot of a revolute or continuous joint, a planar joint's
  // angle, a floating base's yaw about the vertical −g).
  for (int j = 0; j < m.nbodies; ++j) {
    const Joint& joint = m.joints[j];
    theta.setZero();
    switch (joint.type) {
      case JointType::Revolute: case JointType::Continuous: theta[joint.idx_v] = M_PI; break;
      case JointType::Planar: theta[joint.idx_v + 2] = M_PI; break;
      case JointType::Floating: {
        // θ's rotation part is about the body axes: the vertical in the body frame.
        const Vec3 up = m.gravity.norm() > 0 ? Vec3(-m.gravity.normalized()) : Vec3(Vec3::UnitZ());
        const Quat qb(scene.q0[joint.idx_q + 6], scene.q0[joint.idx_q + 3], scene.q0[joint.idx_q + 4],
                      scene.q0[joint.idx_q + 5]);
        theta.segment<3>(joint.idx_v) = M_PI * (qb.conjugate() * up);
        break;
      }
      case JointType::Fixed: case JointType::Prismatic: case JointType::Ball: continue;
    }
    retract(m, scene.q0, theta, q);
    guesses.push_back(q);
  }
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
  std::cout << "scene " << scene.source << ": " << guesses.size() << " starting guesses, "
            << res.distinct.size() << " distinct equilibria found on " << res.sets << " equilibrium set"
            << (res.sets == 1 ? "" : "s") << "\n";
  for (size_t n = 0; n < res.distinct.size(); ++n) {
    const EquilibriumResult& e = res.runs[res.distinct[n]];
    std::cout << "\nequilibrium " << n + 1 << " (from guess " << res.distinct[n] + 1 << ", "
              << e.iterations << " iterations, residual " << e.residual << ") on set " << res.set[n] + 1;
    for (size_t k = 0; k < n; ++k)
      if (res.set[k] == res.set[n]) {
        std::cout << " with equilibrium " << k + 1;
        break;
      }
    std::cout << "\n  "
              << (e.second_kind ? "second kind: held only with nonholonomic reactions (without them it "
                                  "would move; holonomic rows alone leave "
                                : "first kind: the holonomic reactions alone hold it (residual ")
              << e.holonomic_residual << ")\n"
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
