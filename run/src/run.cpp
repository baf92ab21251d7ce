// The run loop and its summary (run.hpp).
#include <appell/divergence_watch.hpp>

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
  iopt.atol = options.tol * 1e-2;
  iopt.h_max = std::max(options.dt, options.duration / 20);
  SimulatorOptions sopt;
  sopt.project_positions = options.project_positions;
  sopt.project_velocities = options.project_velocities;
  sopt.contacts.settle_time = options.settle_time;
  sopt.scheme = options.contacts;
  auto sim = std::make_unique<Simulator>(
      scene.model, scene.constraints,
      makeSolver(options.formulation, scene.model, scene.constraints), options.integrator, iopt,
      sopt);
  if (auto forces = scene.jointForces()) sim->setJointForces(std::move(forces));
  sim->setState(0.0, scene.q0, scene.v0);  // after the forces: the t = 0 reactions include them
  return sim;
}

RunSummary runScene(const Scene& scene, const RunOptions& options, const RunObserver& on_sample,
                    const RunObserver& on_step) {
  const std::unique_ptr<Simulator> owned = makeSimulator(scene, options);
  Simulator& sim = *owned;
  RunSummary s;
  s.options = options;
  s.passive = passiveScene(scene);
  s.contacts = run_detail::contactStats(scene);
  run_detail::markHeldNormals(s.contacts, scene, sim);
  for (const Actuator& a : scene.actuators) s.actuators.push_back({a.name, 0, a.effort_limit, 0, -1, -1});
  DivergenceWatch energy_watch(options.max_energy_error);
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
  if (!sim.lastStateError().empty()) {
    s.ok = false;
    s.failure = sim.lastStateError() + forceMagnitudeCause(scene, sim);
    s.time = sim.time();
    s.counters = sim.counters();
    if (on_sample) on_sample(sim);
    return s;
  }
  auto record = [&](const Simulator& sm) {
    for (const ContactEvent& ev : sm.events()) {
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
  };
  record(sim);
  run_detail::RankMarginWatch margins(scene, options);  // rows independent only by a margin
  margins.sample(sim, true, s.near_dependency);
  if (on_sample) on_sample(sim);

  const auto wall0 = std::chrono::steady_clock::now();
  const bool adaptive = adaptiveIntegrator(options.integrator);
  double h = options.dt;
  long step = 0;
  bool last_sampled = true;
  // The last state within the divergence bound, to go back to (sized once).
  double t_good = sim.time();
  VecX q_good = sim.q(), v_good = sim.v();
  const bool watch = energy_watch.enabled();
  const bool watch_residual = std::isfinite(options.max_residual);
  run_detail::VertexWatch vertices(scene);  // boxes and meshes on terrain meshes
  bool restored = false;  // went back to the last good state (its loss counters restart)
  run_detail::StallWatch stall(options.watchdog_fraction, options.watchdog_interval, sim.time(),
                               s.events.size());
  while (sim.time() < options.duration * (1 - 1e-12)) {
    const StepStatus status = sim.step(std::min(h, options.duration - sim.time()));
    if (!status.ok) {
      s.ok = false;
      s.failure = status.message + forceMagnitudeCause(scene, sim) +
                  run_detail::stepStabilityCause(scene, sim, options);
      break;
    }
    const bool diverged = !energy_watch.check(sim);
    const double deviation = energy_watch.deviation();
    s.energy_scale = energy_watch.scale();
    std::string uncovered;
    const double residual = std::max(sim.velocityResidual(), sim.gapResidual());
    const bool drifted = watch_residual && !(residual <= options.max_residual);
    if (diverged || drifted || !vertices.check(sim, uncovered)) {
      std::ostringstream why;
      if (drifted) {
        why << "the constraint residual reached " << residual << " (|Av+b| "
            << sim.velocityResidual() << ", |gap| " << sim.gapResidual() << ") at t = " << sim.time()
            << " s, beyond the bound " << options.max_residual
            << (options.project_positions ? ": the constraints are no longer held"
                                          : ": the drift grows without projection — drop --no-projection");
      } else if (diverged) {
        // Diverging (an explicit method past its stability limit, a step too
        // long for a stiff moment): stop before the numbers blow up.
        why << (s.passive ? "the energy error of this passive scene reached "
                          : "the work balance of this driven scene (E + losses − work in − E0) is off by ")
            << deviation << " J, " << energy_watch.relative()
            << " of the energy that moved (kinetic, potential exchanged, work) at t = " << sim.time() << " s, beyond the bound "
            << options.max_energy_error
            << ": the integration is diverging — use a smaller step or tolerance, or dopri5";
      } else {
        why << "at t = " << sim.time() << " s: " << uncovered;
      }
      s.ok = false;
      s.failure = why.str() + run_detail::stepStabilityCause(scene, sim, options);
      const double impacts = sim.impactEnergyLoss(), friction = sim.frictionWork();
      const double joint = sim.jointWork(), support = sim.supportWork();
      sim.setState(t_good, q_good, v_good);  // (restarts the loss counters)
      s.impact_energy_loss = impacts;
      s.friction_work = friction;
      s.joint_work = joint;
      s.support_work = support;
      restored = true;
      break;
    }
    if (watch || watch_residual || vertices.active()) {
      t_good = sim.time();
      q_good = sim.q();
      v_good = sim.v();
    }
    ++step;
    if (adaptive) h = status.h_next;
    record(sim);
    margins.sample(sim, !sim.events().empty(), s.near_dependency);
    if (stall.stalled(sim.time(), s.events.size())) {
      s.time = sim.time();
      const std::string why = stall.report(s);
      // The automatic scheme takes over with time-stepping; otherwise stop.
      if (!sim.openTimeSteppingWindow(why)) {
        s.ok = false;
        s.failure = why;
        break;
      }
    }
    s.max_energy_deviation = std::max(s.max_energy_deviation, deviation);
    s.max_velocity_residual = std::max(s.max_velocity_residual, sim.velocityResidual());
    s.max_gap_residual = std::max(s.max_gap_residual, sim.gapResidual());
    s.max_redundant = std::max(s.max_redundant, sim.redundantRows());
    run_detail::sample(s.contacts, sim.time(), sim.lambda(), sim.constraintData());
    sampleActuators(s, scene, sim);
    ++s.samples;
    // A step that ends at an event is always a sample: each event is a row.
    const bool sampled = step % options.output_every == 0 || !sim.events().empty();
    if (on_sample && sampled) on_sample(sim);
    last_sampled = sampled;
    if (options.stop && options.stop->load()) {
      s.interrupted = true;
      if (on_step) on_step(sim);
      break;
    }
    if (on_step) on_step(sim);
  }
  s.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  // The last state reached is always sampled (the failure leaves the last good one).
  if (on_sample && !last_sampled) on_sample(sim);
  s.time = sim.time();
  if (!restored) {
    s.impact_energy_loss = sim.impactEnergyLoss();
    s.friction_work = sim.frictionWork();
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
