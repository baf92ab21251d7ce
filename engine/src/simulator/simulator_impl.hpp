// Simulator::Impl: the simulator's stages and the state they share (the
// pimpl behind appell/simulator.hpp, allocated once at construction).
//
// One step (Simulator::Impl::attemptStep, simulator.cpp) runs the stages in
// order over this state:
//   integrate   the integrator over the acceleration Field (below)
//   watch       pieces of terrains (contact_features.cpp), points that jumped
//               (point_jump.cpp), crossings of the event functions (event_watch.cpp)
//   locate      the first crossing, by root finding (event_locator.hpp,
//               event_location.cpp)
//   resolve     impact (impact.cpp), contact forces (contact_modes.cpp),
//               friction modes (friction_phase.cpp and friction_*.cpp)
//   project     drift control on the gaps and the velocities
//   record      the end state's reports and the event log
// Time-stepping windows (timestepping_window.cpp) replace the event stages
// while open. The per-contact workspace is detail::UnilateralState
// (simulator_internal.hpp).
#pragma once

#include <appell/configuration.hpp>
#include <appell/simulator.hpp>

#include "simulator/simulator_internal.hpp"

#include <array>
#include <limits>
#include <sstream>
#include <memory>
#include <string>
#include <vector>

namespace appell {

namespace timestepping {
class MoreauJean;
}

struct Simulator::Impl {
  using JointForces = Simulator::JointForces;

  Impl(const Model& model, ConstraintList constraints, std::unique_ptr<ConstrainedSolver> solver,
       IntegratorType integrator, const IntegratorOptions& integrator_options,
       const SimulatorOptions& options);
  ~Impl();

  // What the public methods do (simulator.cpp, timestepping_window.cpp).
  bool setState(double t, const VecX& q, const VecX& v);
  StepStatus projectState();
  void setJointForces(JointForces tau);
  void setActuators(std::vector<Actuator> actuators);
  void composeJointForces();
  void chooseSchemeForCompliance();
  StepStatus step(double h);
  const ContactFrame& contactFrame(int constraint) const;
  bool openTimeSteppingWindow(const std::string& why);

