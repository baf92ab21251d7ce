#include <appell/configuration.hpp>
#include <appell/dynamics.hpp>
#include <appell/run_loop.hpp>
#include <appell/simulator.hpp>
#include <appell/tree_solver.hpp>

#include "simulator/simulator_impl.hpp"
#include "timestepping/moreau_jean.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace appell {

Simulator::Impl::Impl(const Model& model, ConstraintList constraints,
                      std::unique_ptr<ConstrainedSolver> solver, IntegratorType integrator,
                      const IntegratorOptions& integrator_options, const SimulatorOptions& options)
    : model_(model), constraints_(std::move(constraints)), solver_(std::move(solver)),
      integrator_(makeIntegrator(integrator, model, integrator_options)), options_(options) {
  if (!solver_) throw std::invalid_argument("Simulator: no constrained solver given");
  for (const auto& c : constraints_)
    if (!c) throw std::invalid_argument("Simulator: the constraint list holds a null constraint");
  validateOptions(options_);
  chooseSchemeForCompliance();
  data_ = std::make_unique<Data>(
      model_, solver_->usesDenseRows() ? MassMatrix::Sized : MassMatrix::None);
  // Dense storage (m × nv) only for the formulations that assemble A.
  cdata_ = std::make_unique<ConstraintData>(
      model_, constraints_, solver_->usesDenseRows() ? DenseRows::Sized : DenseRows::None);
  // The projection's Newton steps share the tree solver when the dynamics
  // use one (one O(n) workspace, not two).
  projector_ = std::make_unique<PositionProjector>(model_, constraints_, options_.projection,
                                                   dynamic_cast<TreeSolver*>(solver_.get()));
  field_ = std::make_unique<Field>(*this);
  q_ = neutralConfiguration(model_);
  v_ = VecX::Zero(model_.nv);
  q_prev_ = q_;
  v_prev_ = v_;
  q_moved_ = q_;
  v_moved_ = v_;
  dtheta_moved_ = VecX::Zero(model_.nv);
  tau_ = VecX::Zero(model_.nv);
  impulse_ = VecX::Zero(cdata_->m);
  result_.vdot = VecX::Zero(model_.nv);
  result_.lambda = VecX::Zero(cdata_->m);
  result_.reaction = VecX::Zero(model_.nv);
  setUpUnilateral();  // after q_, v_: its workspace copies their sizes
  timestepping::checkOptions(options_.timestepping);
  // The time-stepping stage's workspace is dense over the unilateral rows —
  // the Delassus maps (2 nv × rows) and the contact problem's three rows ×
  // rows matrices (timestepping/delassus.cpp, contact_problem.cpp), m bounding
  // rows: built here when that is modest, else when a first window needs it
  // (timeSteppingStage) — a chain of 10⁵ joint limits must not reserve
  // 10⁵ × 10⁵ doubles it never uses. (Counting nv × m alone, 740 balls on a
  // floor reserved 0.30 GB here: docs/hardening.md.)
  const double m = cdata_->m;
  if (uni_ && 2.0 * model_.nv * m + 3.0 * m * m <= kEagerTimeSteppingDoubles)
    timeSteppingStage();
  last_modes_.assign(constraints_.size(), 0);
  event_ring_.assign(options_.timestepping.zeno_events, 0.0);
  window_min_ = options_.timestepping.min_window;
  // Size every per-step buffer of the field and the solver once, here.
  std::string ignored;
  evaluateEndState(ignored);
  if (uni_)  // each contact starts on its nearest piece
    for (auto& r : uni_->rows)
      if (!r.joint) r.feature = r.feature_start = r.feature_free = cdata_->blocks[r.c].piece.feature;
  VecX vdot(model_.nv);
  (*field_)(t_, q_, v_, vdot);
  field_->clear();
}

Simulator::Impl::~Impl() = default;

