// The automatic contact scheme (docs/contacts.md §10): event-driven while the
// events decide the modes and stay sparse, a Moreau–Jean window
// (timestepping/moreau_jean.hpp) where they do not —
//
//   opens   when an event step fails (no consistent contact mode, a step
//           below h_min, a solve that fails at a mode's state), when
//           zeno_events events fall within zeno_time of simulated time
//           (Zeno, slip ↔ stick chattering), when the last stall_work units
//           of the simulation's work (solves and friction block updates)
//           advanced the simulated time by less than stall_time (steps
//           collapsing without events: a stall, decided by counts, so the
//           switch does not depend on the machine's load), or when the
//           caller asks (openTimeSteppingWindow);
//   closes  after at least its minimum length, once the contact modes have
//           not changed over stable_steps steps and the event scheme decides
//           the modes at the window's end (decideContactModes). A window
//           that opens again within its length of the last one's end doubles
//           that length (a scene that keeps failing stays time-stepped).
//
// Both switches are contact events (TimeStepping, Events), in the summary,
// the CSV and the viewer's timeline.
#include <appell/configuration.hpp>
#include <appell/dynamics.hpp>
#include <appell/simulator.hpp>

#include "simulator/simulator_impl.hpp"
#include "timestepping/moreau_jean.hpp"

#include <new>


#include <cmath>
#include <stdexcept>

