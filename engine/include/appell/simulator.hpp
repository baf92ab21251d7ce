// The simulation loop: integrate the constrained dynamics, then remove the drift.
//
//   step(h):  (t, q, v) → integrator step on v̇ = solver(t, q, v, τ(t, q, v))
//             → position projection (Newton on the holonomic gaps, M metric)
//             → velocity projection (solver.projectVelocity, M metric)
//             → reset the integrator's FSAL stage (the state was changed)
//             → evaluate the end state for reports (λ, contact frames,
//               energy, residuals)
//             → unilateral constraints (contact_events.hpp): if an open one
//               crossed its gap or a closed one's λ would pull, the step is
//               shortened to the first such event, located by root finding,
//               and the contact modes are decided there (impact, then the
//               contact-force complementarity problem).
// A step that fails (solver error, non-finite joint forces or state, step size
// below h_min, projection failure) returns a status with the reason and leaves
// the last good state untouched. Everything is preallocated at construction:
// step() performs no heap allocation on success (given constraints and a
// joint-force callback that do not allocate).
#pragma once

#include <appell/constrained_dynamics.hpp>
#include <appell/contact_events.hpp>
#include <appell/integrators.hpp>
#include <appell/projection.hpp>

#include <array>
#include <functional>
#include <memory>
#include <string>

namespace appell {

/// Which scheme handles the unilateral contacts (docs/contacts.md §10).
enum class ContactScheme {
  Events,        ///< event-driven: exact mode switches, located events (§7–8)
  TimeStepping,  ///< Moreau–Jean: velocity-level impulses per fixed step
  Auto,          ///< events, with time-stepping windows where they fail or pile up
};
/// "events", "timestepping" (time_stepping, moreau_jean), "auto": the names
/// of --contacts, the scene's <simulation contacts="…"> and the Python option.
std::span<const NamedValue<ContactScheme>> contactSchemeTable();
const char* toString(ContactScheme scheme);
/// Parses any name of contactSchemeTable(); throws std::invalid_argument otherwise.
ContactScheme contactSchemeFromString(const std::string& name);

/// The time-stepping scheme and the automatic switch (docs/contacts.md §10).
struct TimeSteppingOptions {
  double step = 1e-3;        ///< h of a Moreau–Jean step (s); a shorter requested step is taken
  /// q⁺ = q ⊕ h (θ v⁺ + (1 − θ) v). θ = 1: a contact's gap target
  /// (u⁺ₙ ≥ −g/h) lands it on g = 0 at the step's end; below 1 a landing
  /// penetrates by O(h u⁻ₙ), pushed out over the next step.
  double theta = 1.0;
  /// The contact problem is solved until the natural-map residual of the
  /// Coulomb law in De Saxcé's form is below residual_tol · max(1, |u_free|∞)
  /// (m/s) or max_sweeps Gauss–Seidel sweeps are done (counted, never fatal).
  double residual_tol = 1e-10;
  int max_sweeps = 2000;
  // auto: when a window starts …
  int zeno_events = 64;      ///< … this many events within zeno_time (s) of simulated time
  double zeno_time = 1e-2;
  int collapse_steps = 200;  ///< … or that many steps advance less than collapse_step each on average
  double collapse_step = 1e-7;
  // … and when it ends: at least min_window (s, doubled each time the events
  // fail again within a window's length of its end), the contact modes
  // unchanged over stable_steps steps, and the event scheme's modes decided.
  double min_window = 0.05;
  int stable_steps = 50;
};

namespace detail {
enum class Crossing;
struct UnilateralRow;
struct FrictionProblem;
}
namespace timestepping {
class MoreauJean;
}

struct SimulatorOptions {
  bool project_positions = true;   ///< Newton on the holonomic gaps after every step
  bool project_velocities = true;  ///< impulse solve after every step
  ProjectionOptions projection;
  BaumgarteOptions baumgarte;      ///< off by default (projection is the method)
  /// Solve the dynamics at the end of each step, so lambda() and contact
  /// frames describe the current state (one extra solve per step). Needed
  /// for lift-off detection: with it off, closed contacts never open.
  bool evaluate_end_state = true;
  ContactEventOptions contacts;    ///< unilateral contacts: events, impacts
  ContactScheme scheme = ContactScheme::Auto;
  TimeSteppingOptions timestepping;
};

/// Throws std::invalid_argument naming the first option that is NaN, infinite,
/// negative where it must not be, or an iteration count below one
/// (simulator/options.cpp). The Simulator's constructor calls it.
void validateOptions(const SimulatorOptions& options);

struct StepStatus {
  bool ok = true;
  std::string message;   ///< why !ok (empty on success)
  double h_taken = 0;
  double h_next = 0;     ///< the integrator's suggestion (adaptive) or h
  int rejected = 0;
  int evaluations = 0;
  int projection_iterations = 0;
  int events = 0;        ///< contact events at the end of this step (events())
};

struct SimulatorCounters {
  long steps = 0;                  ///< accepted steps
  long rejected = 0;               ///< rejected attempts (adaptive)
  long evaluations = 0;            ///< dynamics solves by the integrator
  long failed = 0;                 ///< step() calls that returned !ok
  long projection_iterations = 0;  ///< Newton iterations of the position projection
  long events = 0;                 ///< contact events (touchdown, bounce, lift-off)
  long event_steps = 0;            ///< extra steps taken to locate events
  /// Friction onsets whose joint problem did not settle (its modes were then
  /// decided one contact at a time: docs/contacts.md §8).
  long friction_onset_unsettled = 0;
  /// Solves whose sliding contacts' settled directions did not settle (they
  /// then slid along their slips: friction_settled.cpp).
  long settle_unsettled = 0;
  /// Steps redone because their sticking contacts became over-constrained
  /// (one then slides: friction_overconstrained.cpp).
  long overconstrained = 0;
  /// Time-stepping (docs/contacts.md §10): steps taken by it, the windows the
  /// automatic scheme opened, contact problems that hit max_sweeps, and the
  /// largest residual of a solved one.
  long timestepping_steps = 0;
  long windows = 0;
  long unconverged = 0;
  double max_contact_residual = 0;
};

class Simulator {
 public:
  /// τ(t, q, v) written into `tau` (size nv, zeroed before the call).
  using JointForces = std::function<void(double t, const VecX& q, const VecX& v, VecX& tau)>;

