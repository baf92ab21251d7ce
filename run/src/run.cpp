// The run loop and its summary (run.hpp).
#include <appell/divergence_watch.hpp>
#include <appell/run_loop.hpp>

#include "contact_stats.hpp"
#include "rank_margin.hpp"
#include "stall_watch.hpp"
#include "step_stability.hpp"
#include "vertex_watch.hpp"

#include <appell/contacts.hpp>
#include <appell/terrain.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace appell {

namespace {

void check(const RunOptions& o) {
  auto positive = [](const char* what, double x) {
    if (!(x > 0) || !std::isfinite(x))
      throw std::invalid_argument(std::string("run: ") + what + " must be positive and finite, got " +
                                  std::to_string(x));
  };
  positive("duration", o.duration);
  positive("dt", o.dt);
  positive("tol", o.tol);
  if (o.output_every < 1)
    throw std::invalid_argument("run: output_every must be at least 1, got " +
                                std::to_string(o.output_every));
}

// Energy is conserved when nothing drives the scene: no joint forces and no
// support that moves (a moving support does work through the reactions).
bool passiveScene(const Scene& scene) {
  if (scene.driven()) return false;
  for (const Support& s : scene.supports)
    if (isMoving(s.motion)) return false;
  return true;
}

// A failed step names its symptom (a step size too small, contact modes that
// cycle, constraints that disagree); when the joint forces dwarf the scene's
// weight that is the cause to name: forces of that size spin or fling the
// bodies faster than any step follows, and round-off in the reactions is
// larger than the weight itself.
std::string forceMagnitudeCause(const Scene& scene, const Simulator& sim) {
  const Simulator::JointForces forces = scene.jointForces();
  if (!forces) return "";
  VecX tau = VecX::Zero(scene.model.nv);
  forces(sim.time(), sim.q(), sim.v(), tau);
  int at = 0;
  const double largest = tau.cwiseAbs().maxCoeff(&at);
  const double weight = scene.model.totalMass() * scene.model.gravity.norm();
  const double scale = std::max(weight, 1.0);
  if (!(largest > 1e4 * scale)) return "";
  std::string joint;
  for (int j = 0; j < scene.model.nbodies; ++j) {
    const Joint& jt = scene.model.joints[j];
    if (at >= jt.idx_v && at < jt.idx_v + jt.nv) joint = scene.model.joint_names[j];
  }
  std::ostringstream s;
  s.precision(3);
  s << "; the likely cause: the joint force on '" << joint << "' is " << largest << " (N or N·m), "
    << largest / scale << " times the scene's weight of " << weight
    << " N — forces of that size move the bodies faster than a step can follow";
  return s.str();
}

void sampleActuators(RunSummary& s, const Scene& scene, const Simulator& sim) {
  for (std::size_t k = 0; k < scene.actuators.size(); ++k) {
    const Actuator& a = scene.actuators[k];
    const Joint& j = scene.model.joints[a.joint];
    const double demand = a.demand(sim.time(), sim.q()[j.idx_q], sim.v()[j.idx_v]);
    RunSummary::ActuatorStats& st = s.actuators[k];
    st.max_force = std::max(st.max_force, std::min(std::abs(demand), a.effort_limit));
    if (std::abs(demand) > a.effort_limit) {
      if (st.saturated++ == 0) st.first_saturated = sim.time();
      st.last_saturated = sim.time();
    }
  }
}

}  // namespace

bool anyContactCanSlip(const ConstraintList& constraints) {
  for (const auto& c : constraints) {
    if (!std::isfinite(c->friction())) continue;
    for (int k = 0; k < c->rows(); ++k)
      if (isTangential(c->rowKind(k))) return true;
  }
  return false;
}

int RunSummary::flaggedContacts() const {
  return static_cast<int>(
      std::count_if(contacts.begin(), contacts.end(), [](const ContactStats& c) { return c.flagged(); }));
}

RunOptions runOptions(const SimulationSettings& settings) {
  RunOptions o;
  o.duration = settings.duration;
  o.dt = settings.dt;
  o.tol = settings.tol;
  o.integrator = integratorFromString(settings.integrator);
  o.formulation = formulationFromString(settings.formulation);
  o.contacts = contactSchemeFromString(settings.contacts);
  check(o);
  return o;
}

