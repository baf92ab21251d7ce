// Coulomb friction of sliding contacts, by superposition of solves.
//
// A sliding contact j keeps its normal row; its friction rows are replaced by
// the force −μⱼ λₙⱼ ŝⱼ at the contact point against the slip direction ŝⱼ
// (docs/contacts.md §8). The force's direction is not its row's, so the
// system M v̇ + h = τ + Aᵀλ + Σⱼ λₙⱼ gⱼ is no longer symmetric — but for a
// fixed state it is affine in the applied joint forces, for every
// formulation (v̇ and the minimum-norm λ alike). With gⱼ = J_jᵀ wⱼ the
// generalized force of the unit-normal-load friction wrench wⱼ = −μⱼ Wⱼᵀŝⱼ
// (Wⱼ: the friction rows' covectors, i.e. the point-force directions at the
// contact), one solve at τ gives λₙ⁰ and one at τ + gⱼ per sliding contact the
// response Rᵢⱼ = λₙᵢ(τ + gⱼ) − λₙᵢ⁰, so the normal loads solve
//     (1 − R) λₙ = λₙ⁰,
// and the final solve at τ + Σ λₙⱼ gⱼ is exact: k + 2 solves for k sliding
// contacts, O(k n) with the tree solver (the Schur complement on top of its
// passes the friction issue asks for). A singular 1 − R, or a sliding normal
// load that would pull, is a configuration with no consistent sliding mode
// (Painlevé 1895; Pfeiffer & Glocker 1996, §7.4): reported with the contacts.
#include <appell/kinematics.hpp>
#include <appell/simulator.hpp>

#include "simulator/simulator_impl.hpp"

#include <algorithm>
#include <cmath>

