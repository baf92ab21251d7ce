// Coulomb's law on an impact's friction impulses: sliding impacts.
//
// The impact stage (impact.cpp) finds the contacts in the impact
// and their normal impulses by principal pivoting, each contact sticking:
// its friction rows in the velocity projection, so the post-impact slip is
// zero whatever tangential impulse that takes. Coulomb's law bounds that
// impulse, |Pₜ| ≤ μ Pₙ — a ball dropped spinning on ice, a wheel landing
// sideways, a foot striking at an angle slide through the impact — and a
// contact that was sliding before takes no friction impulse there at all.
//
// So when a contact of the impact has friction and either was sliding or
// took a tangential impulse outside its cone, the friction impulses of all
// its contacts with friction are decided together, as the onset does for
// forces (friction_onset.cpp; Moreau 1988, Glocker 2001 at the impulse
// level): their friction rows released, the normal rows keeping Newton's
// law γ⁺ = −e γ⁻, the post-impact slips, the normal impulses and the
// velocities are affine in the friction impulses P,
//     s⁺ = s⁰ + W P,    Pₙ = Pₙ⁰ + N P,    v⁺ = v⁰ + V P,
// s⁰, Pₙ⁰, v⁰ from one projection without them, and W, N, V from one solve
// per unit row force — the constrained response to a force is the response
// to an impulse, the map being the same M-orthogonal projection (W is the
// onset's Delassus operator). Maximal dissipation at the impulse level,
//     min ½ PᵀW P + s⁰ᵀP   over   |Pⱼ| ≤ μⱼ Pₙⱼ,
// by block Gauss–Seidel over the contacts' disks, the normal impulses
// updated as it sweeps: a contact whose minimizer lies inside its static
// disk sticks (s⁺ = 0), one on it slides through the impact with the kinetic
// impulse μₖPₙ and leaves sliding along s⁺. A sliding contact's spin row
// (rolling without spin) takes no impulse: spin friction is not modelled.
// A normal impulse that the friction impulses would turn negative belongs,
// when its contact was at rest in the set (it did not approach; its normal
// impulse without friction was ~0 — a tyre that merely carried load while
// another landed), to a contact that separates: it is handed back
// (`separating`) and the impact phase solves the impact again without it
// (the pivot the normal impulses' complementarity asks for). A contact
// that approached has no consistent sliding impact (Painlevé's paradox at
// the impulse level: Stewart, SIAM Review 42 (2000)): reported with the
// contact named.
//
// A regularized contact (creep speed v_c, friction.cpp) takes part as a
// Coulomb contact: its law's force is μₖλₙ s/v_c with λₙ impulsive, so the
// slip relaxes within the impact on the impulse scale v_c/(μₖ W) — fast
// against a landing's normal impulse — which is Coulomb's sticking impact
// in the limit. It leaves sliding, as it always is when closed.
#include <appell/kinematics.hpp>
#include <appell/simulator.hpp>

#include "simulator/simulator_impl.hpp"

#include <cmath>

