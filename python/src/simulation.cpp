#include "simulation.hpp"

#include "arguments.hpp"

#include <appell/constrained_dynamics.hpp>
#include <appell/kinematics.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace appell::python {

void Recording::sample(const Simulator& sim) {
  t.push_back(sim.time());
  q.push_back(sim.q());
  v.push_back(sim.v());
  lambda.push_back(sim.lambda());
  energy.push_back(sim.energy());
  velocity_residual.push_back(sim.velocityResidual());
  gap_residual.push_back(sim.gapResidual());
}

Simulation::Simulation(std::shared_ptr<const Scene> scene, const SimulationOptions& options)
    : scene_(std::move(scene)), options_(options), watch_(options.max_energy_error) {
  if (!(options.max_energy_error > 0))
    throw std::invalid_argument("max_energy_error must be > 0 (or inf: no watch)");
  if (!scene_) throw std::invalid_argument("Simulation: no scene");
  const Scene& s = *scene_;
  const SimulationSettings& set = s.settings;
  const IntegratorType integrator =
      integratorFromString(options.integrator.empty() ? set.integrator : options.integrator);
  const Formulation formulation =
      formulationFromString(options.formulation.empty() ? set.formulation : options.formulation);
  // The scene's settings are Python attributes too: checked here by name.
  dt_ = options.dt ? positiveArgument(options.dt, 0, "dt") : positiveArgument(set.dt, 0, "scene.settings.dt");
  IntegratorOptions io;  // validated (by name) where the Simulator builds its integrator
  io.rtol = options.rtol ? positiveArgument(options.rtol, 0, "rtol")
                         : positiveArgument(set.tol, 0, "scene.settings.tol");
  io.atol = positiveArgument(options.atol, io.rtol * 1e-2, "atol");
  io.h_min = options.h_min;
  io.h_max = options.h_max;
  SimulatorOptions so;
  so.project_positions = options.project_positions;
  so.project_velocities = options.project_velocities;
  so.contacts.enabled = options.contact_events;
  so.contacts.settle_time = options.settle_time;
  so.scheme = contactSchemeFromString(options.contacts.empty() ? set.contacts : options.contacts);
  sim_ = std::make_unique<Simulator>(s.model, s.constraints,
                                     makeSolver(formulation, s.model, s.constraints), integrator,
                                     io, so);
  // The scene's joint forces (<effort>, <actuator>), as makeSimulator sets them.
  if (auto forces = s.jointForces()) sim_->setJointForces(std::move(forces));
  data_ = std::make_unique<Data>(s.model);
  cdata_ = std::make_unique<ConstraintData>(s.model, s.constraints, DenseRows::None);
  setState(0.0, s.q0, s.v0);
}

bool Simulation::setState(double t, const VecX& q, const VecX& v) {
  const bool ok = sim_->setState(t, q, v);
  watch_.start(*sim_);
  events_.clear();
  collectEvents();
  return ok;
}

void Simulation::collectEvents() {
  for (const ContactEvent& e : sim_->events())
    events_.push_back({e, scene_->constraints[e.constraint]->name()});
}

StepStatus Simulation::watchedStep(double h) {
  if (!watch_.enabled()) return sim_->step(h);
  const double t = sim_->time();
  const VecX q = sim_->q(), v = sim_->v();
  StepStatus st = sim_->step(h);
  if (!st.ok || watch_.check(*sim_)) return st;
  std::ostringstream why;
  why << "the work balance (E + losses − work in − E0) is off by " << watch_.deviation() << " J, "
      << watch_.relative() << " of the energy that moved, after the step to t = " << sim_->time()
      << " s (bound " << watch_.bound() << "): the integration is diverging — use a smaller step or "
      << "tolerance; the state is back at t = " << t << " s";
  setState(t, q, v);  // the last state within the bound (the watch restarts there)
  st.ok = false;
  st.message = why.str();
  return st;
}

StepStatus Simulation::step(std::optional<double> h) {
  const double step_size = positiveArgument(h, dt_, "step: h");
  events_.clear();
  const StepStatus st = watchedStep(step_size);
  collectEvents();
  return st;
}

StepStatus Simulation::advanceTo(double t_end, std::optional<double> step_size, Recording* record,
                                 int every) {
  const double h = positiveArgument(step_size, dt_, "advance_to: h");
  if (!std::isfinite(t_end)) throw std::invalid_argument("advance_to: t_end must be finite");
  if (every < 1) throw std::invalid_argument("advance_to: every must be at least 1");
  events_.clear();
  if (record) record->sample(*sim_);
  // The loop of Simulator::advanceTo, one step() at a time so that every
  // step's events are kept and the states can be recorded.
  StepStatus st;
  const double eps = 1e-12 * std::max(1.0, std::abs(t_end));
  const bool adaptive = sim_->integrator().adaptive();
  double h_suggest = h;
  long n = 0;
  bool sampled_last = true;
  while (t_end - sim_->time() > eps) {
    const double remaining = t_end - sim_->time();
    const double want = adaptive ? h_suggest : h;
    const bool last = want >= remaining - eps;
    st = watchedStep(last ? remaining : want);
    if (!st.ok) break;
    collectEvents();
    if (adaptive && (!last || st.h_taken < remaining)) h_suggest = st.h_next;
    sampled_last = false;
    if (record && ++n % every == 0) {
      record->sample(*sim_);
      sampled_last = true;
    }
  }
  if (record && !sampled_last) record->sample(*sim_);
  return st;
}

void Simulation::rowResiduals(VecX& residual, VecX& gap) {
  const Scene& s = *scene_;
  const VecX& q = sim_->q();
  const VecX& v = sim_->v();
  evaluateConstraintRows(s.model, *data_, s.constraints, *cdata_, sim_->time(), q, v);
  velocityResiduals(*data_, s.constraints, *cdata_, v, residual);
  gap = cdata_->gap;
}

Eigen::Matrix4d Simulation::bodyPose(int body) {
  if (body < 0 || body >= scene_->model.nbodies)
    throw std::out_of_range("no body " + std::to_string(body) + " (the model has " +
                            std::to_string(scene_->model.nbodies) + ")");
  forwardKinematics(scene_->model, *data_, sim_->q());
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() = data_->oMi[body].R;
  T.topRightCorner<3, 1>() = data_->oMi[body].p;
  return T;
}

Simulation::Guard::Guard(const Simulation& s) : s_(s) {
  if (s_.busy_.exchange(true))
    throw std::runtime_error(
        "this Simulation is in use by another thread (step each Simulation on one thread)");
}

Simulation::Guard::~Guard() { s_.busy_.store(false); }

}  // namespace appell::python
