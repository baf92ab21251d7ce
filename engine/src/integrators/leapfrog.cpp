// Generalised Störmer–Verlet (leapfrog) for v̇ = f(t, q, v), q̇ = G(q) v,
// and with constraints the RATTLE-type scheme built on it:
//   v½ = v + ½h F(t, q, v½) + Δ       Δ = M(q)⁻¹A(q)ᵀν, with the discrete
//                                      constraints  g(q⁺) = 0  (holonomic
//                                      rows, RATTLE's) and  A(q ⊕ ½h v½) v½
//                                      + b = 0  (the others, at the midpoint)
//   q⁺ = q ⊕ h v½                      exact flow of the frozen velocity
//   v⁺ = v½ + ½h F(t + h, q⁺, v½)      then the simulator's M-orthogonal
//                                      projection onto A(q⁺) v⁺ + b = 0
// (unconstrained: Δ = 0, F = f, the non-separable Störmer–Verlet of Hairer,
// Lubich & Wanner, Geometric Numerical Integration, §VI.3; RATTLE: Andersen,
// J. Comput. Phys. 52 (1983) 24–34; the midpoint discrete constraint for
// nonholonomic rows as in McLachlan & Perlmutter, J. Nonlinear Sci. 16
// (2006) 283–328). The map is symmetric: from (q⁺, −v⁺) the same step returns
// (q, −v), because q⁺ ⊕ (−h v½) = q (configuration.hpp, integrate), the
// midpoint and the end gaps are the same seen from either end, and the end
// projection is the first kick's impulse Δ run backwards — whenever
// F(q, −v) = F(q, v) and b = 0 (every scleronomic system: the multipliers are
// quadratic in v). Symmetric and consistent, so of order 2; the constraints
// hold at every step; and on reversible integrable problems the energy error
// stays bounded instead of drifting (Modin & Verdier, Numer. Math. 145
// (2020) 405–435, who also show that this is lost on problems without the
// reversibility). Projecting only at the end of the step (Δ = 0, the
// simulator's projections alone) is not symmetric: on the rolling disk the
// energy then drifts linearly (2·10⁻² in 200 s at h = 10 ms; bounded at
// 2·10⁻⁴ with Δ).
//
// The first kick is a fixed point in (v½, Δ): each iteration evaluates F and
// one constrainKick (the discrete constraints' residuals removed by impulses
// at q; it contracts them by O(h)). It converges when ½h ‖∂F/∂v‖ < 1 —
// gyroscopic and constraint-curvature terms, the size of the angular rates —
// and is iterated to round-off, because a half-converged kick breaks the
// symmetry. Plain iteration gains the factor ½h ‖∂F/∂v‖ per evaluation
// (≈ 1/40 on the rolling disk at h = 10 ms: seven iterations); Anderson
// mixing of the last few residuals (Walker & Ni, SIAM J. Numer. Anal. 49
// (2011) 1715–1735; on a nearly linear map, GMRES on I − ½h ∂F/∂v) needs
// three to five. Unconstrained, its history is kept from step to step
// (∂f/∂v moves by O(h)); constrained it restarts each step, because Δ must
// stay a combination of impulses at this step's q. The predictor
// extrapolates the last step's stages: with A = F(q, v½) and B = F(q⁺, v½)
// of the last step and B' the end stage before it, the next F(q⁺, v⁺½) ≈
// B + (A − B') — A − B' is the change with the last velocity increment at
// nearly the same configuration, which the next one repeats to O(h²).
//
// Sliding friction with a slip far below the speeds around it makes
// ∂F/∂v large (docs/contacts.md, Known limits (2)); the fixed point then
// diverges and the step fails saying so.
#include "integrators/integrators_impl.hpp"

#include <cmath>

