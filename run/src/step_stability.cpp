#include "step_stability.hpp"

#include <appell/linearization.hpp>

#include <cmath>
#include <complex>
#include <sstream>

namespace appell::run_detail {

namespace {

/// A unilateral contact this close (m or rad) counts as touching.
constexpr double kTouching = 1e-6;

/// |R(z)| of classical RK4.
double rk4Amplification(std::complex<double> z) {
  const std::complex<double> r = 1.0 + z * (1.0 + z * (0.5 + z * (1.0 / 6.0 + z / 24.0)));
  return std::abs(r);
}

/// The largest h' ≤ h with |R(λh')| ≤ 1 (bisection: the region is star-shaped
/// about 0 along any ray with Re λ < 0 in the range that matters here).
double stableStep(std::complex<double> lambda, double h) {
  double lo = 0, hi = h;
  for (int k = 0; k < 60; ++k) {
    const double mid = 0.5 * (lo + hi);
    (rk4Amplification(lambda * mid) <= 1.0 ? lo : hi) = mid;
  }
  return lo;
}

}  // namespace

std::string stepStabilityCause(const Scene& scene, const Simulator& sim, const RunOptions& options) {
  if (options.integrator != IntegratorType::RK4) return "";
  const Model& model = scene.model;
  if (model.nv > 200) return "";  // a dense eigenproblem: only where it is cheap
  // The constraints as they act now: the closed ones, and the unilateral
  // ones still touching (a failure at a contact that keeps switching leaves
  // it open in the last state, but its modes are the ones the steps ran on).
  ConstraintList closed;
  const ConstraintData& cd = sim.constraintData();
  for (int c = 0; c < static_cast<int>(scene.constraints.size()); ++c) {
    const Constraint& con = *scene.constraints[c];
    const bool touching =
        con.unilateral() && std::abs(cd.gap[cd.offset[c] + con.unilateralRow()]) <= kTouching;
    if (cd.isActive(c) || touching) closed.push_back(scene.constraints[c]);
  }
  LinearizationResult lin;
  try {
    auto solver = makeSolver(Formulation::Tree, model, closed);
    LinearizationOptions lo;
    lo.time = sim.time();
    if (const Simulator::JointForces forces = scene.jointForces()) {
      lo.tau = VecX::Zero(model.nv);
      forces(sim.time(), sim.q(), sim.v(), lo.tau);
    }
    lin = linearize(model, closed, *solver, sim.q(), sim.v(), lo);
  } catch (const std::exception&) {
    return "";  // no diagnosis rather than a wrong one
  }
  const double h = options.dt;
  double worst = 1.0, h_stable = h;
  std::complex<double> mode;
  for (int k = 0; k < lin.eigenvalues.size(); ++k) {
    const std::complex<double> lambda = lin.eigenvalues[k];
    if (lambda.real() > 0) continue;  // grows in the true motion too: not the step's doing
    const double amp = rk4Amplification(lambda * h);
    if (amp <= 1.0 + 1e-9) continue;
    if (amp > worst) {
      worst = amp;
      mode = lambda;
    }
    h_stable = std::min(h_stable, stableStep(lambda, h));
  }
  if (worst <= 1.0) return "";
  std::ostringstream s;
  s.precision(3);
  s << "; the root cause: the step dt = " << h
    << " s is outside RK4's stability region for this motion — its fastest mode, λ = "
    << mode.real() << (mode.imag() >= 0 ? " + " : " − ") << std::abs(mode.imag())
    << "i /s (|λ|·dt = " << std::abs(mode) * h << "), is damped in the true motion but grows by "
    << worst << "× per step in the integration; dt ≤ " << 0.9 * h_stable
    << " s keeps every such mode stable, or use dopri5 (it adapts the step)";
  return s.str();
}

}  // namespace appell::run_detail