namespace appell {

namespace {
/// The most a closed row of the modes decided at a window's close may be off
/// at the window's velocity (m/s, relative to max(1, |v|∞)): drift that the
/// event scheme's projection removes, not a jump of the state.
constexpr double kHandBackSpeed = 1e-6;
}  // namespace

std::span<const NamedValue<ContactScheme>> contactSchemeTable() {
  static const NamedValue<ContactScheme> table[] = {
      {ContactScheme::Events, "events", {"event_driven"},
       "event-driven: located touchdowns, lift-offs, slips and sticks; exact between them"},
      {ContactScheme::TimeStepping, "timestepping", {"time_stepping", "moreau_jean"},
       "Moreau–Jean: velocity-level contact impulses per fixed step; never stalls, O(h)"},
      {ContactScheme::Auto, "auto", {},
       "events, with time-stepping windows where mode decisions fail or events pile up"},
  };
  return table;
}

const char* toString(ContactScheme scheme) {
  for (const auto& e : contactSchemeTable())
    if (e.value == scheme) return e.name;
  return "?";
}

ContactScheme contactSchemeFromString(const std::string& name) {
  return parseName(contactSchemeTable(), name, "contact scheme");
}

void timestepping::checkOptions(const TimeSteppingOptions& o) {
  auto positive = [](const char* what, double x) {
    if (!(x > 0) || !std::isfinite(x))
      throw std::invalid_argument(std::string("Simulator: timestepping.") + what +
                                  " must be positive and finite, got " + std::to_string(x));
  };
  positive("step", o.step);
  positive("residual_tol", o.residual_tol);
  positive("zeno_time", o.zeno_time);
  positive("stall_time", o.stall_time);
  positive("min_window", o.min_window);
  if (!(o.theta > 0 && o.theta <= 1))
    throw std::invalid_argument("Simulator: timestepping.theta must be in (0, 1], got " +
                                std::to_string(o.theta));
  if (o.max_sweeps < 1 || o.zeno_events < 2 || o.stall_work < 4 /* its marks */ ||
      o.stall_steps < 4 || o.stable_steps < 1)
    throw std::invalid_argument(
        "Simulator: timestepping.max_sweeps ≥ 1, zeno_events ≥ 2, stall_work ≥ 4, stall_steps ≥ 4 "
        "and stable_steps ≥ 1 are required");
}

bool Simulator::Impl::timeSteppingStage() {
  if (mj_ || !uni_) return mj_ != nullptr;
  try {
    mj_ = std::make_unique<timestepping::MoreauJean>(model_, constraints_, actuators_,
                                                     options_.timestepping,
                                                     options_.contacts.gap_tol);
  } catch (const std::bad_alloc&) {
    return false;  // too large to time-step: the events keep the scene (and report their failure)
  }
  return true;
}

bool Simulator::Impl::openTimeSteppingWindow(const std::string& why) {
  if (options_.scheme != ContactScheme::Auto || stepping_ || !options_.contacts.enabled ||
      !timeSteppingStage())
    return false;
  openWindow(namedContact(why), why);
  return true;
}

/// The unilateral constraint a message names ('name'), or the first one.
int Simulator::Impl::namedContact(const std::string& message) const {
  int first = -1;
  for (const auto& r : uni_->rows) {
    if (first < 0) first = r.c;
    if (message.find("'" + constraints_[r.c]->name() + "'") != std::string::npos) return r.c;
  }
  return first;
}

void Simulator::Impl::openWindow(int constraint, std::string why) {
  // Soon after the last window closed: the events failed again, so this
  // one lasts twice as long.
  const double min_window = options_.timestepping.min_window;
  window_min_ = window_closed_once_ && t_ - window_end_ < window_min_
                    ? std::min(2 * window_min_, 1e3 * min_window)
                    : min_window;
  stepping_ = true;
  window_start_ = t_;
  stable_ = 0;
  window_reason_ = std::move(why);
  window_contact_ = constraint;
  ++counters_.windows;
  integrator_->reset();
}

// The event scheme again, if it decides the modes at the window's end.
bool Simulator::Impl::closeWindow() {
  q_moved_ = q_;  // (the drift projection's scratch: no allocation)
  v_moved_ = v_;
  const double dissipated = dissipated_;
  const std::size_t logged = events_.size();
  std::string error;
  const double kinetic = appell::kineticEnergy(model_, *data_, q_, v_);
  bool held = decideContactModes(error);
  if (held) {
    // The events hold their closed rows exactly — every event step ends
    // with the drift projection onto them — so the window's state must
    // already satisfy the rows of the modes just decided: else that
    // projection is a jump of the state that no balance term sees. (The
    // CAD car's rear wheels 0.2 mm out of line admit no turn on four
    // sticking tyres: the events decided all four sticking at a window's
    // close, and the next step's projection took the car's 11 J of kinetic
    // energy away.)
    evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
    const double mismatch = appell::velocityResidual(*data_, constraints_, *cdata_, v_);
    held = mismatch <= kHandBackSpeed * std::max(1.0, v_.lpNorm<Eigen::Infinity>());
  }
  if (!held) {
    q_ = q_moved_;
    v_ = v_moved_;
    dissipated_ = dissipated;
    events_.resize(logged);
    return false;
  }
  // An impact the mode decision took (a contact still approaching at the
  // window's end) dissipates as any impact does.
  dissipated_ += kinetic - appell::kineticEnergy(model_, *data_, q_, v_);
  ContactEvent e;
  e.t = t_;
  e.constraint = uni_->rows.front().c;
  e.kind = ContactEventKind::Events;
  events_.push_back(e);
  stepping_ = false;
  window_end_ = t_;
  window_closed_once_ = true;
  restartStallWatch();
  h_suggest_ = 0;
  evaluateEndState(error);
  return true;
}

void Simulator::Impl::restartStallWatch() {
  event_count_ = 0;
  stall_marks_ = stall_low_ = 0;
  stall_next_ = work() + options_.timestepping.stall_work / kStallMarks;
  stall_t_.fill(t_);
  step_marks_ = 0;
  step_next_ = counters_.steps + options_.timestepping.stall_steps / kStallMarks;
  step_t_.fill(t_);
}

// The Zeno and stall watches of the automatic scheme, after an event step.
void Simulator::Impl::watchEvents() {
  const TimeSteppingOptions& o = options_.timestepping;
  // Mode changes only: a contact crossing a terrain's pieces keeps its mode.
  int logged = 0;
  for (const ContactEvent& e : events_)
    if (e.kind != ContactEventKind::Feature) {
      event_ring_[event_count_++ % o.zeno_events] = e.t;
      last_event_contact_ = e.constraint;
      ++logged;
    }
  if (event_count_ >= o.zeno_events && logged > 0) {
    const double oldest = event_ring_[event_count_ % o.zeno_events];
    if (t_ - oldest <= o.zeno_time) {
      std::ostringstream why;
      why << o.zeno_events << " contact events within " << t_ - oldest
          << " s of simulated time (Zeno or slip-stick chattering; last: '"
          << constraints_[events_.back().constraint]->name() << "' "
          << toString(events_.back().kind) << ")";
      if (timeSteppingStage()) openWindow(events_.back().constraint, why.str());
      return;
    }
  }
  // The stall watch: a mark every stall_work / kStallMarks units of work,
  // and the simulated time at the last kStallMarks marks. A stall is the
  // last stall_work units (the work since the oldest mark) advancing less
  // than stall_time at kStallLowMarks marks in a row: low progress sustained
  // over 2.75 stall_work. Measured over that much work, a hard friction
  // problem at one step (an onset's Gauss–Seidel taking 10⁴ block updates)
  // is not one, nor a burst of tiny steps that ends by itself (a skid-steer's
  // slip onset: 2, 5 and 9 marks in a row at tol 1e-10, 1e-11, 1e-12). Work, not
  // evaluations: an evaluation with four sliding tyres costs a hundred times
  // one with none (docs/contacts.md §10).
  if (watchStepSize()) return;
  if (work() < stall_next_) return;
  stall_next_ = work() + o.stall_work / kStallMarks;
  const double oldest = stall_t_[stall_marks_ % kStallMarks];
  stall_t_[stall_marks_++ % kStallMarks] = t_;
  stall_low_ = stall_marks_ >= kStallMarks && t_ - oldest < o.stall_time ? stall_low_ + 1 : 0;
  if (stall_low_ < kStallLowMarks) return;
  const int contact = last_event_contact_ >= 0 ? last_event_contact_ : namedContact("");
  std::ostringstream why;
  why << "the steps stalled: " << kStallLowMarks << " overlapping stretches of " << o.stall_work
      << " units of work (solves and friction block updates) in a row advanced less than "
      << o.stall_time << " s of simulated time each (the last " << t_ - oldest
      << " s; last mode change: '" << constraints_[contact]->name() << "')";
  if (timeSteppingStage()) openWindow(contact, why.str());
}

// The step-size watch: a mark every stall_steps / kStallMarks accepted
// steps and the simulated time at the last kStallMarks marks; the step size
// collapsed when the last stall_steps steps advanced less than stall_time,
// or the last half of them less than a hundredth of it (a mean step below
// 156 ns at the defaults). One stretch suffices (the work rule above needs
// eight): a single hard friction problem is one step, and every example's
// largest burst at its own tolerance, or the skid-steer's at 1e-12, is 39
// steps within 1 ms, and its shortest 64 steps span 6.2 ms; cad_car's stall
// at its steering step takes 206 steps per ms, 64 of them in 3.2 µs, each
// costing a hundred times a smooth step, so the second rule opens its
// window a third of the stall sooner (docs/contacts.md §10: why 128).
// true when it opened a window.
bool Simulator::Impl::watchStepSize() {
  const TimeSteppingOptions& o = options_.timestepping;
  constexpr int kHalf = kStallMarks / 2;
  constexpr double kHalfTime = 1e-2;  // of stall_time, for half the steps
  if (counters_.steps < step_next_) return false;
  step_next_ = counters_.steps + o.stall_steps / kStallMarks;
  const double oldest = step_t_[step_marks_ % kStallMarks];
  const double half = step_t_[(step_marks_ + kHalf) % kStallMarks];
  step_t_[step_marks_++ % kStallMarks] = t_;
  const bool all_slow = step_marks_ >= kStallMarks && t_ - oldest < o.stall_time;
  const bool half_slow = step_marks_ >= kHalf && t_ - half < kHalfTime * o.stall_time;
  if (!all_slow && !half_slow) return false;
  const int contact = last_event_contact_ >= 0 ? last_event_contact_ : namedContact("");
  const long steps = all_slow ? o.stall_steps : o.stall_steps / 2;
  const double limit = all_slow ? o.stall_time : kHalfTime * o.stall_time;
  std::ostringstream why;
  why << "the step size collapsed: the last " << steps << " steps advanced "
      << t_ - (all_slow ? oldest : half) << " s of simulated time (less than " << limit
      << " s; last mode change: '" << constraints_[contact]->name() << "')";
  if (!timeSteppingStage()) return false;
  openWindow(contact, why.str());
  return true;
}

// The step's counters and its work terms (timestepping::StepWork) into the
// run's balance.
void Simulator::Impl::recordTimeSteppingWork() {
  ++counters_.timestepping_steps;
  if (!mj_->converged()) ++counters_.unconverged;
  counters_.contact_sweeps += mj_->sweeps();
  counters_.contact_polished += mj_->polished();
  counters_.max_contact_residual = std::max(counters_.max_contact_residual, mj_->residual());
  const timestepping::StepWork& w = mj_->work();
  dissipated_ += w.impact;
  scheme_loss_ += w.scheme;
  work_[kFrictionWork] += w.friction;
  work_[kJointWork] += w.joint;
  work_[kSupportWork] += w.support;
}

// The modes for reports (isClosed, sliding): what pushed and did not
// rebound. True when some contact's mode changed since the last step.
bool Simulator::Impl::takeTimeSteppingModes() {
  bool changed = false;
  for (const auto& r : uni_->rows) {
    const timestepping::Mode m = mj_->modes()[r.c];
    const bool closed = m != timestepping::Mode::Open && !mj_->rebounds(r.c);
    cdata_->setActive(r.c, closed);
    cdata_->setSliding(r.c, closed && m == timestepping::Mode::Slide);
    changed = changed || last_modes_[r.c] != static_cast<signed char>(m);
    last_modes_[r.c] = static_cast<signed char>(m);
  }
  return changed;
}

StepStatus Simulator::Impl::timeSteppingStep(double h) {
  StepStatus st;
  const double hs = std::min(h, options_.timestepping.step);
  if (window_contact_ >= 0) {  // a window opened since the last step: log it
    ContactEvent e;
    e.t = t_;
    e.constraint = window_contact_;
    e.kind = ContactEventKind::TimeStepping;
    events_.push_back(e);
    window_contact_ = -1;
  }
  ts_step_start_ = t_;
  if (!mj_->step(model_, *data_, constraints_, *cdata_, *solver_, user_tau_fn_, t_, q_, v_, hs,
                 options_.contacts.rest_speed)) {
    // At a window's first step the events' own reason comes first.
    const bool opening = options_.scheme == ContactScheme::Auto && t_ == window_start_;
    return fail(st, (opening ? window_reason_ + "; time-stepping could not take over: " : std::string()) +
                        "time-stepping at t = " + std::to_string(t_) + ": " + mj_->error());
  }
  t_ += hs;
  st.h_taken = hs;
  st.h_next = options_.timestepping.step;
  st.evaluations = 1;
  recordTimeSteppingWork();
  // The drift projection holds the bilateral rows only: the contacts are
  // held by the step's own targets (a closing gap lands on g = 0), and a
  // projection of a floating body's position would turn its body-frame
  // velocity — momentum the contact impulses did not change.
  for (const auto& r : uni_->rows) cdata_->setActive(r.c, false);
  evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
  if (options_.project_positions) {
    projection_ = projector_->project(model_, *data_, constraints_, *cdata_, t_, q_, true);
    st.projection_iterations = projection_.iterations;
    counters_.projection_iterations += projection_.iterations;
    if (!projection_.ok) return fail(st, "position projection failed: " + projection_.error);
  }
  if (options_.project_velocities && cdata_->m_active > 0 &&
      !kernelProject(*cdata_, q_, v_, impulse_))
    return fail(st, "velocity projection failed: " + solver_->lastError());
  // The residuals the run watches as drift: of the rows this step holds
  // exactly, the bilateral ones just projected. A closed contact holds only
  // to its contact problem's residual and an O(h) gap, both reported apart
  // (max_contact_residual, max_contact_gap): a window is first order by
  // design, and an unconverged Gauss–Seidel solve is counted, not fatal.
  evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
  velocity_residual_ = appell::velocityResidual(*data_, constraints_, *cdata_, v_);
  gap_residual_ = appell::gapResidual(*cdata_);
  const bool changed = takeTimeSteppingModes();
  // Reports: the step's forces (impulses over h), residuals, energy.
  evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
  counters_.max_contact_gap = std::max(counters_.max_contact_gap, appell::gapResidual(*cdata_));
  result_.lambda = mj_->lambda();
  result_.vdot = (v_ - v_prev_) / hs;
  result_.ok = true;
  kinetic_ = appell::kineticEnergy(model_, *data_, q_, v_);
  potential_ = appell::potentialEnergy(model_, *data_, q_);
  ++counters_.steps;
  stable_ = changed ? 0 : stable_ + 1;
  if (options_.scheme == ContactScheme::Auto && t_ - window_start_ >= window_min_ &&
      stable_ >= options_.timestepping.stable_steps && !closeWindow())
    stable_ = 0;  // (the events still cannot decide: another stable stretch)
  st.events = static_cast<int>(events_.size());
  counters_.events += st.events;
  return st;
}

}  // namespace appell