std::unique_ptr<Simulator> makeSimulator(const Scene& scene, const RunOptions& options) {
  check(options);
  IntegratorOptions iopt;
  iopt.rtol = options.tol;
  iopt.atol = options.atol.value_or(options.tol * 1e-2);
  iopt.h_min = options.h_min;
  iopt.h_max = options.h_max.value_or(std::max(options.dt, options.duration / 20));
  SimulatorOptions sopt;
  sopt.project_positions = options.project_positions;
  sopt.project_velocities = options.project_velocities;
  sopt.contacts.enabled = options.contact_events;
  sopt.contacts.settle_time = options.settle_time;
  sopt.scheme = options.contacts;
  auto sim = std::make_unique<Simulator>(
      scene.model, scene.constraints,
      makeSolver(options.formulation, scene.model, scene.constraints), options.integrator, iopt,
      sopt);
  if (auto forces = scene.constantJointForces()) sim->setJointForces(std::move(forces));
  if (!scene.actuators.empty()) sim->setActuators(scene.actuators);
  sim->setState(0.0, scene.q0, scene.v0);  // after the forces: the t = 0 reactions include them
  return sim;
}

namespace {

// Each event of the simulator's last step, named, into the summary.
void recordEvents(RunSummary& s, const Scene& scene, const Simulator& sim) {
  for (const ContactEvent& ev : sim.events()) {
    RunEvent r;
    r.t = ev.t;
    r.contact = scene.constraints[ev.constraint]->name();
    r.kind = ev.kind;
    r.speed_before = ev.speed_before;
    r.speed_after = ev.speed_after;
    r.normal_impulse = ev.normal_impulse;
    r.tangential_impulse = ev.tangential_impulse;
    r.outside_friction_cone =
        ev.tangential_impulse > s.contacts[ev.constraint].mu * ev.normal_impulse * (1 + 1e-9);
    const auto* c = dynamic_cast<const ShapeContact*>(scene.constraints[ev.constraint].get());
    if (ev.kind == ContactEventKind::Feature && c)
      if (const auto* mesh = std::get_if<TerrainMesh>(&c->spec().support.surface))
        r.piece = terrainFeatureName(*mesh, ev.feature);
    s.events.push_back(std::move(r));
  }
}

// runScene's view of the loop (run_loop.hpp): the watches that stop a run
// (divergence, drift, uncovered vertices, a stall), the events named, the
// summary's maxima and per-contact statistics, the caller's observers.
class SummaryObserver final : public StepObserver {
 public:
  SummaryObserver(const Scene& scene, const RunOptions& options, RunSummary& s,
                  const Simulator& sim, DivergenceWatch& energy,
                  run_detail::RankMarginWatch& margins, const RunObserver& on_sample,
                  const RunObserver& on_step)
      : scene_(scene), options_(options), s_(s), energy_(energy), margins_(margins),
        on_sample_(on_sample), on_step_(on_step), t_good_(sim.time()), q_good_(sim.q()),
        v_good_(sim.v()), vertices_(scene),
        stall_(options.watchdog_fraction, options.watchdog_interval, sim.time(), s.events.size()) {}

  bool check(Simulator& sim, const StepStatus&) override;
  void events(const Simulator& sim) override { recordEvents(s_, scene_, sim); }
  bool accepted(Simulator& sim, const StepStatus&) override;
  void row(const Simulator& sim) override {
    if (on_sample_) on_sample_(sim);
  }
  bool stopRequested() override {
    if (!(options_.stop && options_.stop->load())) return false;
    s_.interrupted = true;
    return true;
  }
  void progress(const Simulator& sim) override {
    if (on_step_) on_step_(sim);
  }
  /// The divergence watch went back to the last good state.
  bool restored() const { return restored_; }