bool Simulator::Impl::setState(double t, const VecX& q, const VecX& v) {
  if (q.size() != model_.nq || v.size() != model_.nv)
    throw std::invalid_argument("Simulator::setState: q must have size nq = " +
                                std::to_string(model_.nq) + " and v size nv = " +
                                std::to_string(model_.nv));
  if (!std::isfinite(t) || !q.allFinite() || !v.allFinite())
    throw std::invalid_argument("Simulator::setState: non-finite time, q or v");
  if (const int j = degenerateQuaternionJoint(model_, q); j >= 0)
    throw std::invalid_argument("Simulator::setState: the quaternion of joint '" + model_.joint_names[j] +
                                "' is zero (it has no rotation)");
  t_ = t;
  q_ = q;
  v_ = v;
  integrator_->reset();
  h_suggest_ = 0;
  events_.clear();
  state_error_.clear();
  dissipated_ = 0;
  scheme_loss_ = 0;
  work_ = work_prev_ = {};
  if (uni_ && options_.contacts.enabled) {
    if (!decideContactModes(state_error_)) state_error_ = "initial contact modes: " + state_error_;
    // Modes the events cannot decide: time-stepping decides them (auto), or
    // is the scheme anyway.
    restartStallWatch();
    stepping_ = options_.scheme == ContactScheme::TimeStepping && timeSteppingStage();
    window_closed_once_ = false;
    window_min_ = options_.timestepping.min_window;
    if (!state_error_.empty() && options_.scheme != ContactScheme::Events && timeSteppingStage()) {
      if (options_.scheme == ContactScheme::Auto) openWindow(namedContact(state_error_), state_error_);
      state_error_.clear();
    }
  }
  std::string error;
  evaluateEndState(error);
  return state_error_.empty();
}

// Every unilateral constraint's mode at (t_, q_, v_) afresh: those with
// clearance open, the touching ones decided (impact, then forces), each on
// its nearest piece. The points of a pair close one per pass: each next one
// searches past the pieces the closed ones hold.
bool Simulator::Impl::decideContactModes(std::string& error) {
  for (auto& r : uni_->rows) cdata_->setActive(r.c, false);
  for (bool more = true; more;) {
    more = false;
    applyLatches();
    evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
    for (auto& r : uni_->rows) {
      if (cdata_->isActive(r.c)) continue;
      r.lifting = r.touching_down = false;
      r.feature = r.feature_start = r.feature_free = r.joint ? -1 : cdata_->blocks[r.c].piece.feature;
      if (r.dormant || !(cdata_->gap[r.global] <= options_.contacts.gap_tol)) continue;
      cdata_->setActive(r.c, true);
      more = more || !r.siblings.empty();
    }
  }
  const bool ok = decideModes(error) && frictionPhase(error);
  for (auto& r : uni_->rows) r.dir_start = r.dir;
  applyLatches();
  integrator_->reset();
  return ok;
}

// A compliant contact is a spring and damper only a time-stepping step
// models (its normal force from the gap at the step's end); the events hold
// every closed gap at zero. So a scene with one is time-stepped throughout:
// auto becomes timestepping, and events is refused, naming the contact.
void Simulator::Impl::chooseSchemeForCompliance() {
  for (const auto& c : constraints_) {
    if (!c->unilateral() || !c->contactLaw().compliant()) continue;
    if (options_.scheme == ContactScheme::Events)
      throw std::invalid_argument(
          "Simulator: contact '" + c->name() +
          "' is compliant (a normal stiffness): compliant contacts are time-stepped — use the "
          "contact scheme auto or timestepping, or make the contact rigid");
    options_.scheme = ContactScheme::TimeStepping;
    return;
  }
}

void Simulator::Impl::setJointForces(JointForces tau) {
  user_tau_fn_ = std::move(tau);
  composeJointForces();
}

void Simulator::Impl::setActuators(std::vector<Actuator> actuators) {
  for (const Actuator& a : actuators) a.validate(model_);
  actuators_ = std::move(actuators);
  // The time-stepping stage is sized for its servos: rebuilt (an open
  // window goes on with the new ones, from a cold start).
  const bool had_stage = mj_ != nullptr;
  mj_.reset();
  if (had_stage) timeSteppingStage();
  composeJointForces();
}

void Simulator::Impl::composeJointForces() {
  if (actuators_.empty()) {
    tau_fn_ = user_tau_fn_;
  } else {
    tau_fn_ = [this](double t, const VecX& q, const VecX& v, VecX& tau) {
      tau.setZero();
      if (user_tau_fn_) user_tau_fn_(t, q, v, tau);
      if (tau.size() == model_.nv) applyActuators(model_, actuators_, t, q, v, tau);
    };
  }
  integrator_->reset();  // a carried stage holds the old forces' acceleration
}


const ContactFrame& Simulator::Impl::contactFrame(int constraint) const {
  if (constraint < 0 || constraint >= static_cast<int>(cdata_->blocks.size()))
    throw std::out_of_range("Simulator::contactFrame: no constraint " +
                            std::to_string(constraint));
  return cdata_->blocks[constraint].frame;
}

