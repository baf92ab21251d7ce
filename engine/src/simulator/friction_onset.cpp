// The friction modes of contacts that are not slipping, decided together.
//
// At an instant where K closed contacts with friction have zero slip (at
// rest, at a stick event, at t = 0), whether each sticks or starts to slide
// — and in which direction — is one problem, not K: a block on four corners
// whose corners were made to slide one at a time, each against its own
// sticking force, slid with directions that carried lateral parts (the
// redundant corners' minimum-norm sticking forces), so too little friction
// acted downhill until the slips themselves set the directions.
//
// With every friction row of the K contacts released (their forces fⱼ
// unknown, their normal rows kept), the slip accelerations and the normal
// loads are affine in the forces — one solve of the scene's formulation at
// τ and one per unit row force (F + 1 solves for F friction rows, O(F n)
// with the tree solver):
//     ṡ = ṡ⁰ + W f,        λₙ = λₙ⁰ + N f,
// W = Jₜ M⁻¹(1 − Aᵀ(A M⁻¹Aᵀ)⁺A M⁻¹) Jₜᵀ symmetric positive semidefinite (the
// Delassus operator of the friction rows under the remaining constraints).
// Each contact sticks,  ṡⱼ = 0 with |fⱼ| ≤ μⱼλₙⱼ,  or slides from rest along
// its slip acceleration against its friction,  fⱼ = −μⱼλₙⱼ ṡⱼ/|ṡⱼ|  (Pfeiffer &
// Glocker, "Multibody Dynamics with Unilateral Contacts", 1996, §7.3: the
// tangential complementarity at the acceleration level). For given loads
// these are the optimality conditions of
//     min ½ fᵀW f + ṡ⁰ᵀf   over   |fⱼ| ≤ μⱼλₙⱼ
// (maximal dissipation: Moreau 1988), solved by block Gauss–Seidel — each
// contact's block, a disk in its 1–3 friction rows, exactly (the trust-region
// secular equation) — the loads updated as it sweeps. A contact forced to
// slide (at its located slip event the demand is exactly at the cone, and
// rising) takes the circle |fⱼ| = μⱼλₙⱼ: its direction is decided with the
// others.
//
// The result sets each candidate's mode and sliding direction; the friction
// phase then checks the modes with the full rows (a sticking contact's spin
// row, released here, is back) and slides any left over the cone one at a
// time, as before.
#include <appell/kinematics.hpp>
#include <appell/simulator.hpp>

#include "simulator/simulator_impl.hpp"

#include <Eigen/Eigenvalues>

#include <cmath>