 private:
  const Scene& scene_;
  const RunOptions& options_;
  RunSummary& s_;
  DivergenceWatch& energy_;
  run_detail::RankMarginWatch& margins_;
  const RunObserver& on_sample_;
  const RunObserver& on_step_;
  // The last state within the watches' bounds, to go back to (sized once).
  double t_good_;
  VecX q_good_, v_good_;
  run_detail::VertexWatch vertices_;  // boxes and meshes on terrain meshes
  run_detail::StallWatch stall_;
  double deviation_ = 0;
  bool restored_ = false;  // went back to the last good state (its loss counters restart)
};


// The watches that reject a step's state: the work balance (diverging), the
// constraint residual (drift), vertices off the terrain. Rejected: the run
// fails, set back to the last good state.
bool SummaryObserver::check(Simulator& sim, const StepStatus&) {
  const bool diverged = !energy_.check(sim);
  deviation_ = energy_.deviation();
  s_.energy_scale = energy_.scale();
  std::string uncovered;
  const double residual = std::max(sim.velocityResidual(), sim.gapResidual());
  const bool drifted = std::isfinite(options_.max_residual) && !(residual <= options_.max_residual);
  if (diverged || drifted || !vertices_.check(sim, uncovered)) {
    std::ostringstream why;
    if (drifted) {
      why << "the constraint residual reached " << residual << " (|Av+b| "
          << sim.velocityResidual() << ", |gap| " << sim.gapResidual() << ") at t = " << sim.time()
          << " s, beyond the bound " << options_.max_residual
          << (options_.project_positions ? ": the constraints are no longer held"
                                         : ": the drift grows without projection — drop --no-projection");
    } else if (diverged) {
      // Diverging (an explicit method past its stability limit, a step too
      // long for a stiff moment): stop before the numbers blow up.
      why << (s_.passive ? "the energy error of this passive scene reached "
                         : "the work balance of this driven scene (E + losses − work in − E0) is off by ")
          << deviation_ << " J, " << energy_.relative()
          << " of the energy that moved (kinetic, potential exchanged, work) at t = " << sim.time() << " s, beyond the bound "
          << options_.max_energy_error
          << ": the integration is diverging — use a smaller step or tolerance, or dopri5";
    } else {
      why << "at t = " << sim.time() << " s: " << uncovered;
    }
    s_.ok = false;
    s_.failure = why.str() + run_detail::stepStabilityCause(scene_, sim, options_);
    s_.impact_energy_loss = sim.impactEnergyLoss();
    s_.friction_work = sim.frictionWork();
    s_.scheme_energy_loss = sim.schemeEnergyLoss();
    s_.joint_work = sim.jointWork();
    s_.support_work = sim.supportWork();
    sim.setState(t_good_, q_good_, v_good_);  // (restarts the loss counters)
    restored_ = true;
    return false;
  }
  if (energy_.enabled() || std::isfinite(options_.max_residual) || vertices_.active()) {
    t_good_ = sim.time();
    q_good_ = sim.q();
    v_good_ = sim.v();
  }
  return true;
}

// The step's bookkeeping: near-dependent rows, the stall watchdog (which
// stops a run that stalled on the wall clock: the switch to time-stepping is
// the simulator's own, decided by counts so that it does not depend on the
// machine's load), the summary's maxima.
bool SummaryObserver::accepted(Simulator& sim, const StepStatus&) {
  margins_.sample(sim, !sim.events().empty(), s_.near_dependency);
  if (stall_.stalled(sim.time(), s_.events.size())) {
    s_.time = sim.time();
    s_.ok = false;
    s_.failure = stall_.report(s_);
    return false;
  }
  s_.max_energy_deviation = std::max(s_.max_energy_deviation, deviation_);
  s_.max_velocity_residual = std::max(s_.max_velocity_residual, sim.velocityResidual());
  s_.max_gap_residual = std::max(s_.max_gap_residual, sim.gapResidual());
  s_.max_redundant = std::max(s_.max_redundant, sim.redundantRows());
  run_detail::sample(s_.contacts, sim.time(), sim.lambda(), sim.constraintData());
  sampleActuators(s_, scene_, sim);
  ++s_.samples;
  return true;
}

// The summary at t = 0, before the first step.
void startSummary(RunSummary& s, const Scene& scene, const RunOptions& options,
                  const Simulator& sim, DivergenceWatch& energy_watch) {
  s.options = options;
  s.passive = passiveScene(scene);
  s.contacts = run_detail::contactStats(scene);
  run_detail::markHeldNormals(s.contacts, scene, sim);
  for (const Actuator& a : scene.actuators) s.actuators.push_back({a.name, 0, a.effort_limit, 0, -1, -1});
  energy_watch.start(sim);
  s.energy0 = energy_watch.energy0();
  s.energy_scale = energy_watch.scale();
  s.max_velocity_residual = sim.velocityResidual();
  s.max_gap_residual = sim.gapResidual();
  s.max_redundant = sim.redundantRows();
  s.free_velocities =
      scene.model.nv - (sim.constraintData().m_active - sim.redundantRows());
  s.can_slip = anyContactCanSlip(scene.constraints);
  run_detail::sample(s.contacts, sim.time(), sim.lambda(), sim.constraintData());
  sampleActuators(s, scene, sim);
  s.samples = 1;
}

}  // namespace