  class Field;
  StepStatus fail(StepStatus st, std::string message);
  /// One step from the current state (step() saved it as the step's start).
  StepStatus attemptStep(double h);
  // Its stages: integrate and project (simulator.cpp); watch, locate and
  // resolve below.
  bool integrateStep(double h, StepStatus& st, std::string& error);
  bool projectDrift(StepStatus& st, bool rows_current, std::string& error);
  bool evaluateEndState(std::string& error);
  void restore();
  // Unilateral constraints: the workspace (unilateral_setup.cpp).
  void setUpUnilateral();
  void linkPointGroups();
  void sizeUnilateralWorkspace();
  int crossedConstraint(detail::Crossing& type) const;
  bool solveDynamics(double t, const VecX& q, const VecX& v, const VecX& tau,
                     ConstrainedResult& out, SolveOutputs outputs = SolveOutputs::All);
  bool frictionPhase(std::string& error, int forced = -1);
  bool frictionOnset(int forced, std::string& error);
  bool solveSettling(double t, const VecX& q, const VecX& v, const VecX& tau,
                     ConstrainedResult& out, SolveOutputs outputs);
  bool markSliding(const VecX& v);
  void slidingFrictionColumns(std::span<const int> run);
  bool slidingLoadResponses(const VecX& q, const VecX& v, const VecX& tau, int first,
                            std::span<const int> run, ConstrainedResult& out);
  bool slidingNormalLoads(const VecX& q, const VecX& v, const VecX& tau, int first,
                          std::span<const int> run, ConstrainedResult& out);
  bool settleIsland(double t, const VecX& q, const VecX& v, const VecX& tau,
                    std::span<const int> run, double& power, ConstrainedResult& out);
  double settleCandidate(std::span<const int> run, int j, int F);
  void recordSettledForces(ConstrainedResult& out, SolveOutputs outputs);
  void frictionUnitForces(std::span<const int> rows, int detail::UnilateralRow::*first,
                          detail::FrictionProblem& p);
  bool frictionResponses(double t, const VecX& q, const VecX& v, const VecX& tau,
                         std::span<const int> rows, int detail::UnilateralRow::*first, int F,
                         detail::FrictionProblem& p, bool with_velocities = false);
  /// An impact's friction impulses (friction_impact.cpp). When they would
  /// pull a contact that was at rest in the set, `separating` names it.
  bool frictionImpact(std::string& error, int& separating);
  bool frictionImpactCandidates();
  bool frictionImpactMaps(std::span<const int> run, int F, std::string& error);
  int frictionImpactIsland(std::span<const int> run, bool first, std::string& error);
  bool applyFrictionImpulses(int& separating, std::string& error);
  void releaseOnset(bool keep_modes);
  bool frictionOnsetIsland(std::span<const int> run, int forced, std::string& error);
  void setOnsetModes(std::span<const int> run, int forced, int F);
  int overconstrainedIsland(double t, const VecX& q, const VecX& v, std::span<const int> run,
                            double& worst, Vec3& dir);
  void shiftImpactTargets();
  Vec3 contactSlip(int k) const;
  std::string rigidRollingHint() const;
  /// At a state where the sticking rows turned out inconsistent: the
  /// unilateral row whose contact slides to resolve it (its dir set), or −1
  /// (friction_overconstrained.cpp).
  int overconstrainedContact(double t, const VecX& q, const VecX& v);
  Vec3 frictionForce(int k, const VecX& lambda) const;
  // Locate and resolve (event_location.cpp, event_locator.hpp).
  /// `k`, `type`: a crossing already found (−1: look for one).
  StepStatus locateAndHandleEvent(StepStatus st, double h, int k = -1,
                                  detail::Crossing type = detail::Crossing{});
  bool moveAlongStep(double tau, double h, bool dense, StepStatus& st);
  bool locateEvent(StepStatus& st, double h, bool dense, detail::LocatedEvent& ev,
                   std::string& error);
  StepStatus resolveEvent(StepStatus st, const detail::LocatedEvent& located);
  bool resolveFrictionEvent(int k, detail::Crossing type, std::string& error);
  // Watch (event_watch.cpp).
  double eventFunction(int u, detail::Crossing type);
  int earlierCrossing(int k, detail::Crossing type, detail::Crossing& earlier_type);
  // Time-stepping windows (simulator/timestepping_window.cpp).
  bool decideContactModes(std::string& error);
  StepStatus timeSteppingStep(double h);
  void recordTimeSteppingWork();
  bool takeTimeSteppingModes();
  void openWindow(int constraint, std::string why);
  /// The time-stepping stage, built on first use (false: no unilateral
  /// constraint, or too large to allocate).
  bool timeSteppingStage();
  static constexpr double kEagerTimeSteppingDoubles = 1e7;  ///< 80 MB: built at construction
  bool closeWindow();
  void watchEvents();
  /// Starts the Zeno and stall watches' counts afresh from the current state.
  void restartStallWatch();
  /// The step-size part of the stall watch; true when it opened a window.
  bool watchStepSize();
  int namedContact(const std::string& message) const;
  bool restepTo(double tau, StepStatus& st);
  /// work_ after an integrator step from the last step's start.
  void takeStepWork(const StepResult& r);
  bool decideModes(std::string& error);
  bool pointJumpImpact(std::string& error, bool& rows_current);
  // Contacts on piecewise supports (simulator/contact_features.cpp).
  void applyLatches();
  int searchFeatures();
  bool searchedRowsLatched() const;
  void acceptFeatures();
  void switchFeatures(bool lookahead);
  bool projectAfterModes(std::string& error);
  // Impact (impact.cpp) and contact forces (contact_modes.cpp).
  bool impactPhase(std::string& error);
  bool impactTargets();
  bool impactPivoting(std::string& error);
  void logImpacts();
  bool forcePhase(std::string& error);
  bool forceCandidates(bool& held);
  bool forcePivoting(bool held, std::string& error);
  bool solveTrialSet(bool held, bool& consistent, std::string& error);
  int unloadingContact();
  void saveCandidateRows();
  double rowVelocity(int u) const;
  double rowAcceleration(int u) const;
  void logEvent(ContactEventKind kind, int u, double before, double after, double impulse);

  // The constrained solver's two operations, counted in counters_.solves
  // (the stall rule's measure of work, with the friction block updates).
  void kernelSolve(const VecX& q, const VecX& v, const VecX& tau, ConstrainedResult& out,
                   SolveOutputs outputs) {
    ++counters_.solves;
    solver_->solve(model_, *data_, constraints_, *cdata_, q, v, tau, out, outputs);
  }
  bool kernelProject(ConstraintData& cd, const VecX& q, VecX& v, VecX& impulse) {
    ++counters_.solves;
    return solver_->projectVelocity(model_, *data_, constraints_, cd, q, v, impulse);
  }

  const Model& model_;
  ConstraintList constraints_;
  std::unique_ptr<ConstrainedSolver> solver_;
  std::unique_ptr<Integrator> integrator_;
  SimulatorOptions options_;
  std::unique_ptr<Data> data_;
  std::unique_ptr<ConstraintData> cdata_;
  std::unique_ptr<PositionProjector> projector_;
  std::unique_ptr<Field> field_;
  // The joint forces: the caller's, the servos', and their sum, which every
  // event stage evaluates (a Moreau–Jean step takes the servos implicitly).
  JointForces user_tau_fn_;
  std::vector<Actuator> actuators_;
  JointForces tau_fn_;