namespace appell {

using detail::UnilateralRow;

bool Simulator::Impl::frictionImpact(std::string& error, int& separating) {
  separating = -1;
  auto& u = *uni_;
  // Here v_ = v⁺ with every contact sticking, u.vplus = v⁻, u.impulse the
  // projection's multipliers (the push along a row is −impulse).
  if (!frictionImpactCandidates()) return true;
  u.vstick = v_;
  u.vminus = u.vplus;
  for (int k : u.onset) {
    u.was_sliding[k] = cdata_->isSliding(u.rows[k].c);
    cdata_->setSliding(u.rows[k].c, true);
    u.rows[k].released = true;
  }
  // Island by island (islands.cpp): each island's impulses, kept per row,
  // and v⁺ = v⁰ + Σ V P summed in u.vsum; applied once all are found.
  for (int i = 0; i + 1 < static_cast<int>(u.onset_runs.size()); ++i) {
    const int found = frictionImpactIsland(detail::runOf(u.onset, u.onset_runs, i), i == 0, error);
    if (found < 0) {
      releaseOnset(false);
      v_ = u.vstick;
      return false;
    }
    if (found == 0) {
      // Keep the sticking impact (its cone excess is then reported).
      ++counters_.friction_onset_unsettled;
      releaseOnset(false);
      v_ = u.vstick;
      forwardKinematics(model_, *data_, q_, v_);
      return true;
    }
  }
  v_ = u.vsum;
  if (!applyFrictionImpulses(separating, error)) return false;
  releaseOnset(true);
  forwardKinematics(model_, *data_, q_, v_);
  return true;
}

/// One island's friction impulses: 1 when found (kept in its rows' impact
/// state, V P added to u.vsum — which the first island starts at v⁰), 0
/// when the sweeps did not settle, −1 with `error` when a solve failed.
int Simulator::Impl::frictionImpactIsland(std::span<const int> run, bool first,
                                          std::string& error) {
  auto& u = *uni_;
  auto& p = u.onset_problem;
  const int K = static_cast<int>(run.size());
  const int F = detail::numberUnknowns(u.rows, run, &UnilateralRow::first_force);
  if (!frictionImpactMaps(run, F, error)) return -1;
  // Block Gauss–Seidel over the disks, the normal impulses updated: a
  // contact sticks inside its static disk, else slides on its kinetic one.
  const bool settled = p.gaussSeidel(K, F, 10000, counters_.block_updates, [&](int j) {
    const UnilateralRow& r = u.rows[run[j]];
    const int o0 = r.first_force, n = r.nf;
    const double pn = std::max(0.0, p.loadAt(j, F));
    Mat3 H;
    Vec3 c;
    p.disk(o0, n, F, H, c);
    Vec3 fj = detail::diskMinimizer(H, c, n, r.mu * pn);
    if (fj.norm() >= (1 - 1e-12) * r.mu * pn) fj = detail::diskMinimizer(H, c, n, r.mu_k * pn);
    p.f.segment(o0, n) = fj.head(n);
    return r.mu * pn;
  });
  if (!settled) return 0;
  // v⁺ = v⁰ + V P; the impulses and the slips after, for the log and the modes.
  if (first) u.vsum = u.vplus;
  u.vsum.noalias() += p.V.leftCols(F) * p.f.head(F);
  p.acc.head(F) = p.a0.head(F);
  p.acc.head(F).noalias() += p.W.topLeftCorner(F, F) * p.f.head(F);
  for (int j = 0; j < K; ++j) {
    UnilateralRow& r = u.rows[run[j]];
    r.load_after = p.loadAt(j, F);
    r.friction_impulse.setZero();
    r.friction_impulse.head(r.nf) = p.f.segment(r.first_force, r.nf);
    r.slip_after.setZero();
    r.slip_after.head(r.nf) = p.acc.segment(r.first_force, r.nf);
  }
  return 1;
}

bool Simulator::Impl::frictionImpactCandidates() {
  auto& u = *uni_;
  bool needed = false;
  detail::gatherByIsland(u.islands, u.onset, u.onset_runs, [&](int k) {
    const UnilateralRow& r = u.rows[k];
    if (!r.touching || !r.in_set || r.nf == 0) return false;
    const auto& sr = cdata_->slide[r.c];
    double pt = 0;
    for (int i = 0; i < sr.n; ++i)
      pt += std::pow(u.impulse[cdata_->offset[r.c] + sr.row[i]] / sr.scale[i], 2);
    needed = needed || cdata_->isSliding(r.c) ||
             std::sqrt(pt) > r.mu * std::max(0.0, r.impulse) * (1 + 1e-9);
    return true;
  });
  return needed;
}

void Simulator::Impl::releaseOnset(bool keep_modes) {
  auto& u = *uni_;
  for (int k : u.onset) {
    u.rows[k].released = false;
    if (!keep_modes) cdata_->setSliding(u.rows[k].c, u.was_sliding[k] != 0);
  }
}

/// The impact problem's maps at (t, q, v⁻), the friction rows released: the
/// responses to unit friction impulses (V, W, N), Newton's law on the normal
/// rows alone (v⁰ in u.vplus, Pₙ⁰ in p.ln0) and the slips s⁰ at v⁰ (p.a0).
bool Simulator::Impl::frictionImpactMaps(std::span<const int> run, int F, std::string& error) {
  auto& u = *uni_;
  auto& p = u.onset_problem;
  const int K = static_cast<int>(run.size());
  // The responses at (t, q, v⁻): they depend on q only.
  v_ = u.vminus;
  evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
  frictionUnitForces(run, &UnilateralRow::first_force, p);
  tau_.setZero();
  if (!frictionResponses(t_, q_, v_, tau_, run, &UnilateralRow::first_force, F, p, true)) {
    error = "impact with friction: " + p.res.error;
    return false;
  }
  // Newton's law on the normal rows alone: v⁰ (in u.vplus), Pₙ⁰ (in p.ln0).
  evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
  shiftImpactTargets();
  u.vplus = v_;
  if (!kernelProject(*cdata_, q_, u.vplus, u.impulse)) {
    error = "impact with friction: the impulse solve failed: " + solver_->lastError();
    return false;
  }
  for (int j = 0; j < K; ++j) p.ln0[j] = -u.impulse[u.rows[run[j]].global];
  // s⁰: the released rows' slips at v⁰.
  evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, u.vplus);
  for (int j = 0; j < K; ++j) {
    const UnilateralRow& r = u.rows[run[j]];
    p.a0.segment(r.first_force, r.nf) = cdata_->slide[r.c].slip.head(r.nf);
  }
  return true;
}

