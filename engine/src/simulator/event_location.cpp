// The locate and resolve stages of an event: the first crossing of an event
// function inside the step just taken is located (EventLocator,
// event_locator.hpp, on the integrator's dense output or on shortened
// steps), the step is cut there, and the contact modes are decided afresh —
// impact and contact forces (impact.cpp, contact_modes.cpp) for a touchdown,
// a lift-off or a change of piece, the friction modes (friction_phase.cpp)
// for a slip or a stick — between two drift projections. References:
// contact_events.hpp.
#include <appell/dynamics.hpp>
#include <appell/simulator.hpp>

#include "simulator/event_locator.hpp"
#include "simulator/simulator_impl.hpp"

#include <algorithm>
#include <limits>

namespace appell {

using detail::Crossing;
using detail::LocatedEvent;
using detail::UnilateralRow;

/// Integrates from the step's start by τ (no projection): the state the
/// event functions are evaluated on. τ = 0 is the start itself.
bool Simulator::Impl::restepTo(double tau, StepStatus& st) {
  auto& u = *uni_;
  t_ = u.t0;
  q_ = u.q0;
  v_ = u.v0;
  work_ = work_prev_;
  if (tau <= 0) return true;
  integrator_->reset();
  field_->clear();
  const StepResult r = integrator_->step(*field_, t_, q_, v_, tau);
  takeStepWork(r);
  st.evaluations += r.evaluations;
  counters_.evaluations += r.evaluations;
  ++counters_.event_steps;
  return r.ok && q_.allFinite() && v_.allFinite();
}

/// The state at τ after the step's start (t0): on the integrator's dense
/// output over the step of size h when it has one (no new evaluations),
/// else a step from the start shortened to τ.
bool Simulator::Impl::moveAlongStep(double tau, double h, bool dense, StepStatus& st) {
  auto& u = *uni_;
  if (!dense) return restepTo(tau, st);
  t_ = u.t0 + tau;
  if (tau <= 0) {
    q_ = u.q0;
    v_ = u.v0;
    return true;
  }
  return integrator_->denseOutput(tau / h, q_, v_);
}

/// Locates the first event of the step of size h from (u.t0, …): the
/// crossing `ev` names first, then any other that crossed before it, until
/// none did (one round per unilateral row at most). On return the state is
/// the step's own, integrated to ev.hi. false with `error` when a step or an
/// event function failed.
bool Simulator::Impl::locateEvent(StepStatus& st, double h, bool dense, LocatedEvent& ev,
                                  std::string& error) {
  auto& u = *uni_;
  const ContactEventOptions& o = options_.contacts;
  const detail::EventLocator locator{o.max_locate_iterations, o.time_tol};
  auto stateAt = [&](double tau) {
    return moveAlongStep(tau, h, dense, st) ? t_ - u.t0 : std::numeric_limits<double>::quiet_NaN();
  };
  for (int round = 0; ev.k >= 0 && round < static_cast<int>(u.rows.size()) + 1; ++round) {
    const int k = ev.k;
    const Crossing type = ev.type;
    double tau = 0;
    using Status = detail::EventLocator::Status;
    switch (locator.locate(stateAt, [&] { return eventFunction(k, type); }, ev.hi,
                           type == Crossing::Gap || type == Crossing::Slip,
                           type == Crossing::Feature, tau)) {
      case Status::Ok: break;
      case Status::StartStepFailed:
        error = "event location: the step from the last state failed";
        return false;
      case Status::EndsNotFinite:
        error = "event location: the event function of '" + constraints_[u.rows[k].c]->name() +
                "' is not finite";
        return false;
      case Status::StepFailed:
        error = "event location: a shortened step failed";
        return false;
      case Status::NotFinite:
        error = "event location: non-finite event function";
        return false;
    }
    if (!moveAlongStep(tau, h, dense, st)) {
      error = "event location: a shortened step failed";
      return false;
    }
    ev.hi = t_ - u.t0;
    Crossing earlier_type = Crossing::None;
    const int earlier = earlierCrossing(k, type, earlier_type);
    if (earlier < 0) break;
    ev.k = earlier;
    ev.type = earlier_type;
    ev.feature = ev.feature || earlier_type == Crossing::Feature;
  }
  if (ev.feature) {
    // The pieces feature_window later: contacts switching that soon after
    // the first switch with it (contact_features.cpp).
    if (!moveAlongStep(std::min(ev.hi + o.feature_window, h), h, dense, st)) {
      error = "event location: a shortened step failed";
      return false;
    }
    searchFeatures();
    for (int j = 0; j < static_cast<int>(u.rows.size()); ++j) u.feature_ahead[j] = u.rows[j].feature_free;
    if (!dense && !moveAlongStep(ev.hi, h, dense, st)) {
      error = "event location: a shortened step failed";
      return false;
    }
  }
  if (dense && !restepTo(ev.hi, st)) {  // the step itself, to the event
    error = "event location: the step to the event failed";
    return false;
  }
  return true;
}

/// A friction event at row k: at the cone's edge (Cone) it starts sliding
/// against its sticking force; its slip stopped (Slip) and it sticks if the
/// cone allows. Then the friction modes of all (frictionPhase). false with
/// the step's failure message in `error`.
bool Simulator::Impl::resolveFrictionEvent(int k, Crossing type, std::string& error) {
  auto& u = *uni_;
  UnilateralRow& ev = u.rows[k];
  if (type == Crossing::Slip) {
    cdata_->setSliding(ev.c, false);
    ev.redeciding = true;
  } else {  // at the cone's edge: slide against the sticking force
    evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
    tau_.setZero();
    if (tau_fn_) tau_fn_(t_, q_, v_, tau_);
    if (!solveDynamics(t_, q_, v_, tau_, u.res)) {
      error = u.res.error;
      return false;
    }
    const Vec3 ft = frictionForce(k, u.res.lambda);
    if (ft.norm() > 0) ev.dir = -ft / ft.norm();
    ev.dir_start = ev.dir;
    cdata_->setSliding(ev.c, true);
    logEvent(ContactEventKind::Slip, k, 0, 0, 0);
  }
  const bool phase_ok = frictionPhase(error, type == Crossing::Cone ? k : -1);
  ev.redeciding = false;
  if (!phase_ok) {
    error = "at t = " + std::to_string(t_) + ": " + error;
    return false;
  }
  if (type == Crossing::Slip && !cdata_->isSliding(ev.c))
    logEvent(ContactEventKind::Stick, k, 0, 0, 0);
  return true;
}

/// At the located event (the state integrated to it): drift control on the
/// old set and pieces (the closed rows' velocity drift is not slip, the open
/// ones' approach speed stays), the new pieces (a contact may now approach
/// its new one: an impact), the modes, then drift control on the new set.
StepStatus Simulator::Impl::resolveEvent(StepStatus st, const LocatedEvent& located) {
  auto& u = *uni_;
  const int k = located.k;
  const Crossing type = located.type;
  if (located.hi <= 0) {
    if (++u.zero_events > 2)
      return fail(st, "contact '" + constraints_[u.rows[k].c]->name() +
                          "' switches at every step start: no consistent contact mode" +
                          rigidRollingHint());
  } else {
    u.zero_events = 0;
  }
  for (auto& r : u.rows) {
    r.lifting = false;
    r.touching_down = false;
  }
  UnilateralRow& ev = u.rows[k];
  if (type == Crossing::Normal) ev.lifting = true;
  if (type == Crossing::Gap) ev.touching_down = true;
  st.h_taken = located.hi;
  std::string error;
  if (!projectAfterModes(error)) return fail(st, error);
  switchFeatures(located.feature);
  const double T_before = appell::kineticEnergy(model_, *data_, q_, v_);
  if (type == Crossing::Cone || type == Crossing::Slip) {
    if (!resolveFrictionEvent(k, type, error)) return fail(st, error);
  } else if (!decideModes(error) || !frictionPhase(error)) {
    return fail(st, "at t = " + std::to_string(t_) + ": " + error + rigidRollingHint());
  }
  if (!projectAfterModes(error)) return fail(st, error);
  dissipated_ += T_before - appell::kineticEnergy(model_, *data_, q_, v_);
  for (auto& r : u.rows) r.dir_start = r.dir;  // the next step's slip reference
  applyLatches();  // contacts that closed keep the piece they touched down on
  integrator_->reset();
  if (!evaluateEndState(error)) return fail(st, error);
  st.events = static_cast<int>(events_.size());
  counters_.events += st.events;
  return st;
}

/// The step of size h just taken crossed an event (`k`, `type`: already
/// found, or −1 to look): locate the first one, cut the step there, resolve.
StepStatus Simulator::Impl::locateAndHandleEvent(StepStatus st, double h, int k, Crossing type) {
  auto& u = *uni_;
  // The step's start: the last good state (t_prev_ …), saved by step().
  u.t0 = t_prev_;
  u.q0 = q_prev_;
  u.v0 = v_prev_;
  if (k < 0) k = crossedConstraint(type);
  LocatedEvent ev{k, type, type == Crossing::Feature, h};
  // The event functions along the step: on the integrator's dense output
  // when it has one (Dormand–Prince: no new evaluations), else on steps from
  // the start shortened to τ. The step to the located event is always a
  // proper step of the method.
  const bool dense = integrator_->denseOutput(1.0, q_, v_);
  std::string error;
  if (!locateEvent(st, h, dense, ev, error)) return fail(st, error);
  return resolveEvent(st, ev);
}

/// The step's drift control with the new active set.
bool Simulator::Impl::projectAfterModes(std::string& error) {
  if (options_.project_positions) {
    projection_ = projector_->project(model_, *data_, constraints_, *cdata_, t_, q_);
    if (!projection_.ok) {
      error = "position projection failed: " + projection_.error;
      return false;
    }
  }
  if (options_.project_velocities && cdata_->m_active > 0) {
    if (!options_.project_positions)
      evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
    if (!kernelProject(*cdata_, q_, v_, impulse_)) {
      error = "velocity projection failed: " + solver_->lastError();
      return false;
    }
  }
  return true;
}

}  // namespace appell