  /// `model` must outlive the simulator. The state starts at t = 0, the
  /// neutral configuration and zero velocity; call setState().
  Simulator(const Model& model, ConstraintList constraints,
            std::unique_ptr<ConstrainedSolver> solver, IntegratorType integrator,
            const IntegratorOptions& integrator_options = {},
            const SimulatorOptions& options = {});
  ~Simulator();

  /// Sets the state (throws std::invalid_argument on wrong sizes or non-finite
  /// values) and evaluates it for reports; does not project. Unilateral
  /// constraints start open where their gap exceeds the touching tolerance;
  /// the touching ones get their modes decided (an impact if they approach).
  /// Returns false (and lastStateError()) if no consistent mode was found.
  bool setState(double t, const VecX& q, const VecX& v);
  const std::string& lastStateError() const { return state_error_; }
  /// Projects the current state onto the constraints (e.g. initial conditions).
  StepStatus projectState();
  void setJointForces(JointForces tau);

  /// One step of size h (the first attempt, for adaptive integrators).
  StepStatus step(double h);
  /// Steps until t_end: fixed-step integrators with steps of h (the last one
  /// shortened), adaptive ones starting from h and then following their own
  /// suggestion. Stops at the first failure and returns it.
  StepStatus advanceTo(double t_end, double h);

  // State.
  double time() const { return t_; }
  const VecX& q() const { return q_; }
  const VecX& v() const { return v_; }

  // Reports of the current state (after the last step / setState).
  const ConstrainedResult& dynamics() const { return result_; }   ///< v̇, λ, Aᵀλ, rank
  const VecX& lambda() const { return result_.lambda; }
  const ContactFrame& contactFrame(int constraint) const;
  const ConstraintData& constraintData() const { return *cdata_; }
  double kineticEnergy() const { return kinetic_; }
  double potentialEnergy() const { return potential_; }
  double energy() const { return kinetic_ + potential_; }
  double velocityResidual() const { return velocity_residual_; }  ///< ‖A v + b‖∞
  double gapResidual() const { return gap_residual_; }            ///< max |g|
  int redundantRows() const { return result_.redundant; }
  /// Coordinate-partition re-choices of an AppellSolver (0 for other solvers).
  int partitionChanges() const;
  const PositionProjectionResult& lastProjection() const { return projection_; }
  const VecX& lastImpulse() const { return impulse_; }
  /// Contact events of the last step() / setState(), in time order (the
  /// buffer is reused: copy what you keep).
  const std::vector<ContactEvent>& events() const { return events_; }
  /// Kinetic energy taken by the impacts since setState() (J, ≥ 0 up to
  /// round-off; an impact at setState() itself is not counted):
  /// E + impactEnergyLoss() is conserved by a passive scene.
  double impactEnergyLoss() const { return dissipated_; }
  /// Energy taken by sliding friction since setState() (J, ≥ 0): the power
  /// −vᵀQ_f of the friction forces Q_f the dynamics applied (μₖ λₙ |slip|
  /// per contact sliding along its slip), integrated over each step by the
  /// integrator's own stages and weights — to the method's order, like the
  /// state itself: E + impactEnergyLoss() + frictionWork() is conserved by a
  /// passive scene to the integration tolerance.
  double frictionWork() const { return work_[kFrictionWork]; }
  /// Work done on the system since setState() (J), by the same quadrature:
  /// by the joint forces (∫ τ·v dt) and by constraints that move in time
  /// (∫ −λᵀb dt: a turntable or a conveyor drives through its rows). The
  /// balance E + impactEnergyLoss() + frictionWork() − jointWork() −
  /// supportWork() = E(0) holds for every scene (impacts on moving supports
  /// are counted in impactEnergyLoss()).
  double jointWork() const { return work_[kJointWork]; }
  double supportWork() const { return work_[kSupportWork]; }
  /// Whether unilateral constraint `c` is closed now.
  bool isClosed(int constraint) const { return cdata_->isActive(constraint); }
  const SimulatorCounters& counters() const { return counters_; }
  /// The scheme of the next step: Events or TimeStepping (docs/contacts.md §10).
  ContactScheme stepScheme() const {
    return stepping_ ? ContactScheme::TimeStepping : ContactScheme::Events;
  }
  /// Under ContactScheme::Auto: opens a time-stepping window from the
  /// current state (a watchdog's switch), logged as a TimeStepping event at
  /// the next step. false when the scheme is not auto, no contact is
  /// unilateral, or a window is already open.
  bool openTimeSteppingWindow(const std::string& why);
  /// Why the last window opened (empty before the first).
  const std::string& windowReason() const { return window_reason_; }

