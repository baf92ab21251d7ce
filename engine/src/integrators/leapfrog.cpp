// Generalised Störmer–Verlet (leapfrog) for v̇ = f(t, q, v), q̇ = G(q) v:
//   v½ = v + ½h f(t, q, v½)          implicit in v½: fixed-point iteration
//   q⁺ = q ⊕ h v½                     exact flow of the frozen velocity
//   v⁺ = v½ + ½h f(t + h, q⁺, v½)     explicit
// (Hairer, Lubich & Wanner, Geometric Numerical Integration, §VI.3, the
// non-separable Störmer–Verlet). The map is symmetric: stepping back from
// (q⁺, −v⁺) with the same h returns (q, −v) exactly whenever f(q, −v) =
// f(q, v), because q⁺ ⊕ (−h v½) = q (configuration.hpp, integrate) and the
// two half-kicks are each other's adjoint. Symmetric and consistent, so of
// order 2.
//
// For a constrained system f is the constrained acceleration (any of the
// three formulations); the simulator then projects q⁺ onto g = 0 and v⁺
// M-orthogonally onto A v + b = 0 (projection.hpp). The last half-kick
// followed by that projection is exactly RATTLE's: v⁺ = v½ + ½h M⁻¹(Q + Aᵀμ)
// with A(q⁺) v⁺ + b = 0, whatever multiplier f used (Andersen 1983, "Rattle";
// Leimkuhler & Reich, Simulating Hamiltonian Dynamics, §7.2). What keeps
// energy errors bounded is the reversibility (Modin & Verdier 2020); the
// projection, a non-symmetric map, is a perturbation of the size of the
// drift it removes (O(h³) per step).
//
// The fixed point converges when ½h ‖∂f/∂v‖ < 1 — gyroscopic and constraint-
// curvature terms, of the size of the angular rates — and is iterated to
// round-off, because a half-converged first kick breaks the symmetry. Plain
// iteration gains the factor ½h ‖∂f/∂v‖ (≈ 1/40 on the rolling disk at
// h = 10 ms: seven iterations); Anderson mixing of the last few residuals
// (Walker & Ni, SIAM J. Numer. Anal. 49 (2011) 1715–1735) — on a nearly
// linear map, GMRES on I − ½h ∂f/∂v — with its history kept from step to
// step (∂f/∂v moves by O(h)) needs three to four: 5.4 evaluations per step
// on the disk, 4.1 on the sleigh, against RK4's 4 (examples/, 100 s). The
// predictor extrapolates the last step's stages: with A = f(q, v½) and
// B = f(q⁺, v½) of the last step and B' the end stage before it, the next
// f(q⁺, v⁺½) ≈ B + (A − B') — A − B' is the change of f with the last
// velocity increment at nearly the same configuration, which the next one
// repeats to O(h²) — an O(h³) guess instead of B's O(h²).
#include "integrators/integrators_impl.hpp"

