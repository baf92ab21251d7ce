// Running a scene: the loop behind `appell run`, for any caller (the command
// line, a parameter sweep, Python bindings).
//
//   runScene(scene, options, observer) → RunSummary
//
// builds a Simulator for the scene (its model, constraints, constant joint
// forces and initial state), steps it to `duration` — fixed steps of dt for
// euler and rk4 (the last one shortened), the integrator's own suggestion
// for dopri5 — and reduces the run to a summary while it goes:
//   energy      E₀ and max_t |E(t) − E₀|, relative to max(|E₀|, T₀) (a
//               passive scene with time-independent constraints conserves E:
//               ideal reactions do no work on motions the constraints allow);
//   residuals   max_t ‖A v + b‖∞ and max_t |g| over the holonomic gaps;
//   contacts    per constraint, from its rows' kinds (constraint.hpp): the
//               normal load f_n = λ_normal, the friction demand |f_t| / f_n
//               with f_t the λ of the tangent and lateral rows, against the
//               scene's μ, and the samples where a closed contact's normal
//               pulls (f_n < 0: only a bilateral contact can pull; a
//               unilateral one lifts off at f_n = 0);
//   events      every touchdown, bounce and lift-off (contact_events.hpp)
//               with its time, speeds and impulses; an impulse outside the
//               friction cone is flagged; the energy balance counts the
//               kinetic energy the impacts took and the work of sliding
//               friction;
//   failure     the first step that fails stops the run; the summary keeps
//               its reason and the time of the last good state.
// The observer sees the state at t = 0, after every `output_every`-th step
// and at the end; it may write a trajectory (TrajectoryWriter overload).
// The stepping itself is the engine's one loop (appell/run_loop.hpp) with
// the summary as its observer (run/src/run.cpp's SummaryObserver).
#pragma once

#include <appell/constrained_dynamics.hpp>
#include <appell/integrators.hpp>
#include <appell/output.hpp>
#include <appell/scene.hpp>
#include <appell/simulator.hpp>

#include <atomic>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace appell {

struct RunOptions {
  double duration = 1.0;           ///< simulated time (s)
  double dt = 1e-3;                ///< fixed step (euler, rk4), first step (dopri5)
  double tol = 1e-8;               ///< dopri5: relative tolerance (absolute: atol)
  std::optional<double> atol;      ///< adaptive: absolute tolerance (absent: tol/100)
  double h_min = IntegratorOptions{}.h_min;  ///< adaptive: give up below this step (s)
  /// Adaptive: the largest step (s). Absent: max(dt, duration/20), so that a
  /// run of known duration takes at least 20 steps; a simulation stepped
  /// without a duration (Python's Simulation) gives its own (its h_max
  /// option). All three are checked with the integrator's options.
  std::optional<double> h_max;
  /// Unilateral contacts may open and close (ContactEventOptions::enabled).
  bool contact_events = true;
  IntegratorType integrator = IntegratorType::RK4;
  Formulation formulation = Formulation::Tree;
  bool project_positions = true;   ///< Newton on the holonomic gaps after every step
  bool project_velocities = true;  ///< impulse solve after every step
  int output_every = 1;            ///< the observer sees every N-th step (N ≥ 1)
  /// Polled after every step: when it reads true the run stops there (a
  /// clean stop: the state reached is sampled, the summary says so). For a
  /// SIGINT handler or another thread; null: never.
  const std::atomic<bool>* stop = nullptr;
  /// Divergence watch on the work balance of every scene,
  ///     E + impact losses + friction work − joint work − support work = E₀
  /// (passive scenes: no work put in, E + losses is conserved): a step after
  /// which the balance is off by more than this fraction of the energy that
  /// moved (DivergenceWatch: the largest kinetic energy, potential energy
  /// exchanged and work so far — none depends on the potential's datum)
  /// stops the run as failed, the state kept the last one within the bound.
  /// ∞ switches it off.
  double max_energy_error = 5e-2;
  /// Residual watch: a step after which max(‖A v + b‖∞, max |gap|) exceeds
  /// this stops the run as failed, the state kept the last one within it —
  /// drift the projection no longer removes (or, with projection off, drift
  /// grown past what the user accepts). ∞ switches it off.
  double max_residual = 1e-6;
  /// ContactEventOptions::settle_time: sliding contacts whose slip direction
  /// settles faster slide on their settled directions (0: never).
  double settle_time = ContactEventOptions{}.settle_time;
  /// Near-dependency watch (run/src/rank_margin.cpp): closed rows whose
  /// smallest kept singular value (equilibrated, mass metric) is below this
  /// are reported as independent only by a margin — rows that an exact
  /// design makes dependent and CAD rounding made independent, locking a
  /// freedom (RunSummary::near_dependency). 0 switches the watch off.
  double near_dependency_level = 1e-3;
  /// Which scheme handles the contacts (docs/contacts.md §10).
  ContactScheme contacts = ContactScheme::Auto;
  /// Stall watchdog: over every `watchdog_interval` seconds of the run's CPU
  /// time (its thread's) the simulated time must advance at least
  /// `watchdog_fraction` of it. When it
  /// does not, the run stops as failed, naming the contacts, the events per
  /// simulated second and the last mode changes. It never switches the
  /// scheme: a trajectory must not depend on the machine's load — the
  /// automatic scheme's own stall rule (TimeSteppingOptions::stall_work)
  /// switches by counts, and must act first: its 2.75·10⁵ units of work
  /// take 1–2 s of CPU at the stalls measured (docs/contacts.md §10), inside
  /// the 5 s interval. 0 switches it off.
  double watchdog_fraction = 1e-3;
  double watchdog_interval = 5.0;
};