  double t_ = 0, t_prev_ = 0;
  VecX q_, v_, q_prev_, v_prev_, tau_, impulse_;
  VecX q_moved_, v_moved_, dtheta_moved_;  // the state before the drift projection, and the move
  ConstrainedResult result_;
  PositionProjectionResult projection_;
  double kinetic_ = 0, potential_ = 0, velocity_residual_ = 0, gap_residual_ = 0;
  double h_suggest_ = 0;
  SimulatorCounters counters_;
  std::unique_ptr<detail::UnilateralState> uni_;  // sized once: unilateral_setup.cpp
  std::vector<ContactEvent> events_;
  std::string state_error_;
  double dissipated_ = 0;
  double scheme_loss_ = 0;  // the time-stepping θ-method's own loss (StepWork::scheme)
  // Work integrals since setState(), now and at the last step's start (a
  // step redone to an event starts from there): the Field's rates.
  enum WorkIndex { kFrictionWork, kJointWork, kSupportWork, kWorkTerms };
  static_assert(kWorkTerms <= AccelerationField::kMaxRates);
  std::array<double, kWorkTerms> work_{}, work_prev_{};
  // Time-stepping: the stage, whether the next step is one, the open
  // window (start, minimum length, modes unchanged since, the last modes),
  // and the automatic switch's watches (rings of event and step times).
  std::unique_ptr<timestepping::MoreauJean> mj_;
  bool stepping_ = false;
  double window_start_ = 0, window_min_ = 0, window_end_ = 0;
  bool window_closed_once_ = false;
  int stable_ = 0;
  int window_contact_ = -1;  // a window to log at the next step (its contact), or −1
  std::vector<signed char> last_modes_;
  std::vector<double> event_ring_;
  long event_count_ = 0;
  int last_event_contact_ = -1;  // the constraint of the last mode change (events)
  // The stall watch: the simulated time at the last kStallMarks marks, the
  // marks so far, the work at which the next is set, and the marks in a row
  // that found low progress.
  static constexpr int kStallMarks = 4, kStallLowMarks = 8;
  long work() const { return counters_.solves + counters_.block_updates; }
  std::array<double, kStallMarks> stall_t_{};
  long stall_marks_ = 0, stall_next_ = 0, stall_low_ = 0;
  // The step-size watch (watchStepSize): the same marks over accepted steps.
  std::array<double, kStallMarks> step_t_{};
  long step_marks_ = 0, step_next_ = 0;
  std::string window_reason_;
  // The start of the last step when it was time-stepped (NaN: an event
  // step, or none yet): when mj_ holds that step's contact problem.
  double ts_step_start_ = std::numeric_limits<double>::quiet_NaN();
};

// v̇ = f(t, q, v): joint forces, constraint rows, the solver. Failures are
// remembered (with the reason) and reported as "not admissible" to the
// integrator, which then rejects the step.
class Simulator::Impl::Field final : public AccelerationField {
 public:
  explicit Field(Impl& s)
      : s_(s),
        tau_(VecX::Zero(s.model_.nv)),
        residual_(VecX::Zero(s.cdata_->m)),
        residual_c_(VecX::Zero(s.cdata_->m)),
        impulse_(VecX::Zero(s.cdata_->m)),
        q_kick_(s.model_.nq),
        q_fail_(s.model_.nq),
        v_fail_(s.model_.nv) {}