namespace appell::detail {

Leapfrog::Leapfrog(const Model& model, const IntegratorOptions& options)
    : model_(model),
      opt_(options),
      a_(model.nv),
      a_end_(model.nv),
      a_shift_(VecX::Zero(model.nv)),
      vh_(model.nv),
      w_(model.nv),
      y_(model.nv),
      xp_(model.nv),
      z_(2 * model.nv),
      g_(2 * model.nv),
      res_(2 * model.nv),
      g_prev_(2 * model.nv),
      res_prev_(2 * model.nv),
      dF_(2 * model.nv, kAndersonDepth),
      dG_(2 * model.nv, kAndersonDepth),
      q1_(model.nq) {}

void Leapfrog::dropOldestPair() {
  for (int c = 0; c + 1 < depth_; ++c) {
    dF_.col(c) = dF_.col(c + 1);
    dG_.col(c) = dG_.col(c + 1);
  }
  --depth_;
}

// Anderson mixing of depth ≤ kAndersonDepth: z⁺ = G − ΔG γ with γ the
// least-squares fit of the residual by its recent differences ΔF (each pair
// scaled to |ΔF| = 1, which leaves z⁺ alone and keeps the normal equations'
// conditioning that of the directions). Mixing keeps Δ in the span of the
// rows' impulses: it only combines such Δs.
void Leapfrog::mixAnderson(int k, double change, double previous, double scale) {
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
  z_ = g_;
  while (depth_ > 0) {
    const SmallMat gram = dF_.leftCols(depth_).transpose() * dF_.leftCols(depth_);
    const SmallVec rhs = dF_.leftCols(depth_).transpose() * res_;
    const Eigen::LDLT<SmallMat> ldlt(gram);
    const SmallVec gamma = ldlt.solve(rhs);
    if (ldlt.info() == Eigen::Success && gamma.allFinite() && ldlt.rcond() > 1e-10) {
      z_.noalias() -= dG_.leftCols(depth_) * gamma;
      return;
    }
    dropOldestPair();  // nearly dependent differences
  }
}

// F(q, x) = f(q, P_q x): f at the velocity's projection onto the rows at
// q. With redundant rows (a box flat on the ground) f exists only on the
// rows — off them their acceleration-level right sides disagree. Both
// kicks discard f's constraint part anyway (Δ absorbs it, the end
// projection removes it); what changes is that the velocity-dependent
// forces are taken at P_q x, which differs from x by O(h): the method stays
// consistent, and symmetric since F(q, −x) = F(q, x).
bool Leapfrog::projectedField(AccelerationField& f, double t, const VecX& q, const VecX& x, VecX& out) {
  if (!f.constrained()) return f(t, q, x, out);
  xp_ = x;
  return f.projectVelocity(t, q, xp_) && f(t, q, xp_, out);
}

// The drift to q⁺ = q ⊕ h v½ and the second kick v⁺ = v½ + ½h F(q⁺, v½);
// the step's power integrals by the trapezoid over the two kicks' stages.
bool Leapfrog::endKick(AccelerationField& f, double& t, VecX& q, VecX& v, double h, StepResult& r) {
  StageRates start{}, end{};
  vh_ = z_.head(model_.nv);
  readRates(f, start);  // at (q, v½) of the last iterate
  // A − B' for the next predictor (B' is a_end_ until it is overwritten below).
  if (have_end_) a_shift_ = a_ - a_end_;
  else a_shift_.setZero();
  integrate(model_, q, vh_, h, q1_);
  ++r.evaluations;
  if (!q1_.allFinite() || !projectedField(f, t + h, q1_, vh_, a_end_) || !a_end_.allFinite()) {
    have_end_ = false;
    return false;
  }
  readRates(f, end);
  have_end_ = true;
  v = vh_ + (0.5 * h) * a_end_;
  q = q1_;
  t += h;
  r.h_taken = r.h_next = h;
  // The powers, by the same rule: the trapezoid over the two kicks' stages.
  for (int i = 0; i < AccelerationField::kMaxRates; ++i) r.integrals[i] = 0.5 * h * (start[i] + end[i]);
  return true;
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
    if (!f(t, q, v, a_) || !a_.allFinite()) return failed(nullptr);  // v is on the rows
  }
  // The fixed point is on z = (x, Δ): x the half-step velocity, Δ its
  // accumulated constraint impulse (M⁻¹Aᵀν at q). One map G(z):
  //   w = v + ½h F(t, q, x),  y = constrainKick(t, q, h; w + Δ),  G(z) = (y, y − w)
  // whose fixed point is x = v + ½h F(q, x) + Δ with x meeting the discrete
  // constraints (for an unconstrained field Δ stays 0).
  const int n = model_.nv;
  const bool constrained = f.constrained();
  // The fixed points are the z with a zero residual at q ⊕ ½h x; Δ lies in
  // the span of the rows' impulses at q only because every iterate's does.
  // Differences carried from the last step hold impulses at the last q: with
  // constraints the history starts afresh each step.
  if (constrained) depth_ = 0;
  z_.head(n) = v + (0.5 * h) * a_;
  z_.tail(n).setZero();
  bool converged = false;
  double last_change = 0, first_change = 0;
  const char* diverged =
      "the leapfrog's implicit half-step did not converge (the step is too large for the "
      "velocity-dependent forces: ½h·|∂f/∂v| must stay below 1); use a smaller dt";
  for (int k = 0; k < opt_.implicit_max_iterations && !converged; ++k) {
    ++r.evaluations;
    vh_ = z_.head(n);  // x
    if (!projectedField(f, t, q, vh_, a_) || !a_.allFinite())
      return failed(k > 0 && last_change > first_change ? diverged : nullptr);
    w_ = v + (0.5 * h) * a_;
    g_.head(n) = w_ + z_.tail(n);
    if (constrained) {
      y_ = g_.head(n);
      if (!f.constrainKick(t, q, h, y_)) return failed(nullptr);
      g_.head(n) = y_;
    }
    g_.tail(n) = g_.head(n) - w_;
    res_ = g_ - z_;  // the fixed point's residual
    const double change = res_.lpNorm<Eigen::Infinity>();
    const double scale = 1 + g_.head(n).lpNorm<Eigen::Infinity>();
    if (!std::isfinite(change) || (k > 2 && change > 1e3 * first_change)) return failed(diverged);
    if (k == 0) first_change = change;
    // Converged: at the tolerance, or stalled at the field's round-off
    // floor (the change stopped shrinking while already tiny).
    const double previous = last_change;
    converged = change <= opt_.implicit_tol * scale ||
                (k > 0 && change > 0.5 * previous && change <= kRoundOffFloor * scale);
    last_change = change;
    if (converged) {
      z_.swap(g_);
      break;
    }
    mixAnderson(k, change, previous, scale);
  }
  if (!converged) return failed(diverged);
  if (!endKick(f, t, q, v, h, r)) return failed(nullptr);
  return r;
}

}  // namespace appell::detail
