// The friction stage of a mode decision: stick or slide, and the sliding
// direction, for every closed contact with friction, once the normal modes
// are decided (contact_modes.cpp, impact.cpp). Contacts at zero slip are
// decided together (friction_onset.cpp); the rest one at a time, until no
// mode changes. docs/contacts.md §8.
#include <appell/simulator.hpp>

#include "simulator/simulator_impl.hpp"

namespace appell {

using detail::UnilateralRow;

/// Friction modes at (t_, q_, v_), the normal modes decided. The contacts
/// that are not slipping are decided together first (frictionOnset), when
/// one of them needs a decision: a sticking one over its cone, a sliding one
/// whose slip stopped, or `forced` (at its slip event). Then, until nothing
/// changes (each change moves the others' loads): a closed contact that
/// slips (an initial state sliding, or one whose impact left the cone)
/// slides along its slip; a sticking one whose friction demand exceeds μ
/// slides against its sticking force (−λₜ/|λₜ|: the friction it already
/// exerts, at its limit).
bool Simulator::Impl::frictionPhase(std::string& error, int forced) {
  auto& u = *uni_;
  const ContactEventOptions& o = options_.contacts;
  bool onset_done = false;
  // Regularized contacts slide whenever closed (their force a function of
  // the slip); nothing below decides their mode.
  for (UnilateralRow& r : u.rows)
    if (r.creep > 0 && cdata_->isActive(r.c) && !cdata_->isSliding(r.c))
      cdata_->setSliding(r.c, true);
  for (int it = 0;; ++it) {
    if (it == o.max_mode_iterations) {
      error = "friction modes: no consistent stick/slip set after " + std::to_string(it) + " passes";
      return false;
    }
    evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
    tau_.setZero();
    if (tau_fn_) tau_fn_(t_, q_, v_, tau_);
    if (!solveDynamics(t_, q_, v_, tau_, u.res)) {
      error = "friction modes: " + u.res.error;
      return false;
    }
    if (!onset_done) {
      onset_done = true;
      bool needed = forced >= 0;
      for (int k = 0; k < static_cast<int>(u.rows.size()) && !needed; ++k) {
        const UnilateralRow& r = u.rows[k];
        if (r.nf == 0 || r.creep > 0 || !cdata_->isActive(r.c) ||
            contactSlip(k).norm() > o.speed_tol)
          continue;
        needed = cdata_->isSliding(r.c) ||
                 frictionForce(k, u.res.lambda).norm() > r.mu * u.res.lambda[r.global] + o.force_tol;
      }
      if (needed) {
        if (!frictionOnset(forced, error)) return false;
        continue;
      }
    }
    int change = -1;
    for (int k = 0; k < static_cast<int>(u.rows.size()) && change < 0; ++k) {
      UnilateralRow& r = u.rows[k];
      if (r.nf == 0 || !cdata_->isActive(r.c) || cdata_->isSliding(r.c)) continue;
      const double fn = u.res.lambda[r.global];
      // Sticking rows' residuals are the slip (before any projection).
      const Vec3 slip = contactSlip(k);
      const Vec3 ft = frictionForce(k, u.res.lambda);
      if (slip.norm() > o.speed_tol) {
        r.dir = slip / slip.norm();
      } else if (ft.norm() > r.mu * fn + o.force_tol && ft.norm() > 0) {
        r.dir = -ft / ft.norm();
      } else {
        continue;
      }
      r.dir_start = r.dir;
      cdata_->setSliding(r.c, true);
      if (!r.redeciding) logEvent(ContactEventKind::Slip, k, 0, slip.norm(), 0);
      change = k;
    }
    if (change < 0) return true;
  }
}

}  // namespace appell