RunSummary runScene(const Scene& scene, const RunOptions& options, const RunObserver& on_sample,
                    const RunObserver& on_step) {
  const std::unique_ptr<Simulator> owned = makeSimulator(scene, options);
  Simulator& sim = *owned;
  RunSummary s;
  DivergenceWatch energy_watch(options.max_energy_error);
  startSummary(s, scene, options, sim, energy_watch);
  if (!sim.lastStateError().empty()) {
    s.ok = false;
    s.failure = sim.lastStateError() + forceMagnitudeCause(scene, sim);
    s.time = sim.time();
    s.counters = sim.counters();
    if (on_sample) on_sample(sim);
    return s;
  }
  recordEvents(s, scene, sim);  // the modes decided at t = 0
  run_detail::RankMarginWatch margins(scene, options);  // rows independent only by a margin
  margins.sample(sim, true, s.near_dependency);
  SummaryObserver observer(scene, options, s, sim, energy_watch, margins, on_sample, on_step);

  LoopSpec spec;
  spec.t_end = options.duration;
  spec.h = options.dt;
  spec.finish = LoopSpec::Finish::Clip;
  spec.row_every = options.output_every;
  spec.row_at_events = true;  // a step that ends at an event is always a row
  const auto wall0 = std::chrono::steady_clock::now();
  const LoopResult loop = runLoop(sim, spec, &observer);
  s.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  if (loop.end == LoopEnd::Failed) {
    s.ok = false;
    s.failure = loop.status.message + forceMagnitudeCause(scene, sim) +
                run_detail::stepStabilityCause(scene, sim, options);
  }
  s.time = sim.time();
  if (!observer.restored()) {
    s.impact_energy_loss = sim.impactEnergyLoss();
    s.friction_work = sim.frictionWork();
    s.scheme_energy_loss = sim.schemeEnergyLoss();
    s.joint_work = sim.jointWork();
    s.support_work = sim.supportWork();
  }
  s.counters = sim.counters();
  s.partition_changes = sim.partitionChanges();
  return s;
}

RunSummary runScene(const Scene& scene, const RunOptions& options, TrajectoryWriter& writer,
                    const RunObserver& on_step) {
  std::vector<ContactFrame> frames(scene.constraints.size());
  std::vector<ContactState> states(scene.constraints.size());
  auto write = [&](const Simulator& sim) {
    for (std::size_t k = 0; k < frames.size(); ++k) {
      frames[k] = sim.contactFrame(static_cast<int>(k));
      states[k] = {sim.isClosed(static_cast<int>(k)), 0};
    }
    for (const ContactEvent& ev : sim.events())
      if (ev.t == sim.time()) states[ev.constraint].event = 1 + static_cast<int>(ev.kind);
    writer.write(sim.time(), sim.q(), sim.v(), sim.energy(),
                 std::max(sim.velocityResidual(), sim.gapResidual()), frames, sim.lambda(), states);
  };
  return runScene(scene, options, write, on_step);
}

}  // namespace appell