/// The settled impulses P (p.f, v_ = v⁺): each contact's normal and friction
/// impulses for the log and its mode after the impact. false (the impact
/// undone) when they would pull a contact, `separating` naming it when it
/// was at rest.
bool Simulator::Impl::applyFrictionImpulses(int& separating, std::string& error) {
  auto& u = *uni_;
  const ContactEventOptions& o = options_.contacts;
  for (int k : u.onset) {
    UnilateralRow& r = u.rows[k];
    const auto& sr = cdata_->slide[r.c];
    const double pn = r.load_after;
    if (pn < -o.force_tol) {
      releaseOnset(false);
      v_ = u.vstick;
      if (r.gamma >= -o.speed_tol) separating = k;  // at rest: it may separate instead
      error = "impact with friction: the friction impulses would pull contact '" +
              constraints_[r.c]->name() +
              "' off the support (a Painlevé-type impact: no consistent sliding impact)";
      return false;
    }
    r.impulse = pn;
    u.impulse[r.global] = -pn;
    for (int i = 0; i < sr.n; ++i)
      u.impulse[cdata_->offset[r.c] + sr.row[i]] = -r.friction_impulse[i] * sr.scale[i];
    const Vec3 slip = r.slip_after;
    const bool slides = slip.norm() > o.speed_tol;
    if (slides) {
      r.dir = slip / slip.norm();
      r.dir_start = r.dir;
    }
    // A regularized contact leaves sliding whatever its slip (its force is
    // then μₖλₙ s/v_c: no stick or slip event).
    cdata_->setSliding(r.c, slides || r.creep > 0);
    const bool was = u.was_sliding[k] != 0 && r.creep == 0;
    if (r.creep > 0) continue;
    if (slides && !was) logEvent(ContactEventKind::Slip, k, 0, slip.norm(), 0);
    if (!slides && was) logEvent(ContactEventKind::Stick, k, 0, 0, 0);
  }
  return true;
}

}  // namespace appell