  const Model& model() const { return model_; }
  const ConstraintList& constraints() const { return constraints_; }
  ConstrainedSolver& solver() { return *solver_; }
  Integrator& integrator() { return *integrator_; }

 private:
  class Field;
  StepStatus fail(StepStatus st, std::string message);
  /// One step from the current state (step() saved it as the step's start).
  StepStatus attemptStep(double h);
  bool evaluateEndState(std::string& error);
  void restore();
  // Unilateral constraints (simulator/contact_events.cpp).
  void setUpUnilateral();
  int crossedConstraint(detail::Crossing& type) const;
  bool solveDynamics(double t, const VecX& q, const VecX& v, const VecX& tau,
                     ConstrainedResult& out, SolveOutputs outputs = SolveOutputs::All);
  bool frictionPhase(std::string& error, int forced = -1);
  bool frictionOnset(int forced, std::string& error);
  bool solveSettling(double t, const VecX& q, const VecX& v, const VecX& tau,
                     ConstrainedResult& out, SolveOutputs outputs);
  void frictionUnitForces(const std::vector<int>& rows, int detail::UnilateralRow::*first,
                          detail::FrictionProblem& p);
  bool frictionResponses(double t, const VecX& q, const VecX& v, const VecX& tau,
                         const std::vector<int>& rows, int detail::UnilateralRow::*first, int F,
                         detail::FrictionProblem& p, bool with_velocities = false);
  /// An impact's friction impulses (friction_impact.cpp). When they would
  /// pull a contact that was at rest in the set, `separating` names it.
  bool frictionImpact(std::string& error, int& separating);
  void shiftImpactTargets();
  Vec3 contactSlip(int k) const;
  std::string rigidRollingHint() const;
  /// At a state where the sticking rows turned out inconsistent: the
  /// unilateral row whose contact slides to resolve it (its dir set), or −1
  /// (friction_overconstrained.cpp).
  int overconstrainedContact(double t, const VecX& q, const VecX& v);
  Vec3 frictionForce(int k, const VecX& lambda) const;
  /// `k`, `type`: a crossing already found (−1: look for one).
  StepStatus locateAndHandleEvent(StepStatus st, double h, int k = -1,
                                  detail::Crossing type = detail::Crossing{});
  double eventFunction(int u, detail::Crossing type);
  // Time-stepping windows (simulator/timestepping_window.cpp).
  bool decideContactModes(std::string& error);
  StepStatus timeSteppingStep(double h);
  void openWindow(int constraint, std::string why);
  /// The time-stepping stage, built on first use (false: no unilateral
  /// constraint, or too large to allocate).
  bool timeSteppingStage();
  static constexpr double kEagerTimeSteppingDoubles = 1e7;  ///< 80 MB: built at construction
  bool closeWindow();
  void watchEvents(const StepStatus& st);
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
  bool impactPhase(std::string& error);
  bool forcePhase(std::string& error);
  int unloadingContact();
  void saveCandidateRows();
  double rowVelocity(int u) const;
  double rowAcceleration(int u) const;
  void logEvent(ContactEventKind kind, int u, double before, double after, double impulse);

  const Model& model_;
  ConstraintList constraints_;
  std::unique_ptr<ConstrainedSolver> solver_;
  std::unique_ptr<Integrator> integrator_;
  SimulatorOptions options_;
  std::unique_ptr<Data> data_;
  std::unique_ptr<ConstraintData> cdata_;
  std::unique_ptr<PositionProjector> projector_;
  std::unique_ptr<Field> field_;
  JointForces tau_fn_;

  double t_ = 0, t_prev_ = 0;
  VecX q_, v_, q_prev_, v_prev_, tau_, impulse_;
  VecX q_moved_, v_moved_, dtheta_moved_;  // the state before the drift projection, and the move
  ConstrainedResult result_;
  PositionProjectionResult projection_;
  double kinetic_ = 0, potential_ = 0, velocity_residual_ = 0, gap_residual_ = 0;
  double h_suggest_ = 0;
  SimulatorCounters counters_;
  std::unique_ptr<detail::UnilateralState> uni_;  // sized once: contact_events.cpp
  std::vector<ContactEvent> events_;
  std::string state_error_;
  double dissipated_ = 0;
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
  std::vector<double> event_ring_, step_ring_;
  long event_count_ = 0, step_count_ = 0;
  std::string window_reason_;
};

}  // namespace appell