void Simulator::Impl::restore() {
  t_ = t_prev_;
  q_ = q_prev_;
  v_ = v_prev_;
  work_ = work_prev_;
  integrator_->reset();
  std::string ignored;
  evaluateEndState(ignored);
}

StepStatus Simulator::Impl::fail(StepStatus st, std::string message) {
  restore();
  st.ok = false;
  st.message = std::move(message);
  ++counters_.failed;
  return st;
}

// Reports of the current state: constraint rows, residuals, energy and, when
// asked, the dynamics (λ, contact forces) at (t, q, v).
bool Simulator::Impl::evaluateEndState(std::string& error) {
  evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
  velocity_residual_ = appell::velocityResidual(*data_, constraints_, *cdata_, v_);
  gap_residual_ = appell::gapResidual(*cdata_);
  bool ok = true;
  if (options_.evaluate_end_state) {
    tau_.setZero();
    if (tau_fn_) tau_fn_(t_, q_, v_, tau_);
    if (tau_.size() == model_.nv && tau_.allFinite()) {
      solveDynamics(t_, q_, v_, tau_, result_);
      if (!result_.ok) {
        error = result_.error;
        ok = false;
      }
    } else {
      error = "the joint-force callback returned a non-finite or wrongly sized tau";
      ok = false;
    }
  }
  kinetic_ = appell::kineticEnergy(model_, *data_, q_, v_);
  potential_ = appell::potentialEnergy(model_, *data_, q_);
  return ok;
}

StepStatus Simulator::Impl::projectState() {
  StepStatus st;
  t_prev_ = t_;
  q_prev_ = q_;
  v_prev_ = v_;
  const StateProjectionResult pr = appell::projectState(
      model_, *data_, constraints_, *cdata_, *solver_, *projector_, t_, q_, v_, impulse_);
  projection_ = pr.position;
  st.projection_iterations = pr.position.iterations;
  if (!pr.ok) return fail(st, pr.error);
  integrator_->reset();
  std::string error;
  if (!evaluateEndState(error)) return fail(st, error);
  return st;
}

void Simulator::Impl::takeStepWork(const StepResult& r) {
  for (int i = 0; i < kWorkTerms; ++i) work_[i] = work_prev_[i] + r.integrals[i];
}

StepStatus Simulator::Impl::step(double h) {
  if (!(h > 0) || !std::isfinite(h)) {
    std::ostringstream os;
    os << "Simulator::step: the step size must be positive and finite (got " << h << ")";
    throw std::invalid_argument(os.str());
  }
  t_prev_ = t_;
  q_prev_ = q_;
  v_prev_ = v_;
  work_prev_ = work_;
  events_.clear();
  ts_step_start_ = std::numeric_limits<double>::quiet_NaN();
  if (stepping_) return timeSteppingStep(h);
  StepStatus st = attemptStep(h);
  // Sticking contacts that became over-constrained inside the step: one
  // slides from the step's start, and the step is redone (at most once per
  // unilateral constraint: friction_overconstrained.cpp).
  for (int redo = 0; !st.ok && uni_ && options_.contacts.enabled && field_->solveFailed() &&
                     redo < static_cast<int>(uni_->rows.size());
       ++redo) {
    const int k = overconstrainedContact(field_->failedT(), field_->failedQ(), field_->failedV());
    if (k < 0) break;
    --counters_.failed;  // fail() restored the step's start: not a failure after all
    detail::UnilateralRow& row = uni_->rows[k];
    row.dir_start = row.dir;
    cdata_->setSliding(row.c, true);
    logEvent(ContactEventKind::Slip, k, 0, 0, 0);
    ++counters_.overconstrained;
    st = attemptStep(h);
  }
  if (uni_ && options_.scheme == ContactScheme::Auto && options_.contacts.enabled) {
    if (!st.ok && timeSteppingStage()) {
      // The events gave up here (no consistent mode, a step below h_min, a
      // solve that failed): fail() restored the step's start, from which a
      // time-stepping window takes the step.
      --counters_.failed;
      events_.clear();
      openWindow(namedContact(st.message), st.message);
      return timeSteppingStep(h);
    }
    watchEvents();
  }
  return st;
}