/// The scene's own settings as run options. Throws std::invalid_argument for
/// an unknown integrator or formulation name, or a non-positive duration,
/// step or tolerance.
RunOptions runOptions(const SimulationSettings& settings);

/// Whether some constraint has friction rows (tangent, lateral) with a finite
/// Coulomb coefficient — rows that can give way by sliding.
bool anyContactCanSlip(const ConstraintList& constraints);

/// One constraint's reactions over the run: a contact's normal load and friction
/// demand (constraints with a normal row), a one-row coupling's reaction.
struct ContactStats {
  std::string name;                ///< the constraint's name
  double mu = std::numeric_limits<double>::infinity();  ///< the scene's μ (∞: unchecked)
  double creep_speed = 0;          ///< regularized friction's v_c (0: Coulomb with sticking)
  int normal_row = -1;             ///< λ index of the normal row, −1: none (no stats)
  std::vector<int> tangential_rows;  ///< λ indices of tangent and lateral rows
  /// With spin friction ℓ: the spin row's λ index and its unit ℓ/μ (its
  /// torque over ℓ/μ joins the friction demand); −1 without.
  int spin_row = -1;
  double spin_scale = 1;
  double min_normal = std::numeric_limits<double>::infinity(), max_normal = 0;
  double max_demand = 0, t_max_demand = 0;  ///< max |f_t| / f_n and when
  long pulling = 0, over_mu = 0;   ///< samples with f_n ≤ 0, with |f_t| / f_n > μ
  double first_pull = -1, first_slip = -1;  ///< when they first happened (−1: never)
  /// The friction demand exceeded μ or the normal pulled.
  bool flagged() const { return pulling > 0 || over_mu > 0; }
  long open_samples = 0;           ///< samples with the contact open (in flight)
  /// Samples with the contact sliding, and its largest slip speed then (m/s:
  /// a misaligned axle's scrub is its speed times the misalignment).
  long sliding_samples = 0;
  double max_slip = 0;
  /// The normal row moves nothing (the joints hold the contact's height, as a
  /// planar joint does a sleigh's): no normal load or friction demand to judge.
  bool normal_held = false;
  /// A one-row constraint that is not a contact (a mimic coupling): λ of its
  /// row, the generalized force it applies to its joint, and its range.
  int reaction_row = -1;
  double min_reaction = std::numeric_limits<double>::infinity(),
         max_reaction = -std::numeric_limits<double>::infinity();
};

/// A contact event of the run (Simulator::events()), named.
struct RunEvent {
  double t = 0;
  std::string contact;
  ContactEventKind kind = ContactEventKind::Touchdown;
  double speed_before = 0, speed_after = 0;  ///< normal velocity (negative: approaching)
  double normal_impulse = 0, tangential_impulse = 0;
  /// The impulse left the friction cone (|Λ_t| > μ Λ_n): a real contact would slip.
  bool outside_friction_cone = false;
  /// A change of terrain piece (ContactEventKind::Feature): the piece it
  /// moved onto, named (terrainFeatureName).
  std::string piece;
};

