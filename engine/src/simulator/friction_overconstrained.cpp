// Sticking contacts that become over-constrained while they move.
//
// A car whose two front knuckles turn by the same angle δ (parallel
// steering, a linear mimic) has no common instantaneous centre for its four
// tyres once δ ≠ 0: with all four sticking, the lateral rows of the front
// pair and the rear axle leave no forward motion. Rolling straight at speed
// and starting to steer, the rows' mismatch grows like δ² (det ∝ t δ², t the
// track) and sticking would need internal lateral forces growing like δ̇/δ
// — past every friction cone from δ = 0⁺: physically one tyre starts to
// scrub at once. Until that mismatch exceeds the solver's rank tolerance the
// rows count as redundant and consistent; past it, the solve reports them
// inconsistent and the step fails (docs/contacts.md §8, Known limits).
//
// That failure is the event. At the failed stage's state, with every
// sticking contact's friction rows released (as the onset does,
// friction_onset.cpp), the slip accelerations are ṡ = a⁰ + W f. Sticking
// asks W f = −a⁰. Let Z span the eigenvectors of W whose eigenvalues are at
// its round-off (relative 10⁻¹⁰: the solver's rank tolerance squared is far
// below, a physical Delassus ratio far above). Exact redundancies (two
// wheels on one rigid axle) have a⁰ ⟂ Z; the over-constraint is
//     g = Z Zᵀ a⁰ ≠ 0,
// the part of the free slip acceleration no finite force can cancel: the
// sticking force along −g is unbounded. As it grows, the contact whose cone
// it fills first is the j that maximises |gⱼ| / (μⱼ λₙⱼ) (λₙ the normal loads
// with friction released): that contact slides, from zero slip, with its
// friction along −gⱼ (Pfeiffer & Glocker, "Multibody Dynamics with
// Unilateral Contacts", 1996, §7.3: a sticking contact whose demand reaches
// the cone slides). The step is redone from its start with it sliding; its
// settled direction (friction_settled.cpp) then decides the force each
// evaluation, the others stay sticking and are consistent again. The event
// is located where the mismatch crossed the rank tolerance, not at δ = 0⁺
// (measured: δ ≈ 1.2·10⁻⁵ rad, docs/contacts.md §8).
#include <appell/kinematics.hpp>
#include <appell/simulator.hpp>

#include "simulator/simulator_impl.hpp"

#include <cmath>

namespace appell {

using detail::UnilateralRow;

int Simulator::Impl::overconstrainedContact(double t, const VecX& q, const VecX& v) {
  auto& u = *uni_;
  evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t, q, v);
  detail::gatherByIsland(u.islands, u.onset, u.onset_runs, [&](int k) {
    const UnilateralRow& r = u.rows[k];
    return r.nf > 0 && cdata_->isActive(r.c) && !cdata_->isSliding(r.c);
  });
  if (u.onset.empty()) return -1;
  for (int k : u.onset) {
    cdata_->setSliding(u.rows[k].c, true);
    u.rows[k].released = true;
  }
  evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t, q, v);
  tau_.setZero();
  if (tau_fn_) tau_fn_(t, q, v, tau_);
  // The contact whose cone the unbounded sticking force fills first, over
  // every island (each its own W: islands.cpp).
  int pick = -1;
  double worst = 0;
  Vec3 dir = Vec3::Zero();
  for (int i = 0; i + 1 < static_cast<int>(u.onset_runs.size()) && pick != -2; ++i) {
    const int k = overconstrainedIsland(t, q, v, detail::runOf(u.onset, u.onset_runs, i), worst, dir);
    if (k != -1) pick = k;
  }
  for (int k : u.onset) {
    cdata_->setSliding(u.rows[k].c, false);
    u.rows[k].released = false;
  }
  if (pick < 0) return -1;
  // Its friction along −gⱼ: it slips along +gⱼ.
  u.rows[pick].dir = dir;
  return pick;
}

/// One island's over-constraint: the row (and its slip direction, in `dir`)
/// whose demand-to-budget ratio exceeds `worst` (which it raises), −1 when
/// none does, −2 when a solve failed (no contact is picked then).
int Simulator::Impl::overconstrainedIsland(double t, const VecX& q, const VecX& v,
                                           std::span<const int> run, double& worst, Vec3& dir) {
  auto& u = *uni_;
  auto& p = u.onset_problem;
  const int K = static_cast<int>(run.size());
  const int F = detail::numberUnknowns(u.rows, run, &UnilateralRow::first_force);
  frictionUnitForces(run, &UnilateralRow::first_force, p);
  const bool ok = frictionResponses(t, q, v, tau_, run, &UnilateralRow::first_force, F, p);
  if (!ok || !p.W.topLeftCorner(F, F).allFinite() || !p.a0.head(F).allFinite()) return -2;

  // W's round-off null space, on the storage sized for the largest island's
  // friction rows: the rows past F carry an identity at W's scale (never null).
  const int nf = static_cast<int>(u.over_W.rows());
  const double wmax = std::max(p.W.topLeftCorner(F, F).cwiseAbs().maxCoeff(), 1e-300);
  u.over_W.setZero();
  u.over_W.topLeftCorner(F, F) = 0.5 * (p.W.topLeftCorner(F, F) + p.W.topLeftCorner(F, F).transpose());
  for (int i = F; i < nf; ++i) u.over_W(i, i) = wmax;
  u.over_eig.compute(u.over_W);
  if (u.over_eig.info() != Eigen::Success) return -2;
  const VecX& w = u.over_eig.eigenvalues();
  const MatX& Y = u.over_eig.eigenvectors();
  u.over_g.setZero();
  for (int i = 0; i < nf && w[i] <= 1e-10 * wmax; ++i)  // (ascending)
    u.over_g.head(F) += Y.col(i).head(F) * Y.col(i).head(F).dot(p.a0.head(F));
  // a⁰'s round-off: its terms are accelerations of the size of |a⁰|∞ and g.
  const double floor = 1e-11 * std::max(1.0, p.a0.head(F).lpNorm<Eigen::Infinity>());
  if (!(u.over_g.head(F).lpNorm<Eigen::Infinity>() > floor)) return -1;

  int pick = -1;
  for (int j = 0; j < K; ++j) {
    const UnilateralRow& r = u.rows[run[j]];
    const double demand = u.over_g.segment(r.first_force, r.nf).norm();
    const double budget = r.mu * std::max(p.ln0[j], 0.0);
    // (A contact with no load holds nothing: it is the first to go.)
    const double ratio = budget > 0 ? demand / budget : (demand > 0 ? HUGE_VAL : 0.0);
    if (ratio > worst) {
      worst = ratio;
      pick = run[j];
      dir.setZero();
      dir.head(r.nf) = u.over_g.segment(r.first_force, r.nf).normalized();
    }
  }
  return pick;
}

}  // namespace appell
