// The watch stage: after a step, which unilateral constraint's event
// function changed sign over it — an open gap below zero (touchdown), a
// closed normal force that would pull (lift-off), a sticking friction demand
// beyond μλₙ (slip), a sliding slip reversed (stick) — and those functions
// at the current state, for the event locator (event_location.cpp). The
// event log is written here too. References: contact_events.hpp.
#include <appell/simulator.hpp>

#include "simulator/simulator_impl.hpp"

#include <limits>

namespace appell {

using detail::Crossing;
using detail::UnilateralRow;

/// The first unilateral constraint whose event function changed sign over
/// the step just taken (end state in cdata_ and result_), or −1, and which
/// function: an open gap (touchdown), a closed normal force (lift-off), a
/// sticking friction demand beyond μ (slip), a sliding slip reversed (stick).
int Simulator::Impl::crossedConstraint(Crossing& type) const {
  const double ftol = options_.contacts.force_tol;
  for (int k = 0; k < static_cast<int>(uni_->rows.size()); ++k) {
    const UnilateralRow& r = uni_->rows[k];
    type = Crossing::None;
    if (!cdata_->isActive(r.c)) {
      if (!r.dormant && cdata_->gap[r.global] < 0) type = Crossing::Gap;
    } else if (options_.evaluate_end_state) {
      const double fn = result_.lambda[r.global];
      if (fn < -ftol) type = Crossing::Normal;
      else if (r.nf > 0 && !cdata_->isSliding(r.c) &&
               frictionForce(k, result_.lambda).norm() > r.mu * fn + ftol)
        type = Crossing::Cone;
      else if (r.nf > 0 && r.creep == 0 && cdata_->isSliding(r.c) &&
               cdata_->slide[r.c].slip.dot(r.dir_start) <
                   -options_.contacts.speed_tol)
        type = Crossing::Slip;
    }
    if (type != Crossing::None) return k;
  }
  return -1;
}

/// The friction rows' multipliers of unilateral row k (up to 3).
Vec3 Simulator::Impl::frictionForce(int k, const VecX& lambda) const {
  const UnilateralRow& r = uni_->rows[k];
  const auto& sr = cdata_->slide[r.c];
  Vec3 f = Vec3::Zero();
  for (int i = 0; i < sr.n; ++i) f[i] = lambda[cdata_->offset[r.c] + sr.row[i]] / sr.scale[i];
  return f;
}

/// Event function of unilateral row k at the current (t_, q_, v_): the gap
/// while open; while closed λᵤ, or μλₙ − |λₜ| (sticking), or the slip along
/// its direction at the step's start (sliding) — one solve when it needs λ.
double Simulator::Impl::eventFunction(int k, Crossing type) {
  const UnilateralRow& r = uni_->rows[k];
  if (type == Crossing::Feature) return searchFeatures() >= 0 ? -1.0 : 1.0;  // any switched
  evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
  if (type == Crossing::Gap) return cdata_->gap[r.global];
  if (type == Crossing::Slip) return cdata_->slide[r.c].slip.dot(r.dir_start);
  tau_.setZero();
  if (tau_fn_) tau_fn_(t_, q_, v_, tau_);
  if (!solveDynamics(t_, q_, v_, tau_, uni_->res)) return std::numeric_limits<double>::quiet_NaN();
  const double fn = uni_->res.lambda[r.global];
  if (type == Crossing::Normal) return fn;
  return r.mu * fn - frictionForce(k, uni_->res.lambda).norm();
}

/// At the located time of row k's crossing (`type`): another row whose
/// event function is already past its tolerance there — it crossed first. −1 when none did; else its row and, in
/// `earlier_type`, which function.
int Simulator::Impl::earlierCrossing(int k, Crossing type, Crossing& earlier_type) {
  auto& u = *uni_;
  const ContactEventOptions& o = options_.contacts;
  int earlier = -1;
  earlier_type = Crossing::None;
  if (type != Crossing::Feature) {
    earlier = searchFeatures();
    if (earlier >= 0) earlier_type = Crossing::Feature;
  }
  evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
  for (int j = 0; j < static_cast<int>(u.rows.size()) && earlier < 0; ++j) {
    if (j == k && type != Crossing::Feature) continue;
    const UnilateralRow& r = u.rows[j];
    if (!cdata_->isActive(r.c)) {
      if (!r.dormant && cdata_->gap[r.global] < -o.gap_tol)
        earlier = j, earlier_type = Crossing::Gap;
    } else if (cdata_->isSliding(r.c) && r.creep == 0) {
      if (eventFunction(j, Crossing::Slip) < -o.speed_tol)
        earlier = j, earlier_type = Crossing::Slip;
    } else if (cdata_->isSliding(r.c)) {  // regularized: only its load can cross
      if (options_.evaluate_end_state && eventFunction(j, Crossing::Normal) < -o.force_tol)
        earlier = j, earlier_type = Crossing::Normal;
    } else if (options_.evaluate_end_state) {
      if (eventFunction(j, Crossing::Normal) < -o.force_tol)
        earlier = j, earlier_type = Crossing::Normal;
      else if (r.nf > 0 && eventFunction(j, Crossing::Cone) < -o.force_tol)
        earlier = j, earlier_type = Crossing::Cone;
    }
  }
  return earlier;
}

void Simulator::Impl::logEvent(ContactEventKind kind, int k, double before, double after,
                         double impulse) {
  const UnilateralRow& r = uni_->rows[k];
  ContactEvent e;
  e.t = t_;
  e.constraint = r.c;
  e.kind = kind;
  e.speed_before = before;
  e.speed_after = after;
  e.normal_impulse = impulse;
  // The friction impulse of this event's impact (none for a lift-off, a
  // stick or a change of piece, whatever impact came before).
  const bool impact = kind == ContactEventKind::Touchdown || kind == ContactEventKind::Bounce ||
                      kind == ContactEventKind::Slip;
  e.tangential_impulse = impact ? r.tangential : 0;
  events_.push_back(e);
}

}  // namespace appell
