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

#include "simulator/simulator_internal.hpp"

#include <Eigen/Eigenvalues>

#include <cmath>

namespace appell {

using detail::UnilateralRow;

/// argmin ½ fᵀH f + cᵀf over |f| ≤ r in the first n (≤ 3) components, H
/// symmetric positive semidefinite: the unconstrained (minimum-norm)
/// minimizer when it lies inside, else f = −(H + νI)⁻¹c with ν > 0 on the
/// circle (bisection on the monotone |f(ν)|).
Vec3 detail::diskMinimizer(const Mat3& H, const Vec3& c, int n, double r) {
  if (!(r > 0)) return Vec3::Zero();
  Mat3 Hp = Mat3::Identity();
  Hp.topLeftCorner(n, n) = H.topLeftCorner(n, n);
  Vec3 cp = Vec3::Zero();
  cp.head(n) = c.head(n);
  Eigen::SelfAdjointEigenSolver<Mat3> es(Hp);
  const Vec3 lam = es.eigenvalues().cwiseMax(0.0);
  const Vec3 cq = es.eigenvectors().transpose() * cp;
  const double tiny = 1e-12 * std::max(lam.maxCoeff(), 1e-300);
  // The minimum-norm unconstrained minimizer exists when c has no part in
  // H's null space.
  bool bounded = true;
  Vec3 fq = Vec3::Zero();
  for (int i = 0; i < 3; ++i) {
    if (lam[i] > tiny) fq[i] = -cq[i] / lam[i];
    else if (std::abs(cq[i]) > 1e-14 * (cq.norm() + 1e-300)) bounded = false;
  }
  if (bounded && fq.norm() <= r) {
    Vec3 f = es.eigenvectors() * fq;
    f.tail(3 - n).setZero();
    return f;
  }
  auto radius = [&](double nu) {
    double s = 0;
    for (int i = 0; i < 3; ++i) s += cq[i] * cq[i] / ((lam[i] + nu) * (lam[i] + nu));
    return std::sqrt(s);
  };
  double lo = 0, hi = cq.norm() / r;  // |f(hi)| ≤ |c| / hi = r
  for (int it = 0; it < 200 && hi - lo > 1e-16 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    (radius(mid) > r ? lo : hi) = mid;
  }
  for (int i = 0; i < 3; ++i) fq[i] = -cq[i] / (lam[i] + hi);
  Vec3 f = es.eigenvectors() * fq;
  f.tail(3 - n).setZero();
  return f;
}

/// Column first + i of p.U: the generalized force of a unit force along
/// friction row i of each of `ks`'s rows (row k's first unknown at k.*first),
/// with data_ at the state's kinematics.
void Simulator::frictionUnitForces(const std::vector<int>& ks, int UnilateralRow::*first,
                                   detail::FrictionProblem& p) {
  auto& u = *uni_;
  for (int k : ks) {
    const UnilateralRow& r = u.rows[k];
    const auto& sr = cdata_->slide[r.c];
    for (int i = 0; i < r.nf; ++i) {
      auto col = p.U.col(r.*first + i);
      col.setZero();
      if (r.a >= 0) {
        spatialJacobianWorld(model_, *data_, r.a, u.J);
        col.noalias() += u.J.transpose() * sr.Wa.row(i).transpose();
      }
      if (r.b >= 0) {
        spatialJacobianWorld(model_, *data_, r.b, u.J);
        col.noalias() -= u.J.transpose() * sr.Wb.row(i).transpose();
      }
    }
  }
}

/// The affine maps of the problem over `ks` (their F friction rows released
/// by the caller): slip accelerations a0 + W f and normal loads ln0 + N f at
/// (t, q, v) under τ + U f — one solve at τ and one per unit row force, at
/// the scale of the loads (the map is affine: any scale is exact up to
/// round-off relative to τ). false with p.res.error when a solve fails.
bool Simulator::frictionResponses(double t, const VecX& q, const VecX& v, const VecX& tau,
                                  const std::vector<int>& ks, int UnilateralRow::*first, int F,
                                  detail::FrictionProblem& p, bool with_velocities) {
  const int K = static_cast<int>(ks.size());
  auto respond = [&](const VecX& tau_prime, Eigen::Ref<VecX> acc, Eigen::Ref<VecX> load) {
    if (!solveDynamics(t, q, v, tau_prime, p.res)) return false;
    forwardKinematics(model_, *data_, q, v, p.res.vdot);
    for (int j = 0; j < K; ++j) {
      const UnilateralRow& r = uni_->rows[ks[j]];
      const auto& sr = cdata_->slide[r.c];
      const Vec6 aa = r.a >= 0 ? spatialAccelerationWorld(*data_, r.a) : Vec6::Zero();
      const Vec6 ab = r.b >= 0 ? spatialAccelerationWorld(*data_, r.b) : Vec6::Zero();
      for (int i = 0; i < r.nf; ++i)
        acc[r.*first + i] = sr.kappa[i] + sr.Wa.row(i).dot(aa) - sr.Wb.row(i).dot(ab);
      load[j] = p.res.lambda[r.global];
    }
    return true;
  };
  if (!respond(tau, p.a0.head(F), p.ln0.head(K))) return false;
  if (with_velocities) p.V.col(0) = p.res.vdot;  // (the base, until column 0's response)
  const double scale = std::max(1.0, p.ln0.head(K).cwiseAbs().maxCoeff());
  for (int c = 0; c < F; ++c) {
    // (Its own vector: the solve superposes sliding friction in tau_f.)
    p.tau = tau + scale * p.U.col(c);
    if (!respond(p.tau, p.acc.head(F), p.load.head(K))) return false;
    p.W.col(c).head(F) = (p.acc.head(F) - p.a0.head(F)) / scale;
    p.N.col(c).head(K) = (p.load.head(K) - p.ln0.head(K)) / scale;
    if (with_velocities) {
      // Column c − 1 held the base: move it along (no extra storage).
      if (c + 1 < F) p.V.col(c + 1) = p.V.col(c);
      p.V.col(c) = (p.res.vdot - p.V.col(c)) / scale;
    }
  }
  return true;
}

/// The slip velocity of unilateral row k's friction rows at data_'s
/// velocities (a sliding contact's as evaluated; a sticking one's from its
/// rows, before any projection).
Vec3 Simulator::contactSlip(int k) const {
  const UnilateralRow& r = uni_->rows[k];
  const auto& sr = cdata_->slide[r.c];
  if (cdata_->isSliding(r.c)) return sr.slip;
  const RowBlock& blk = cdata_->blocks[r.c];
  Vec3 slip = Vec3::Zero();
  for (int i = 0; i < sr.n; ++i) {
    const int row = sr.row[i];
    double val = blk.b[row];
    if (r.a >= 0) val += blk.Wa.row(row).dot(data_->oMi[r.a].act(data_->v[r.a]));
    if (r.b >= 0) val -= blk.Wb.row(row).dot(data_->oMi[r.b].act(data_->v[r.b]));
    slip[i] = sr.scale[i] * val;
  }
  return slip;
}

/// Decides the modes and sliding directions of every closed contact with
/// friction whose slip is zero at (t_, q_, v_), together (above); `forced`
/// (a row index, or −1) slides. false with `error` when a solve fails; a
/// sweep that does not settle leaves the modes as they were (the friction
/// phase then decides them one at a time).
bool Simulator::frictionOnset(int forced, std::string& error) {
  auto& u = *uni_;
  const ContactEventOptions& o = options_.contacts;
  evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
  u.onset.clear();
  int F = 0;
  for (int k = 0; k < static_cast<int>(u.rows.size()); ++k) {
    UnilateralRow& r = u.rows[k];
    if (r.nf == 0 || r.creep > 0 || !cdata_->isActive(r.c)) continue;
    if (k != forced && contactSlip(k).norm() > o.speed_tol) continue;
    r.first_force = F;
    F += r.nf;
    u.onset.push_back(k);
  }
  const int K = static_cast<int>(u.onset.size());
  if (K == 0) return true;
  // Release their friction rows.
  for (int j = 0; j < K; ++j) {
    UnilateralRow& r = u.rows[u.onset[j]];
    u.was_sliding[u.onset[j]] = cdata_->isSliding(r.c);
    cdata_->setSliding(r.c, true);
    r.released = true;
  }
  auto restore = [&] {
    for (int j = 0; j < K; ++j) {
      UnilateralRow& r = u.rows[u.onset[j]];
      r.released = false;
      cdata_->setSliding(r.c, u.was_sliding[u.onset[j]] != 0);
    }
  };
  evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
  auto& p = u.onset_problem;
  frictionUnitForces(u.onset, &UnilateralRow::first_force, p);
  tau_.setZero();
  if (tau_fn_) tau_fn_(t_, q_, v_, tau_);
  if (!frictionResponses(t_, q_, v_, tau_, u.onset, &UnilateralRow::first_force, F, p)) {
    restore();
    error = "friction modes: " + p.res.error;
    return false;
  }
  // Block Gauss–Seidel, the loads updated as it goes.
  const bool settled = p.gaussSeidel(K, F, 10000, [&](int j) {
    const UnilateralRow& r = u.rows[u.onset[j]];
    const int o0 = r.first_force, n = r.nf;
    const double radius = r.mu * std::max(0.0, p.loadAt(j, F));
    Mat3 H;
    Vec3 c;
    p.disk(o0, n, F, H, c);
    Vec3 fj = detail::diskMinimizer(H, c, n, radius);
    if (u.onset[j] == forced && fj.norm() < radius) {
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
  // Modes: a contact on its cone whose slip accelerates slides along that
  // acceleration, against its friction.
  p.acc.head(F) = p.a0.head(F);
  p.acc.head(F).noalias() += p.W.topLeftCorner(F, F) * p.f.head(F);
  const double atol = 1e-9 * std::max(1.0, p.acc.head(F).lpNorm<Eigen::Infinity>());
  for (int j = 0; j < K; ++j) {
    const int k = u.onset[j];
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
  return true;
}

}  // namespace appell
