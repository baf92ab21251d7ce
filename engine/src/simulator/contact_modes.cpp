// The contact-force stage of a mode decision: which touching contacts stay
// closed, by principal pivoting on λᵤ ≥ 0 (closed) and γ̇ ≥ 0 (open) with one
// dynamics solve per pivot; the saved rows it reads normal velocities and
// accelerations from; and decideModes, which runs the stages of a decision
// in order (impact.cpp, then the forces here). References: contact_events.hpp.
#include <appell/kinematics.hpp>
#include <appell/simulator.hpp>

#include "simulator/simulator_impl.hpp"

#include <algorithm>
#include <cmath>

namespace appell {

using detail::UnilateralRow;

namespace {

/// A saved joint-space row (over its columns) applied to x.
double sparseDot(const UnilateralRow& r, const VecX& x) {
  double s = 0;
  for (size_t k = 0; k < r.cols.size(); ++k) s += r.a_joint[static_cast<int>(k)] * x[r.cols[k]];
  return s;
}

}  // namespace

bool detail::breakTwoCycle(std::vector<UnilateralRow>& rows, int flip, int& last_flip,
                           int& next_unload) {
  int other = -1;
  for (int k = next_unload; k < static_cast<int>(rows.size()) && other < 0; ++k)
    if (k != flip && rows[k].touching && rows[k].in_set) other = k;
  if (other < 0) return false;
  rows[other].in_set = false;
  rows[flip].in_set = true;
  next_unload = other + 1;
  last_flip = -1;
  return true;
}

/// γ = ġ of unilateral row k from its saved row, at data_'s velocities.
double Simulator::Impl::rowVelocity(int k) const {
  const UnilateralRow& r = uni_->rows[k];
  if (r.joint) return sparseDot(r, v_) + r.bval;
  double g = r.bval;
  if (r.a >= 0) g += r.wa.dot(data_->oMi[r.a].act(data_->v[r.a]));
  if (r.b >= 0) g -= r.wb.dot(data_->oMi[r.b].act(data_->v[r.b]));
  return g;
}

/// γ̇ of unilateral row k, data_ holding forwardKinematics(q, v, v̇).
double Simulator::Impl::rowAcceleration(int k) const {
  const UnilateralRow& r = uni_->rows[k];
  if (r.joint) return sparseDot(r, uni_->vdot) + r.abias;
  double g = r.kappa;
  if (r.a >= 0) g += r.wa.dot(spatialAccelerationWorld(*data_, r.a));
  if (r.b >= 0) g -= r.wb.dot(spatialAccelerationWorld(*data_, r.b));
  return g;
}

/// What a failed mode decision may mean when several closed contacts roll
/// without slip or by Coulomb's law (sticking, or switching between stick
/// and slip): a vehicle on uneven ground, over-constrained by its own tyres
/// (docs/contacts.md §4). Empty when fewer than two such contacts are closed.
std::string Simulator::Impl::rigidRollingHint() const {
  int rigid = 0;
  for (const auto& r : uni_->rows)
    if (cdata_->isActive(r.c) && cdata_->slide[r.c].n > 0 && r.creep == 0) ++rigid;
  if (rigid < 2) return "";
  return " (" + std::to_string(rigid) +
         " closed contacts roll without slip or stick by Coulomb's law, which can "
         "over-constrain a vehicle on uneven ground; tyres with a finite 'mu' and a "
         "'creep_speed' slip a little instead: docs/contacts.md §4, §8)";
}

/// Closes every touching contact, evaluates the rows at (t_, q_, v_) and keeps
/// a copy of each unilateral row; the active set is left all-touching-closed.
void Simulator::Impl::saveCandidateRows() {
  auto& u = *uni_;
  evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
  for (auto& r : u.rows) {
    r.gap = cdata_->gap[r.global];
    r.touching = !r.bounced && (cdata_->isActive(r.c) ||
                                (!r.dormant && std::abs(r.gap) <= options_.contacts.gap_tol) ||
                                r.touching_down);
    if (r.touching) cdata_->setActive(r.c, true);
  }
  evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
  for (auto& r : u.rows) {
    if (!r.touching) continue;
    const RowBlock& blk = cdata_->blocks[r.c];
    if (r.joint) {
      r.a_joint = blk.A_joint.row(r.row).transpose();
      r.bval = blk.b_joint[r.row];
      r.abias = blk.abias_joint[r.row];
    } else {
      r.wa = blk.Wa.row(r.row).transpose();
      r.wb = blk.Wb.row(r.row).transpose();
      r.bval = blk.b[r.row];
      r.kappa = blk.kappa[r.row];
    }
  }
}

/// Contact forces: λᵤ ≥ 0 for the closed, γ̇ ≥ 0 for the open touching
/// contacts, by principal pivoting with one dynamics solve per pivot.
bool Simulator::Impl::forcePhase(std::string& error) {
  auto& u = *uni_;
  bool held = false;
  if (!forceCandidates(held)) return true;
  u.vminus = v_;
  if (!forcePivoting(held, error)) return false;
  for (int k = 0; k < static_cast<int>(u.rows.size()); ++k) {
    const auto& r = u.rows[k];
    if (!r.touching) continue;
    if (r.was_closed && !r.in_set) logEvent(ContactEventKind::LiftOff, k, 0, 0, 0);
    if (!r.was_closed && r.in_set) logEvent(ContactEventKind::Touchdown, k, r.gamma, 0, 0);
  }
  return true;
}

/// The touching contacts at rest (at most rest_speed apart, `held` when one
/// separates that slowly) take part, starting in the set when they were
/// closed or touch down; the others open (a closed one lifts off). Whether
/// any takes part.
bool Simulator::Impl::forceCandidates(bool& held) {
  auto& u = *uni_;
  const ContactEventOptions& o = options_.contacts;
  saveCandidateRows();  // rows at the post-impact velocity (κ depends on v)
  // Only contacts at rest take part: one that separates (γ > 0, the trailing
  // foot an impact unloaded) is open, and lifts off if it was closed. One
  // that separates slower than rest_speed is held (its velocity projected to
  // zero): a body rocking between contacts with ever smaller plastic impacts
  // (an accumulation of impacts in finite time) comes to rest.
  bool any = false;
  for (int k = 0; k < static_cast<int>(u.rows.size()); ++k) {
    auto& r = u.rows[k];
    if (!r.touching) continue;
    const double gamma = rowVelocity(k);
    if (gamma > std::max(o.speed_tol, r.was_closed || r.touching_down ? o.rest_speed : 0.0)) {
      r.touching = false;
      cdata_->setActive(r.c, false);
      if (r.was_closed) logEvent(ContactEventKind::LiftOff, k, 0, gamma, 0);
      continue;
    }
    held = held || gamma > o.speed_tol;
    any = true;
    r.in_set = !r.lifting && (r.was_closed || r.touching_down);
  }
  return any;
}

/// The consistent set by principal pivoting: the in-set contacts push
/// (λᵤ ≥ 0), the others accelerate away (γ̇ ≥ 0). false with `error`.
bool Simulator::Impl::forcePivoting(bool held, std::string& error) {
  auto& u = *uni_;
  const ContactEventOptions& o = options_.contacts;
  const double acc_tol = o.force_tol * (1 + model_.gravity.norm());
  int last_flip = -1, next_unload = 0;
  for (int it = 0;; ++it) {
    if (it == o.max_mode_iterations) {
      error = "contact modes: no consistent set of contacts after " + std::to_string(it) +
              " pivots (a Painlevé-type configuration?)";
      return false;
    }
    for (auto& r : u.rows)
      if (r.touching) cdata_->setActive(r.c, r.in_set);
    bool consistent = false;
    if (!solveTrialSet(held, consistent, error)) return false;
    if (!consistent) continue;
    u.vdot = u.res.vdot;
    forwardKinematics(model_, *data_, q_, v_, u.vdot);
    // The tolerances scale with the forces at work: with 10⁹ N·m on a wheel,
    // round-off in λ and γ̈ is far above 1e-9 and an absolute test would
    // pivot on noise forever.
    const double fscale = std::max({1.0, u.res.lambda.lpNorm<Eigen::Infinity>(),
                                    tau_.lpNorm<Eigen::Infinity>()});
    const double ascale = std::max(1.0, u.vdot.lpNorm<Eigen::Infinity>());
    int flip = -1;
    for (int k = 0; k < static_cast<int>(u.rows.size()) && flip < 0; ++k) {
      const auto& r = u.rows[k];
      if (!r.touching) continue;
      if (r.in_set ? u.res.lambda[r.global] < -o.force_tol * fscale
                   : rowAcceleration(k) < -acc_tol * ascale)
        flip = k;
    }
    if (flip < 0) break;
    if (flip == last_flip) {  // it would pull, and out of the set it accelerates into its support
      if (!detail::breakTwoCycle(u.rows, flip, last_flip, next_unload)) {
        error = "contact modes: no consistent set of contacts: '" +
                constraints_[u.rows[flip].c]->name() +
                "' would pull and cannot separate (a Painlevé-type configuration?)";
        return false;
      }
      continue;
    }
    u.rows[flip].in_set = !u.rows[flip].in_set;
    last_flip = flip;
  }
  return true;
}

/// The dynamics with the trial set closed (in u.res). `consistent` false when no acceleration holds the set and
/// a contact was unloaded instead (the pivoting then goes on); false with
/// `error` when none can be.
bool Simulator::Impl::solveTrialSet(bool held, bool& consistent, std::string& error) {
  auto& u = *uni_;
  // The velocity the trial set holds: a held contact still separates at up
  // to rest_speed, and redundant rows (two sticking corners on one edge)
  // give consistent accelerations only at a velocity that satisfies them
  // all — so with a held contact, project onto the trial set (plastic)
  // before solving. (Not otherwise: a contact that slips keeps its slip for
  // the friction phase.)
  v_ = u.vminus;
  evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
  if (held && cdata_->m_active > 0) {
    u.vplus = v_;
    if (!kernelProject(*cdata_, q_, u.vplus, u.impulse)) {
      error = "contact modes: the velocity projection failed: " + solver_->lastError();
      return false;
    }
    std::swap(v_, u.vplus);
    evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
  }
  tau_.setZero();
  if (tau_fn_) tau_fn_(t_, q_, v_, tau_);
  if (!solveDynamics(t_, q_, v_, tau_, u.res)) {
    // No acceleration holds every contact of the trial set: a rigid body
    // on more contacts than its surface allows — a car whose tyres meet a
    // ramp askew (the wobbly table). One of them unloads: the first whose
    // opening leaves a consistent set that it separates from (γ̇ ≥ 0) and
    // no contact pulls.
    const int drop = unloadingContact();
    if (drop < 0) {
      error = "contact modes: " + u.res.error;
      return false;
    }
    u.rows[drop].in_set = false;
    return true;
  }
  consistent = true;
  return true;
}

/// In the force phase, when the trial set is inconsistent: the in-set
/// contact whose opening gives a consistent set where it separates and every
/// other in-set contact pushes — of those, the one that separates fastest —
/// or −1. Only a real inconsistency unloads a contact: the separation must
/// exceed kUnloadAcceleration of the state's accelerations, or a residual
/// that drift leaves (a state projected to 1e-6) would open a loaded tyre;
/// that stays an error. One solve per candidate; the active set is left as
/// the trial set.
int Simulator::Impl::unloadingContact() {
  constexpr double kUnloadAcceleration = 1e-4;
  auto& u = *uni_;
  const double ftol = options_.contacts.force_tol;
  int found = -1;
  double fastest = 0;
  for (int j = 0; j < static_cast<int>(u.rows.size()); ++j) {
    UnilateralRow& cand = u.rows[j];
    if (!cand.touching || !cand.in_set) continue;
    cdata_->setActive(cand.c, false);
    evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
    if (solveDynamics(t_, q_, v_, tau_, u.res)) {
      u.vdot = u.res.vdot;
      forwardKinematics(model_, *data_, q_, v_, u.vdot);
      const double fscale = std::max(1.0, u.res.lambda.lpNorm<Eigen::Infinity>());
      const double ascale = std::max(1.0, u.res.vdot.lpNorm<Eigen::Infinity>());
      const double separation = rowAcceleration(j);
      bool ok = separation >= kUnloadAcceleration * ascale && separation > fastest;
      for (const UnilateralRow& r : u.rows)
        ok = ok && !(r.touching && r.in_set && r.c != cand.c && u.res.lambda[r.global] < -ftol * fscale);
      if (ok) {
        found = j;
        fastest = separation;
      }
    }
    cdata_->setActive(cand.c, true);
  }
  return found;
}

/// Decides the mode of every touching unilateral constraint at (t_, q_, v_):
/// open the ones with clearance, impact the approaching ones, then solve for
/// the contact forces. Leaves the active set in cdata_.
bool Simulator::Impl::decideModes(std::string& error) {
  auto& u = *uni_;
  for (auto& r : u.rows) {
    r.was_closed = cdata_->isActive(r.c);
    r.bounced = false;
  }
  saveCandidateRows();
  for (auto& r : u.rows)
    if (!r.touching) cdata_->setActive(r.c, false);
  return impactPhase(error) && forcePhase(error);
}

}  // namespace appell