// One step from the current state, as its stages: integrate, watch (a
// change of terrain piece is located at once; a contact point that jumped is
// an impact here), project the drift, evaluate the end state, watch the
// event functions, and locate and resolve the first crossing — or accept
// the contacts' modes and pieces as they are.
StepStatus Simulator::Impl::attemptStep(double h) {
  StepStatus st;
  std::string error;
  if (!integrateStep(h, st, error)) return fail(st, error);
  bool rows_current = false;  // cdata_ holds the rows at (t_, q_): the projection need not redo them
  if (uni_ && options_.contacts.enabled) {
    // A closed contact that moved onto another piece of a terrain inside
    // the step: an event, located (simulator/contact_features.cpp).
    const int k = searchFeatures();
    if (k >= 0) {
      st = locateAndHandleEvent(st, st.h_taken, k, detail::Crossing::Feature);
      if (st.ok) ++counters_.steps;
      return st;
    }
    rows_current = searchedRowsLatched();
    if (!pointJumpImpact(error, rows_current))
      return fail(st, "at t = " + std::to_string(t_) + ": " + error);
  }
  if (!projectDrift(st, rows_current, error)) return fail(st, error);
  if (!evaluateEndState(error)) {
    field_->noteFailure(t_, q_, v_);
    return fail(st, error);
  }
  // Unilateral constraints: a gap or a normal force that changed sign over
  // the step means an event inside it (event_watch.cpp, event_location.cpp).
  detail::Crossing crossing = detail::Crossing::None;
  if (uni_ && options_.contacts.enabled && crossedConstraint(crossing) >= 0) {
    st = locateAndHandleEvent(st, st.h_taken);
    if (!st.ok) return st;
  } else if (uni_) {
    if (options_.contacts.enabled) acceptFeatures();
    uni_->zero_events = 0;
    for (auto& row : uni_->rows) row.dir_start = row.dir;  // the next step's slip reference
    st.events = static_cast<int>(events_.size());  // a slip at an over-constrained redo
    counters_.events += st.events;
  }
  ++counters_.steps;
  return st;
}

/// The integrate stage: the integrator's step over the acceleration field
/// from the current state, its work integrals and counts. false with the
/// reason when it failed or left a non-finite state.
bool Simulator::Impl::integrateStep(double h, StepStatus& st, std::string& error) {
  field_->clear();
  const StepResult r = integrator_->step(*field_, t_, q_, v_, h);
  takeStepWork(r);
  st.h_taken = r.h_taken;
  st.h_next = r.h_next;
  st.rejected = r.rejected;
  st.evaluations = r.evaluations;
  counters_.rejected += r.rejected;
  counters_.evaluations += r.evaluations;
  if (!r.ok) {
    if (field_->failed()) error = field_->message();
    else if (r.failure) error = r.failure;
    else
      error = integrator_->adaptive()
                  ? "the step size fell below h_min (the dynamics are too stiff or singular here)"
                  : "the integrator produced a non-finite state";
    return false;
  }
  if (!std::isfinite(t_) || !q_.allFinite() || !v_.allFinite()) {
    error = "the integrator produced a non-finite state";
    return false;
  }
  return true;
}

/// The project stage (drift control): positions onto the gaps, then
/// velocities onto A v + b = 0. The integrator is told how far that moved
/// the state (it may keep its FSAL stage for a move within its tolerance).
bool Simulator::Impl::projectDrift(StepStatus& st, bool rows_current, std::string& error) {
  const bool projecting = options_.project_positions || options_.project_velocities;
  if (projecting) {
    q_moved_ = q_;
    v_moved_ = v_;
  }
  if (options_.project_positions) {
    projection_ = projector_->project(model_, *data_, constraints_, *cdata_, t_, q_, rows_current);
    st.projection_iterations = projection_.iterations;
    counters_.projection_iterations += projection_.iterations;
    if (!projection_.ok) {
      error = "position projection failed: " + projection_.error;
      return false;
    }
  }
  if (options_.project_velocities && cdata_->m_active > 0) {
    if (!options_.project_positions && !rows_current)
      evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
    if (!kernelProject(*cdata_, q_, v_, impulse_)) {
      field_->noteFailure(t_, q_, v_);
      error = "velocity projection failed: " + solver_->lastError();
      return false;
    }
  }
  if (projecting) {
    difference(model_, q_moved_, q_, dtheta_moved_);
    v_moved_ = v_ - v_moved_;
    integrator_->stateMoved(dtheta_moved_, v_moved_);
  }
  return true;
}

// The loop is run_loop.cpp's, carrying this simulator's step suggestion.
StepStatus Simulator::advanceTo(double t_end, double h) {
  return detail::advanceCarrying(*this, t_end, h, impl_->h_suggest_, impl_->t_);
}

}  // namespace appell
