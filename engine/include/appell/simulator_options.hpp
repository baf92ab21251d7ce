// The simulator's options (contact scheme, time-stepping, projection, contact
// events) and what it reports (StepStatus per step, SimulatorCounters over a
// run): the plain data a user sets and reads around appell/simulator.hpp.
// validateOptions is in simulator/options.cpp.
#pragma once

#include <appell/constrained_dynamics.hpp>
#include <appell/contact_events.hpp>
#include <appell/projection.hpp>

#include <span>
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
  /// … or when the last stall_work units of the event scheme's work
  /// (SimulatorCounters::solves + block_updates: every stage, rejected steps
  /// and event location included) advanced the simulated time by less than
  /// stall_time (s), checked every stall_work/4 units and found at eight
  /// checks in a row: a stall decided by counts of the simulation's own work,
  /// so the same run switches at the same state on any machine under any
  /// load (the wall clock only stops a run: RunOptions::watchdog_fraction).
  /// 10⁵ units are 0.4–0.8 s of CPU on a car (docs/contacts.md §10).
  long stall_work = 100000;
  double stall_time = 1e-3;
  /// … or when the last stall_steps accepted event steps advanced the
  /// simulated time by less than stall_time, or the last stall_steps/2 by
  /// less than stall_time/100 (checked every stall_steps/4 steps): the step
  /// size collapsed — a mean step below 7.8 µs, or 156 ns over half as many
  /// steps, at the defaults, where every example's largest burst is 39 steps
  /// in 1 ms, its shortest 64 steps span 0.47 ms, and the stalls run at 200
  /// steps per ms and more (docs/contacts.md §10). Cheap steps that stall (a
  /// box's four corners at their slip onset) are caught here long before
  /// their work reaches the rule above.
  long stall_steps = 128;
  // … and when it ends: at least min_window (s, doubled each time the events
  // fail again within a window's length of its end), the contact modes
  // unchanged over stable_steps steps, and the event scheme's modes decided.
  double min_window = 0.05;
  int stable_steps = 50;
};

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
  long evaluations = 0;            ///< calls of the integrator's field (v̇ at a stage)
  /// The constrained solver's dynamics solves and velocity projections (an
  /// evaluation with k sliding contacts takes k + 2 of them), and the blocks
  /// that the friction problems' Gauss–Seidel sweeps solved: the
  /// simulation's work, which the automatic scheme's stall rule counts.
  long solves = 0;
  long block_updates = 0;
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
  /// largest residual of a solved one; the largest |gap| of a contact closed
  /// at the end of a time-stepping step (O(h): the step's gap targets).
  long timestepping_steps = 0;
  long windows = 0;
  long unconverged = 0;
  double max_contact_residual = 0;
  double max_contact_gap = 0;
  /// Block Gauss–Seidel sweeps over all those contact problems, and the
  /// problems an active-set solve finished (docs/contacts.md §10).
  long contact_sweeps = 0;
  long contact_polished = 0;
};

}  // namespace appell
