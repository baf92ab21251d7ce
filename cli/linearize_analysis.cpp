// One linearization as `appell linearize` does it (linearize_analysis.hpp).
#include "linearize_analysis.hpp"

#include <appell/appell.hpp>
#include <appell/equilibria.hpp>
#include <appell/output.hpp>

#include <Eigen/QR>

#include <algorithm>
#include <iostream>
#include <sstream>

namespace appell::cli {

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

std::vector<int> cyclicCoordinates(const Scene& scene, const Args& args) {
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
  return cyclic;
}

Formulation linearizeFormulation(const Scene& scene, const Args& args) {
  try {
    return formulationFromString(args.text("formulation", scene.settings.formulation));
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
}

const char* verdict(const Analysis& a) { return !a.ok ? "none" : a.unstable() ? "unstable" : "not growing"; }

}  // namespace appell::cli