/// Closed rows independent only by a small margin, seen at some sample of
/// the run (run/src/rank_margin.cpp). With B = L⁻¹Aᵀ the closed rows in the
/// mass metric (M = LLᵀ), columns scaled to unit norm, and σ₁ ≥ … ≥ σᵣ its
/// singular values above the solvers' rank threshold (rank_abs_tol +
/// rank_rel_tol), σᵣ below `RunOptions::near_dependency_level` means: the
/// solvers keep those rows as independent (σᵣ is above the threshold), but
/// by a margin of round-off or CAD rounding; the motion they nearly allow is
/// locked. Recorded at the sample where σᵣ was smallest.
struct NearDependency {
  bool found = false;
  double t_first = -1;             ///< first sample where it was seen (s)
  double t = 0;                    ///< the sample with the smallest margin (s)
  double sigma = 0;                ///< σᵣ there
  double threshold = 0;            ///< the rank threshold (σ at or below it: redundant)
  /// The rows the near-dependency combines ("left_tyre.tangent1"), largest
  /// share first: the right singular vector of σᵣ, entries ≥ 0.2 of its largest.
  std::vector<std::string> rows;
  /// The freedom lost: the motion L⁻ᵀu (u the left singular vector of σᵣ)
  /// that violates the rows only by σᵣ, by velocity coordinate (CSV names,
  /// "root_joint.wz"), largest first, with its components relative to the
  /// largest; entries ≥ 0.2 of it.
  std::vector<std::pair<std::string, double>> freedom;
  long samples = 0;                ///< samples where some σᵣ was below the level
  long checks = 0;                 ///< samples checked
  /// How many times the threshold σᵣ is.
  double margin() const { return threshold > 0 ? sigma / threshold : 0; }
};

struct RunSummary {
  RunOptions options;
  bool ok = true;                  ///< every step succeeded
  std::string failure;             ///< why the run stopped (empty when ok)
  bool interrupted = false;        ///< stopped early by RunOptions::stop (still ok)
  double time = 0;                 ///< time reached (of the last good state when !ok)
  SimulatorCounters counters;
  int partition_changes = 0;       ///< re-choices of the Appell velocity partition
  double wall_seconds = 0;         ///< wall time of the stepping loop
  bool passive = true;             ///< no joint forces, no moving support: E is conserved
  double energy0 = 0;              ///< E at t = 0 (J)
  double max_energy_deviation = 0; ///< max |E + impact losses + friction work − work in − E₀| (J)
  double impact_energy_loss = 0;   ///< kinetic energy taken by impacts (J)
  double friction_work = 0;        ///< energy taken by sliding friction (J, Simulator::frictionWork)
  double scheme_energy_loss = 0;   ///< the time-stepping scheme's own loss (J, Simulator::schemeEnergyLoss)
  double joint_work = 0;           ///< work of the joint forces, ∫ τ·v dt (J)
  double support_work = 0;         ///< work of constraints that move in time, ∫ −λᵀb dt (J)
  std::vector<RunEvent> events;    ///< contact events, in time order
  double energy_scale = 0;         ///< DivergenceWatch::scale(): the energy that moved (J, ≥ 1e-12)
  double max_velocity_residual = 0;  ///< max ‖A v + b‖∞, t = 0 included
  double max_gap_residual = 0;       ///< max |g|, t = 0 included
  int max_redundant = 0;           ///< most redundant rows at any sample
  /// Independent velocities the closed constraints leave at t = 0:
  /// nv − rank(A) (0: nothing can move — an over-constrained vehicle whose
  /// axles are out of line, which the CLI warns about).
  int free_velocities = 0;
  /// Rows independent only by a margin at some sample (found = false: none).
  NearDependency near_dependency;
  /// Some contact has friction rows with a finite μ: with free_velocities 0
  /// the scene is held while its contacts stick, and moves only by slipping
  /// (a braked car parked on a slope), not stuck for good.
  bool can_slip = false;
  long samples = 0;                ///< states summarised (t = 0 and every step)
  std::vector<ContactStats> contacts;  ///< one per constraint, in order
  /// One per actuator (Scene::actuators), over the samples: the largest
  /// |τ| it applied and how often it was saturated at its effort limit.
  struct ActuatorStats {
    std::string name;
    double max_force = 0, effort_limit = 0;
    long saturated = 0;
    double first_saturated = -1, last_saturated = -1;
  };
  std::vector<ActuatorStats> actuators;

  double relativeEnergyDeviation() const { return max_energy_deviation / energy_scale; }
  int flaggedContacts() const;
};

/// Sees the simulator's current state (time, q, v, λ, contact frames, energy).
using RunObserver = std::function<void(const Simulator&)>;

/// A Simulator for the scene: its solver, integrator and projection from the
/// options, its constant joint forces, its state set to (0, q0, v0) — the one
/// setup of `appell run`, runScene and Python's Simulation. The scene must
/// outlive it.
std::unique_ptr<Simulator> makeSimulator(const Scene& scene, const RunOptions& options);

/// Runs the scene (see the top of this file). `on_sample` sees the sampled
/// states (t = 0, every output_every-th step, the end); `on_step` every
/// accepted step (e.g. for a progress bar). Throws std::invalid_argument for
/// bad options; a failing step is not an exception but RunSummary::failure.
RunSummary runScene(const Scene& scene, const RunOptions& options,
                    const RunObserver& on_sample = {}, const RunObserver& on_step = {});

/// The same, writing the sampled states to `writer` (made for this scene).
RunSummary runScene(const Scene& scene, const RunOptions& options, TrajectoryWriter& writer,
                    const RunObserver& on_step = {});

}  // namespace appell