namespace appell::detail {

Leapfrog::Leapfrog(const Model& model, const IntegratorOptions& options)
    : model_(model),
      opt_(options),
      a_(model.nv),
      a_end_(model.nv),
      a_shift_(VecX::Zero(model.nv)),
      vh_(model.nv),
      g_(model.nv),
      res_(model.nv),
      g_prev_(model.nv),
      res_prev_(model.nv),
      dF_(model.nv, kAndersonDepth),
      dG_(model.nv, kAndersonDepth),
      q1_(model.nq) {}

void Leapfrog::dropOldestPair() {
  for (int c = 0; c + 1 < depth_; ++c) {
    dF_.col(c) = dF_.col(c + 1);
    dG_.col(c) = dG_.col(c + 1);
  }
  --depth_;
}

StepResult Leapfrog::step(AccelerationField& f, double& t, VecX& q, VecX& v, double h) {
  StepResult r;
  auto failed = [&](const char* why) {
    r.ok = false;
    r.failure = why;
    return r;
  };
  // Predictor: the last step's stages extrapolated — or one evaluation at (q, v).
  if (have_end_) {
    a_ = a_end_ + a_shift_;
  } else {
    ++r.evaluations;
    if (!f(t, q, v, a_) || !a_.allFinite()) return failed(nullptr);
  }
  vh_ = v + (0.5 * h) * a_;
  StageRates start{}, end{};
  bool converged = false;
  double last_change = 0;
  for (int k = 0; k < opt_.implicit_max_iterations && !converged; ++k) {
    ++r.evaluations;
    if (!f(t, q, vh_, a_) || !a_.allFinite()) return failed(nullptr);
    g_ = v + (0.5 * h) * a_;  // g(x) for x = vh_
    res_ = g_ - vh_;          // the fixed point's residual
    const double change = res_.lpNorm<Eigen::Infinity>();
    const double scale = 1 + g_.lpNorm<Eigen::Infinity>();
    // Converged: at the tolerance, or stalled at the field's round-off
    // floor (the change stopped shrinking while already tiny).
    const double previous = last_change;
    converged = change <= opt_.implicit_tol * scale ||
                (k > 0 && change > 0.5 * previous && change <= kRoundOffFloor * scale);
    last_change = change;
    if (converged) {
      vh_.swap(g_);
      break;
    }
    // Anderson mixing of depth ≤ kAndersonDepth: x⁺ = g − ΔG γ with γ the
    // least-squares fit of the residual by its recent differences ΔF (each
    // pair scaled to |ΔF| = 1, which leaves x⁺ alone and keeps the normal
    // equations' conditioning that of the directions).
    // A mixing step that did not halve the residual: the history (carried
    // from the last step, or spoiled by round-off) is stale — restart.
    if (k > 0 && change > 0.5 * previous) depth_ = 0;
    if (k > 0 && res_prev_.lpNorm<Eigen::Infinity>() > kPairFloor * scale) {
      if (depth_ == kAndersonDepth) dropOldestPair();
      const double norm = (res_ - res_prev_).norm();
      if (norm > 0) {
        dF_.col(depth_) = (res_ - res_prev_) / norm;
        dG_.col(depth_) = (g_ - g_prev_) / norm;
        ++depth_;
      }
    }
    res_prev_ = res_;
    g_prev_ = g_;
    vh_ = g_;
    while (depth_ > 0) {
      const SmallMat gram = dF_.leftCols(depth_).transpose() * dF_.leftCols(depth_);
      const SmallVec rhs = dF_.leftCols(depth_).transpose() * res_;
      const Eigen::LDLT<SmallMat> ldlt(gram);
      const SmallVec gamma = ldlt.solve(rhs);
      if (ldlt.info() == Eigen::Success && gamma.allFinite() && ldlt.rcond() > 1e-10) {
        vh_.noalias() -= dG_.leftCols(depth_) * gamma;
        break;
      }
      dropOldestPair();  // nearly dependent differences
    }
  }
  if (!converged)
    return failed(
        "the leapfrog's implicit half-step did not converge (the step is too large for the "
        "velocity-dependent forces: ½h·|∂f/∂v| must stay below 1); use a smaller dt");
  readRates(f, start);  // at (q, v½) of the last iterate
  // A − B' for the next predictor (B' is a_end_ until it is overwritten below).
  if (have_end_) a_shift_ = a_ - a_end_;
  else a_shift_.setZero();
  integrate(model_, q, vh_, h, q1_);
  ++r.evaluations;
  if (!q1_.allFinite() || !f(t + h, q1_, vh_, a_end_) || !a_end_.allFinite()) {
    have_end_ = false;
    return failed(nullptr);
  }
  readRates(f, end);
  have_end_ = true;
  v = vh_ + (0.5 * h) * a_end_;
  q = q1_;
  t += h;
  r.h_taken = r.h_next = h;
  // The powers, by the same rule: the trapezoid over the two kicks' stages.
  for (int i = 0; i < AccelerationField::kMaxRates; ++i) r.integrals[i] = 0.5 * h * (start[i] + end[i]);
  return r;
}

}  // namespace appell::detail
