// The impact stage: Newton's law of restitution on the touching contacts
// that approach (γ⁺ = −e γ⁻ where γ⁻ < −rest_speed, else γ⁺ = 0), the
// impulse solve being the solver's velocity projection onto the closed rows
// with their offsets shifted to the targets, and the set of contacts that
// take an impulse found by principal pivoting (a contact that would pull
// leaves, one that would approach joins). Then Coulomb's law on the friction
// impulses (friction_impact.cpp). References: contact_events.hpp.
#include <appell/kinematics.hpp>
#include <appell/simulator.hpp>

#include "simulator/simulator_impl.hpp"

#include <cmath>

namespace appell {

using detail::UnilateralRow;

/// Shifts the closed impact rows so that the projection makes γ⁺ = −e γ⁻.
void Simulator::Impl::shiftImpactTargets() {
  for (auto& r : uni_->rows) {
    if (!r.touching || !r.in_set) continue;
    cdata_->b[r.global] += r.target;
    RowBlock& blk = cdata_->blocks[r.c];
    if (r.joint) blk.b_joint[r.row] += r.target;
    else blk.b[r.row] += r.target;
  }
}

/// Impact: Newton's law on the touching contacts that approach, with the
/// velocity projection as the impulse solve, by principal pivoting; then
/// Coulomb's law on their friction impulses (friction_impact.cpp). A set
/// member at rest that those impulses would pull separates: it leaves the
/// set for good and the impact is solved again (at most once per contact).
bool Simulator::Impl::impactPhase(std::string& error) {
  auto& u = *uni_;
  forwardKinematics(model_, *data_, q_, v_);
  if (!impactTargets()) return true;
  for (int round = 0;; ++round) {
    if (!impactPivoting(error)) return false;
    // (u.vplus holds v⁻.)
    int separating = -1;
    if (frictionImpact(error, separating)) break;
    // The friction impulses would pull a set member that was at rest: it
    // separates — out of the set, and the impact is solved again from v⁻.
    if (separating < 0 || round == static_cast<int>(u.rows.size())) return false;
    u.rows[separating].in_set = false;
    u.rows[separating].separated = true;
    v_ = u.vminus;
    forwardKinematics(model_, *data_, q_, v_);
  }
  logImpacts();
  return true;
}

/// Each touching contact's normal velocity γ⁻ and restitution target, and
/// whether it starts in the impact's set (closed, or approaching). Returns
/// whether any approaches (else there is no impact).
bool Simulator::Impl::impactTargets() {
  auto& u = *uni_;
  const ContactEventOptions& o = options_.contacts;
  bool any = false;
  for (int k = 0; k < static_cast<int>(u.rows.size()); ++k) {
    auto& r = u.rows[k];
    r.impulse = r.tangential = 0;
    r.target = 0;
    r.separated = false;
    if (!r.touching) continue;
    r.gamma = rowVelocity(k);
    if (r.gamma < -o.speed_tol) {
      any = true;
      const double e = constraints_[r.c]->restitution();
      r.target = r.gamma < -o.rest_speed ? e * r.gamma : 0.0;
    }
    r.in_set = r.was_closed || r.gamma < -o.speed_tol;
  }
  return any;
}

/// The set of contacts that take an impulse, by principal pivoting: v_ is
/// v⁺ of the consistent set on return (u.vplus holds v⁻), false with `error`
/// when none was found.
bool Simulator::Impl::impactPivoting(std::string& error) {
  auto& u = *uni_;
  const ContactEventOptions& o = options_.contacts;
  int last_flip = -1, next_unload = 0;
  for (int it = 0;; ++it) {
    if (it == o.max_mode_iterations) {
      error = "impact: no consistent set of contacts after " + std::to_string(it) + " pivots";
      return false;
    }
    for (auto& r : u.rows)
      if (r.touching) cdata_->setActive(r.c, r.in_set);
    evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
    shiftImpactTargets();
    u.vplus = v_;
    if (!kernelProject(*cdata_, q_, u.vplus, u.impulse)) {
      // Restitution targets on redundant rows can contradict each other: a
      // ball resting on one slope of a valley that strikes the other with
      // e > 0 cannot both rebound there and keep rolling on the first (two
      // points of one rigid body keep their distance). A set member at rest
      // (no target) is then the one that gives way: it leaves the set, and
      // the pivoting goes on (it rejoins if it would approach).
      int resting = -1;
      for (int k = 0; k < static_cast<int>(u.rows.size()) && resting < 0; ++k) {
        const auto& r = u.rows[k];
        if (r.touching && r.in_set && r.target == 0 && r.gamma >= -o.speed_tol) resting = k;
      }
      if (resting < 0) {
        error = "impact: the impulse solve failed: " + solver_->lastError();
        return false;
      }
      u.rows[resting].in_set = false;
      last_flip = resting;
      continue;
    }
    std::swap(v_, u.vplus);  // rowVelocity reads v_ and data_ at v⁺
    forwardKinematics(model_, *data_, q_, v_);
    double scale = 0;
    for (const auto& r : u.rows)
      if (r.touching && r.in_set) scale = std::max(scale, std::abs(u.impulse[r.global]));
    int flip = -1;
    for (int k = 0; k < static_cast<int>(u.rows.size()) && flip < 0; ++k) {
      auto& r = u.rows[k];
      if (!r.touching) continue;
      if (r.in_set) {
        r.impulse = -u.impulse[r.global];  // v⁺ = v − M⁻¹Aᵀμ: the push along the row is −μ
        if (r.impulse < -1e-10 * (1 + scale)) flip = k;
      } else if (!r.separated && rowVelocity(k) + r.target < -o.speed_tol) {
        flip = k;
      }
    }
    if (flip < 0) break;
    std::swap(v_, u.vplus);  // back to the pre-impact velocity
    if (flip == last_flip) {  // it would pull, and out of the set it approaches
      if (!detail::breakTwoCycle(u.rows, flip, last_flip, next_unload)) {
        error = "impact: no consistent set of contacts: '" + constraints_[u.rows[flip].c]->name() +
                "' would pull and cannot stay out";
        return false;
      }
      continue;
    }
    u.rows[flip].in_set = !u.rows[flip].in_set;
    last_flip = flip;
  }
  return true;
}

/// After the impact (v_ = v⁺): the friction impulse of each contact in the
/// set; those with restitution rebound (open), the others closed plastically.
void Simulator::Impl::logImpacts() {
  auto& u = *uni_;
  const ContactEventOptions& o = options_.contacts;
  // v_ is v⁺. Contacts that took an impulse with restitution rebound: open.
  for (int k = 0; k < static_cast<int>(u.rows.size()); ++k) {
    auto& r = u.rows[k];
    if (!r.touching || !r.in_set) continue;
    const Constraint& con = *constraints_[r.c];
    double t2 = 0;
    for (int i = 0; i < con.rows(); ++i)
      if (isTangential(con.rowKind(i))) t2 += std::pow(u.impulse[cdata_->offset[r.c] + i], 2);
    r.tangential = std::sqrt(t2);
    const double after = rowVelocity(k);
    if (r.target < 0) {
      logEvent(ContactEventKind::Bounce, k, r.gamma, after, r.impulse);
      r.touching = false;  // separating: not a candidate of the force problem
      r.bounced = true;
      cdata_->setActive(r.c, false);
    } else if (r.gamma < -o.speed_tol) {
      logEvent(ContactEventKind::Touchdown, k, r.gamma, after, r.impulse);
      r.touching_down = false;  // logged
      r.was_closed = true;      // closed plastically: the force problem starts from it
    }
  }
}

}  // namespace appell
