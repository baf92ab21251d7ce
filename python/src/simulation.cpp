#include "simulation.hpp"

#include "arguments.hpp"

#include <appell/run.hpp>
#include <appell/run_loop.hpp>

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

// The scene's simulator is run/'s makeSimulator, the one setup of `appell
// run` too; what differs is only what Python has no duration for (h_max, an
// explicit option) and the options Python exposes beyond the CLI's.
Simulation::Simulation(std::shared_ptr<const Scene> scene, const SimulationOptions& options)
    : scene_(std::move(scene)), options_(options), watch_(options.max_energy_error) {
  if (!(options.max_energy_error > 0))
    throw std::invalid_argument("max_energy_error must be > 0 (or inf: no watch)");
  if (!scene_) throw std::invalid_argument("Simulation: no scene");
  const Scene& s = *scene_;
  const SimulationSettings& set = s.settings;
  RunOptions run;
  run.integrator =
      integratorFromString(options.integrator.empty() ? set.integrator : options.integrator);
  run.formulation =
      formulationFromString(options.formulation.empty() ? set.formulation : options.formulation);
  // The scene's settings are Python attributes too: checked here by name.
  dt_ = options.dt ? positiveArgument(options.dt, 0, "dt") : positiveArgument(set.dt, 0, "scene.settings.dt");
  run.dt = dt_;
  // Validated (by name) where the Simulator builds its integrator.
  run.tol = options.rtol ? positiveArgument(options.rtol, 0, "rtol")
                         : positiveArgument(set.tol, 0, "scene.settings.tol");
  run.atol = positiveArgument(options.atol, run.tol * 1e-2, "atol");
  run.h_min = options.h_min;
  run.h_max = options.h_max;
  run.project_positions = options.project_positions;
  run.project_velocities = options.project_velocities;
  run.contact_events = options.contact_events;
  run.settle_time = options.settle_time;
  run.contacts = contactSchemeFromString(options.contacts.empty() ? set.contacts : options.contacts);
  sim_ = makeSimulator(s, run);  // its state set to (0, q0, v0)
  data_ = std::make_unique<Data>(s.model);
  cdata_ = std::make_unique<ConstraintData>(s.model, s.constraints, DenseRows::None);
  watch_.start(*sim_);
  collectEvents();
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

bool Simulation::watchRejects(double t, const VecX& q, const VecX& v, std::string& why) {
  if (!watch_.enabled() || watch_.check(*sim_)) return false;
  std::ostringstream os;
  os << "the work balance (E + losses − work in − E0) is off by " << watch_.deviation() << " J, "
     << watch_.relative() << " of the energy that moved, after the step to t = " << sim_->time()
     << " s (bound " << watch_.bound() << "): the integration is diverging — use a smaller step or "
     << "tolerance; the state is back at t = " << t << " s";
  why = os.str();
  setState(t, q, v);  // the last state within the bound (the watch restarts there)
  return true;
}

StepStatus Simulation::watchedStep(double h) {
  if (!watch_.enabled()) return sim_->step(h);
  const double t = sim_->time();
  const VecX q = sim_->q(), v = sim_->v();
  StepStatus st = sim_->step(h);
  if (st.ok && watchRejects(t, q, v, st.message)) st.ok = false;
  return st;
}

StepStatus Simulation::step(std::optional<double> h) {
  const double step_size = positiveArgument(h, dt_, "step: h");
  events_.clear();
  const StepStatus st = watchedStep(step_size);
  collectEvents();
  return st;
}

// Python's view of the one loop (appell/run_loop.hpp): the divergence watch
// undoes a step past its bound, every step's events are kept, the rows go
// into the recording.
class Simulation::LoopObserver final : public StepObserver {
 public:
  LoopObserver(Simulation& s, Recording* record)
      : s_(s), record_(record), t_good_(s.sim_->time()), q_good_(s.sim_->q()), v_good_(s.sim_->v()) {}
  bool check(Simulator& sim, const StepStatus&) override {
    if (s_.watchRejects(t_good_, q_good_, v_good_, why_)) return false;
    if (s_.watch_.enabled()) {  // the state to go back to (sized once)
      t_good_ = sim.time();
      q_good_ = sim.q();
      v_good_ = sim.v();
    }
    return true;
  }
  void events(const Simulator&) override { s_.collectEvents(); }
  void row(const Simulator& sim) override {
    if (record_) record_->sample(sim);
  }
  const std::string& why() const { return why_; }

 private:
  Simulation& s_;
  Recording* record_;
  double t_good_;
  VecX q_good_, v_good_;
  std::string why_;
};

StepStatus Simulation::advanceTo(double t_end, std::optional<double> step_size, Recording* record,
                                 int every) {
  const double h = positiveArgument(step_size, dt_, "advance_to: h");
  if (!std::isfinite(t_end)) throw std::invalid_argument("advance_to: t_end must be finite");
  if (every < 1) throw std::invalid_argument("advance_to: every must be at least 1");
  events_.clear();
  LoopObserver observer(*this, record);
  LoopSpec spec;  // Simulator::advanceTo's steps, the adaptive ones from h each call
  spec.t_end = t_end;
  spec.h = h;
  spec.row_every = every;
  const LoopResult r = runLoop(*sim_, spec, &observer);
  StepStatus st = r.status;
  if (r.end == LoopEnd::Observer) {
    st.ok = false;
    st.message = observer.why();
  }
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
