// Simulator's public methods: each forwards to its Impl (simulator_impl.hpp),
// where the stages and their state live. The Impl is allocated here, once.
#include <appell/simulator.hpp>

#include "simulator/simulator_impl.hpp"
#include "timestepping/moreau_jean.hpp"

#include <appell/contact_problem.hpp>

#include <cmath>

namespace appell {

Simulator::Simulator(const Model& model, ConstraintList constraints,
                     std::unique_ptr<ConstrainedSolver> solver, IntegratorType integrator,
                     const IntegratorOptions& integrator_options, const SimulatorOptions& options)
    : impl_(std::make_unique<Impl>(model, std::move(constraints), std::move(solver), integrator,
                                   integrator_options, options)) {}

Simulator::~Simulator() = default;

bool Simulator::setState(double t, const VecX& q, const VecX& v) { return impl_->setState(t, q, v); }
StepStatus Simulator::projectState() { return impl_->projectState(); }
void Simulator::setJointForces(JointForces tau) { impl_->setJointForces(std::move(tau)); }
void Simulator::setActuators(std::vector<Actuator> actuators) {
  impl_->setActuators(std::move(actuators));
}
StepStatus Simulator::step(double h) { return impl_->step(h); }
bool Simulator::openTimeSteppingWindow(const std::string& why) {
  return impl_->openTimeSteppingWindow(why);
}

double Simulator::time() const { return impl_->t_; }
const VecX& Simulator::q() const { return impl_->q_; }
const VecX& Simulator::v() const { return impl_->v_; }
const std::string& Simulator::lastStateError() const { return impl_->state_error_; }

const ConstrainedResult& Simulator::dynamics() const { return impl_->result_; }
const VecX& Simulator::lambda() const { return impl_->result_.lambda; }
const ContactFrame& Simulator::contactFrame(int constraint) const {
  return impl_->contactFrame(constraint);
}
const ConstraintData& Simulator::constraintData() const { return *impl_->cdata_; }
double Simulator::kineticEnergy() const { return impl_->kinetic_; }
double Simulator::potentialEnergy() const { return impl_->potential_; }
double Simulator::energy() const { return impl_->kinetic_ + impl_->potential_; }
double Simulator::velocityResidual() const { return impl_->velocity_residual_; }
double Simulator::gapResidual() const { return impl_->gap_residual_; }
int Simulator::redundantRows() const { return impl_->result_.redundant; }
int Simulator::partitionChanges() const { return impl_->solver_->partitionChanges(); }
const PositionProjectionResult& Simulator::lastProjection() const { return impl_->projection_; }
const VecX& Simulator::lastImpulse() const { return impl_->impulse_; }
const std::vector<ContactEvent>& Simulator::events() const { return impl_->events_; }
double Simulator::impactEnergyLoss() const { return impl_->dissipated_; }
double Simulator::frictionWork() const { return impl_->work_[Impl::kFrictionWork]; }
double Simulator::schemeEnergyLoss() const { return impl_->scheme_loss_; }
double Simulator::jointWork() const { return impl_->work_[Impl::kJointWork]; }
double Simulator::supportWork() const { return impl_->work_[Impl::kSupportWork]; }
bool Simulator::isClosed(int constraint) const { return impl_->cdata_->isActive(constraint); }
const SimulatorCounters& Simulator::counters() const { return impl_->counters_; }
ContactScheme Simulator::stepScheme() const {
  return impl_->stepping_ ? ContactScheme::TimeStepping : ContactScheme::Events;
}
const std::string& Simulator::windowReason() const { return impl_->window_reason_; }
bool Simulator::contactProblem(ContactProblemData& out) const {
  if (std::isnan(impl_->ts_step_start_) || !impl_->mj_ || impl_->mj_->candidates() == 0) return false;
  impl_->mj_->record(out);
  out.t = impl_->ts_step_start_;
  return true;
}

const Model& Simulator::model() const { return impl_->model_; }
const ConstraintList& Simulator::constraints() const { return impl_->constraints_; }
ConstrainedSolver& Simulator::solver() { return *impl_->solver_; }
Integrator& Simulator::integrator() { return *impl_->integrator_; }

}  // namespace appell