  bool operator()(double t, const VecX& q, const VecX& v, VecX& vdot) override {
    Impl& s = s_;
    tau_.setZero();
    if (s.tau_fn_) {
      s.tau_fn_(t, q, v, tau_);
      if (tau_.size() != s.model_.nv || !tau_.allFinite()) {
        record("the joint-force callback returned a non-finite or wrongly sized tau", t);
        return false;
      }
    }
    // Only the closed rows act on the motion: contacts in flight are
    // evaluated at the step's end, where touchdown is detected.
    s.cdata_->closed_only = true;
    evaluateConstraintRows(s.model_, *s.data_, s.constraints_, *s.cdata_, t, q, v);
    s.cdata_->closed_only = false;
    if (s.options_.baumgarte.enabled)
      applyBaumgarte(*s.data_, s.constraints_, *s.cdata_, v, s.options_.baumgarte.alpha,
                     s.options_.baumgarte.beta);
    // Rows that move in time (b ≠ 0) do work −λᵀb: only then are the
    // multipliers needed at a stage.
    const bool moving = (s.cdata_->b.array() != 0).any();
    s.solveDynamics(t, q, v, tau_, stage_, moving ? SolveOutputs::All : SolveOutputs::Accelerations);
    if (!stage_.ok) {
      if (!failed_) noteFailure(t, q, v);
      record(stage_.error, t);
      return false;
    }
    if (!stage_.vdot.allFinite()) {
      record("the solver returned a non-finite acceleration", t);
      return false;
    }
    vdot = stage_.vdot;
    // The powers of the work balance at this stage (Simulator::frictionWork).
    rates_[kFrictionWork] = s.uni_ ? s.uni_->friction_power : 0.0;
    rates_[kJointWork] = tau_.dot(v);
    rates_[kSupportWork] = moving ? -stage_.lambda.dot(s.cdata_->b) : 0.0;
    return true;
  }
  bool constrained() const override { return !s_.constraints_.empty(); }
  bool projectVelocity(double t, const VecX& q, VecX& v) override {
    Impl& s = s_;
    evaluateConstraintRows(s.model_, *s.data_, s.constraints_, *s.cdata_, t, q, v);
    if (!s.kernelProject(*s.cdata_, q, v, impulse_)) {
      record("the leapfrog's velocity projection failed: " + s.solver_->lastError(), t);
      return false;
    }
    return true;
  }
  // The leapfrog's discrete constraints (integrators.hpp): the residuals at
  // the half-step point (velocity rows) and the gaps at the step's end over h
  // (holonomic rows), removed by impulses along the rows at (t, q) — the rows
  // at q with their offsets shifted by (those residuals − the residual at q),
  // then the solver's own M-orthogonal projection.
  bool constrainKick(double t, const VecX& q, double h, VecX& w) override {
    Impl& s = s_;
    ConstraintData& cd = *s.cdata_;
    integrate(s.model_, q, w, 0.5 * h, q_kick_);
    evaluateConstraintRows(s.model_, *s.data_, s.constraints_, cd, t + 0.5 * h, q_kick_, w);
    velocityResiduals(*s.data_, s.constraints_, cd, w, residual_c_);
    integrate(s.model_, q, w, h, q_kick_);
    evaluateConstraintRows(s.model_, *s.data_, s.constraints_, cd, t + h, q_kick_, w);
    // A gap at the round-off of its own evaluation (ε·|q|) is zero: divided
    // by an event's shortened step (h ~ 1e-12 s) it would be a velocity
    // correction of ~1e-5 m/s that changes with each evaluation's round-off,
    // and the implicit kick's fixed point could not settle.
    const double gap_floor = 8 * std::numeric_limits<double>::epsilon() *
                             (1 + q_kick_.lpNorm<Eigen::Infinity>());
    for (int i = 0; i < cd.m; ++i)
      if (cd.holonomic[i] && cd.isActive(cd.row_constraint[i]))
        residual_c_[i] = std::abs(cd.gap[i]) > gap_floor ? cd.gap[i] / h : 0.0;
    evaluateConstraintRows(s.model_, *s.data_, s.constraints_, cd, t, q, w);
    velocityResiduals(*s.data_, s.constraints_, cd, w, residual_);
    residual_c_ -= residual_;
    shiftRowOffsets(s.constraints_, cd, residual_c_);
    if (!s.kernelProject(cd, q, w, impulse_)) {
      record("the leapfrog's constrained half-kick failed: " + s.solver_->lastError(), t);
      return false;
    }
    return true;
  }
  int rateCount() const override { return kWorkTerms; }
  double rate(int i) const override { return rates_[i]; }

  void clear() {
    failed_ = false;
    solve_failed_ = false;
    message_.clear();
  }
  bool failed() const { return failed_; }
  /// A solve failed at (t, q, v) — a stage's, or the step's end state or
  /// projection (Impl::attemptStep): an over-constrained sticking set is
  /// decided there (Impl::step, friction_overconstrained.cpp).
  void noteFailure(double t, const VecX& q, const VecX& v) {
    solve_failed_ = true;
    t_fail_ = t;
    q_fail_ = q;
    v_fail_ = v;
  }
  /// Whether a solve failed (then failedT/Q/V are its state).
  bool solveFailed() const { return solve_failed_; }
  double failedT() const { return t_fail_; }
  const VecX& failedQ() const { return q_fail_; }
  const VecX& failedV() const { return v_fail_; }
  const std::string& message() const { return message_; }

 private:
  void record(const std::string& why, double t) {
    if (failed_) return;  // keep the first reason
    failed_ = true;
    std::ostringstream os;
    os << why << " (at t = " << t << ")";
    message_ = os.str();
  }

  Impl& s_;
  VecX tau_;
  VecX residual_, residual_c_, impulse_;  // constrainKick's (size m)
  VecX q_kick_;                           // its half-step and end points
  ConstrainedResult stage_;
  std::array<double, kWorkTerms> rates_{};
  bool failed_ = false;
  bool solve_failed_ = false;
  double t_fail_ = 0;
  VecX q_fail_, v_fail_;
  std::string message_;
};

}  // namespace appell