namespace appell {

using detail::UnilateralRow;

/// Decides the modes and sliding directions of every closed contact with
/// friction whose slip is zero at (t_, q_, v_), together (above), island by
/// island (islands.cpp); `forced` (a row index, or −1) slides. false with
/// `error` when a solve fails; a sweep that does not settle leaves its
/// island's modes as they were (the friction phase then decides them one at
/// a time).
bool Simulator::Impl::frictionOnset(int forced, std::string& error) {
  auto& u = *uni_;
  const ContactEventOptions& o = options_.contacts;
  evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
  detail::gatherByIsland(u.islands, u.onset, u.onset_runs, [&](int k) {
    const UnilateralRow& r = u.rows[k];
    if (r.nf == 0 || r.creep > 0 || !cdata_->isActive(r.c)) return false;
    return k == forced || contactSlip(k).norm() <= o.speed_tol;
  });
  if (u.onset.empty()) return true;
  // Release their friction rows.
  for (int k : u.onset) {
    UnilateralRow& r = u.rows[k];
    u.was_sliding[k] = cdata_->isSliding(r.c);
    cdata_->setSliding(r.c, true);
    r.released = true;
  }
  evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
  tau_.setZero();
  if (tau_fn_) tau_fn_(t_, q_, v_, tau_);
  for (int i = 0; i + 1 < static_cast<int>(u.onset_runs.size()); ++i)
    if (!frictionOnsetIsland(detail::runOf(u.onset, u.onset_runs, i), forced, error)) {
      for (int k : u.onset)  // (the islands already decided keep their modes)
        if (u.rows[k].released) {
          u.rows[k].released = false;
          cdata_->setSliding(u.rows[k].c, u.was_sliding[k] != 0);
        }
      return false;
    }
  return true;
}

/// One island's onset problem, its rows released by frictionOnset: solved,
/// its rows restored, and its modes set when the sweeps settled.
bool Simulator::Impl::frictionOnsetIsland(std::span<const int> run, int forced,
                                          std::string& error) {
  auto& u = *uni_;
  const int K = static_cast<int>(run.size());
  const int F = detail::numberUnknowns(u.rows, run, &UnilateralRow::first_force);
  auto restore = [&] {
    for (int k : run) {
      UnilateralRow& r = u.rows[k];
      r.released = false;
      cdata_->setSliding(r.c, u.was_sliding[k] != 0);
    }
  };
  auto& p = u.onset_problem;
  frictionUnitForces(run, &UnilateralRow::first_force, p);
  if (!frictionResponses(t_, q_, v_, tau_, run, &UnilateralRow::first_force, F, p)) {
    restore();
    error = "friction modes: " + p.res.error;
    return false;
  }
  // Block Gauss–Seidel, the loads updated as it goes.
  const bool settled = p.gaussSeidel(K, F, 10000, counters_.block_updates, [&](int j) {
    const UnilateralRow& r = u.rows[run[j]];
    const int o0 = r.first_force, n = r.nf;
    const double radius = r.mu * std::max(0.0, p.loadAt(j, F));
    Mat3 H;
    Vec3 c;
    p.disk(o0, n, F, H, c);
    Vec3 fj = detail::diskMinimizer(H, c, n, radius);
    if (run[j] == forced && fj.norm() < radius) {
      // At its slip event: on the cone, along the sticking force found
      // (or the one it had).
      const Vec3 d = fj.norm() > 0 ? Vec3(fj / fj.norm()) : Vec3(-r.dir);
      fj = radius * d;
    }
    p.f.segment(o0, n) = fj.head(n);
    return radius;
  });
  restore();
  if (!settled) {
    ++counters_.friction_onset_unsettled;
    return true;
  }
  setOnsetModes(run, forced, F);
  return true;
}

/// The onset's modes from one island's settled forces f: a contact on its
/// cone whose slip accelerates slides along that acceleration, against its
/// friction; `forced` slides; the others stick. Logs the changes.
void Simulator::Impl::setOnsetModes(std::span<const int> run, int forced, int F) {
  auto& u = *uni_;
  auto& p = u.onset_problem;
  const int K = static_cast<int>(run.size());
  p.acc.head(F) = p.a0.head(F);
  p.acc.head(F).noalias() += p.W.topLeftCorner(F, F) * p.f.head(F);
  const double atol = 1e-9 * std::max(1.0, p.acc.head(F).lpNorm<Eigen::Infinity>());
  for (int j = 0; j < K; ++j) {
    const int k = run[j];
    UnilateralRow& r = u.rows[k];
    const int n = r.nf;
    Vec3 fj = Vec3::Zero(), aj = Vec3::Zero();
    fj.head(n) = p.f.segment(r.first_force, n);
    aj.head(n) = p.acc.segment(r.first_force, n);
    const double load = p.loadAt(j, F);
    const bool on_cone = fj.norm() >= (1 - 1e-9) * r.mu * std::max(0.0, load);
    const bool slides = k == forced || (on_cone && aj.norm() > atol);
    const bool was = u.was_sliding[k] != 0;
    if (slides) {
      r.dir = fj.norm() > 0 ? Vec3(-fj / fj.norm()) : Vec3(aj / aj.norm());
      r.dir_start = r.dir;
    }
    cdata_->setSliding(r.c, slides);
    if (slides && !was && !r.redeciding) logEvent(ContactEventKind::Slip, k, 0, 0, 0);
    if (!slides && was && k != forced) logEvent(ContactEventKind::Stick, k, 0, 0, 0);
  }
}

}  // namespace appell