namespace appell {

using detail::UnilateralRow;

/// The slip direction of a sliding contact from its rows' slip velocities.
/// Within a step the slip never reverses (a reversal is an event that ends
/// the step), so a stage state whose slip is below `floor` or points against
/// the step's starting direction — a slip just starting from rest, where a
/// stage's truncation error (O(h²ω²v) for a fast-spinning wheel) exceeds the
/// slip itself — keeps the step's starting direction.
void detail::slipDirection(const ConstraintData& cd, UnilateralRow& r, double floor) {
  const auto& sr = cd.slide[r.c];
  // Components beyond the contact's friction rows are zero throughout (the
  // rows' storage starts zero), so whole 3-vectors are used.
  const double speed = sr.slip.norm();
  // Regularized: a continuous function of the slip, linear below the creep
  // speed — the force −μₖλₙ dir is then smooth in the state and the slip may
  // pass through zero without an event.
  if (r.creep > 0) {
    r.dir = sr.slip / std::max(speed, r.creep);
    return;
  }
  if (speed > floor && sr.slip.dot(r.dir_start) > 0) r.dir = sr.slip / speed;
  else r.dir = r.dir_start;
}

// Marks the sliding contacts (u.sliding, island by island); true when one
// of them may slide on its settled direction (friction_settled.cpp): its
// slip is small beside the state's speeds.
bool Simulator::Impl::markSliding(const VecX& v) {
  auto& u = *uni_;
  const double screen = options_.contacts.settle_time > 0 && !u.settle_off
                            ? detail::kSettleScreen * v.lpNorm<Eigen::Infinity>()
                            : -1.0;
  bool settling = false;
  detail::gatherByIsland(u.islands, u.sliding, u.sliding_runs, [&](int k) {
    UnilateralRow& r = u.rows[k];
    if (r.released) return false;
    r.settling = false;
    if (!cdata_->isActive(r.c) || !cdata_->isSliding(r.c)) return false;
    if (r.nf > 0 && r.creep == 0 && cdata_->slide[r.c].slip.norm() <= screen) r.settling = settling = true;
    return true;
  });
  return settling;
}

// Friction forces per unit normal load gⱼ (columns of u.G) of one island's
// sliding contacts, from the rows' covectors (world spatial forces on A and
// B) and their slip directions, with data_ at forwardKinematics(q, v).
void Simulator::Impl::slidingFrictionColumns(std::span<const int> run) {
  auto& u = *uni_;
  for (int j = 0; j < static_cast<int>(run.size()); ++j) {
    const UnilateralRow& r = u.rows[run[j]];
    const auto& sr = cdata_->slide[r.c];
    const Vec3 f = -r.mu_k * r.dir;  // components along the friction rows (kinetic μ)
    auto g = u.G.col(j);
    g.setZero();
    if (r.a >= 0) {
      spatialJacobianWorld(model_, *data_, r.a, u.J);
      g.noalias() += u.J.transpose() * (sr.Wa.transpose() * f);
    }
    if (r.b >= 0) {
      spatialJacobianWorld(model_, *data_, r.b, u.J);
      g.noalias() -= u.J.transpose() * (sr.Wb.transpose() * f);
    }
  }
}

// 1 − R of one island (its sliding contacts from u.sliding[first] on), R the
// normal loads' responses to each contact's unit friction force: one solve at
// τ + gⱼ per sliding contact, against λₙ⁰ (u.lam0, the solve at τ).
bool Simulator::Impl::slidingLoadResponses(const VecX& q, const VecX& v, const VecX& tau,
                                           int first, std::span<const int> run,
                                           ConstrainedResult& out) {
  auto& u = *uni_;
  const int k = static_cast<int>(run.size());
  for (int j = 0; j < k; ++j) {
    u.tau_unit = tau + u.G.col(j);
    kernelSolve(q, v, u.tau_unit, u.unit, SolveOutputs::All);
    if (!u.unit.ok) {
      out.ok = false;
      out.error = u.unit.error;
      return false;
    }
    for (int i = 0; i < k; ++i)
      u.R(i, j) = (i == j ? 1.0 : 0.0) - (u.unit.lambda[u.rows[run[i]].global] - u.lam0[first + i]);
  }
  return true;
}

// The normal loads of one island's sliding contacts, (1 − R) λₙ = λₙ⁰ on the
// leading block of R's storage (sized for the largest island), into u.s;
// their friction added to u.tau_f and its power to u.friction_power.
// 1 − R is how the normal loads answer themselves through the friction
// they cause. A consistent, unique sliding mode for every λₙ⁰ needs it to
// be a P-matrix (Cottle, Pang & Stone, The Linear Complementarity Problem,
// 1992, §3.3): for one contact 1 − R > 0 — Painlevé's rod at μ > 4/3 is
// the classic failure (Stewart, SIAM Review 42 (2000) 3–39) — and a
// positive determinant in general (necessary). Otherwise the loads have no
// solution with λₙ ≥ 0 or several: reported, never picked.
bool Simulator::Impl::slidingNormalLoads(const VecX& q, const VecX& v, const VecX& tau, int first,
                                         std::span<const int> run, ConstrainedResult& out) {
  auto& u = *uni_;
  const int k = static_cast<int>(run.size());
  slidingFrictionColumns(run);
  if (!slidingLoadResponses(q, v, tau, first, run, out)) return false;
  auto fail = [&](const char* why) {
    out.ok = false;
    out.error = std::string("sliding friction: ") + why + " at contacts";
    for (int j : run) out.error += " '" + constraints_[u.rows[j].c]->name() + "'";
    out.error += " (a Painlevé-type configuration: no consistent sliding mode)";
    return false;
  };
  u.lu.compute(u.R.topLeftCorner(k, k));
  const double det = u.lu.determinant();
  if (!(std::abs(det) > 1e-12)) return fail("the normal loads are not determined");
  if (det < 0)
    return fail("the friction of the sliding contacts turns their normal loads against "
                "themselves (det(1 − R) < 0)");
  u.s.segment(first, k) = u.lu.solve(u.lam0.segment(first, k));
  if (!u.s.segment(first, k).allFinite()) return fail("the normal loads are not finite");
  for (int j = 0; j < k; ++j) u.tau_f.noalias() += u.s[first + j] * u.G.col(j);
  // The power these forces take, −vᵀ(τ_f − τ): the work balance's rate.
  for (int j = 0; j < k; ++j) u.friction_power -= u.s[first + j] * u.G.col(j).dot(v);
  return true;
}

bool Simulator::Impl::solveDynamics(double t, const VecX& q, const VecX& v, const VecX& tau,
                              ConstrainedResult& out, SolveOutputs outputs) {
  auto* u = uni_.get();
  if (u && markSliding(v)) return solveSettling(t, q, v, tau, out, outputs);
  if (u) u->friction_power = 0;
  if (!u || u->sliding.empty()) {
    kernelSolve(q, v, tau, out, outputs);
    return out.ok;
  }
  const int k = static_cast<int>(u->sliding.size());
  for (int j : u->sliding)
    detail::slipDirection(*cdata_, u->rows[j], 10 * options_.contacts.speed_tol);
  // λₙ⁰: the solve at τ (the full result in out).
  kernelSolve(q, v, tau, out, SolveOutputs::All);
  if (!out.ok) return false;
  for (int i = 0; i < k; ++i) u->lam0[i] = out.lambda[u->rows[u->sliding[i]].global];
  // Island by island: their loads do not answer one another's friction.
  u->tau_f = tau;
  for (int i = 0; i + 1 < static_cast<int>(u->sliding_runs.size()); ++i)
    if (!slidingNormalLoads(q, v, tau, u->sliding_runs[i],
                            detail::runOf(u->sliding, u->sliding_runs, i), out))
      return false;
  kernelSolve(q, v, u->tau_f, out, outputs);
  if (!out.ok) return false;
  if (outputs != SolveOutputs::All) return true;
  // Report the friction force on the friction rows' multipliers: the force
  // along each row's direction, as for a sticking contact.
  for (int j = 0; j < k; ++j) {
    const UnilateralRow& r = u->rows[u->sliding[j]];
    const auto& sr = cdata_->slide[r.c];
    for (int i = 0; i < sr.n; ++i)
      out.lambda[cdata_->offset[r.c] + sr.row[i]] = -r.mu_k * u->s[j] * r.dir[i] * sr.scale[i];
  }
  return true;
}

}  // namespace appell
