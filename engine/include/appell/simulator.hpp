// The simulation loop: integrate the constrained dynamics, then remove the drift.
//
//   step(h):  integrate (v̇ = solver(t, q, v, τ(t, q, v)) by the integrator)
//             → watch (pieces of terrains, contact points that jumped)
//             → project (Newton on the holonomic gaps, then velocities, M metric)
//             → evaluate the end state (λ, contact frames, energy, residuals)
//             → watch the unilateral constraints: if an open one crossed its
//               gap or a closed one's λ would pull, locate the first such
//               event by root finding, shorten the step to it and resolve the
//               contact modes there (impact, contact forces, friction).
// The stages and their state live behind Simulator::Impl
// (engine/src/simulator/, docs/architecture.md). A step that fails (solver
// error, non-finite joint forces or state, step size below h_min,
// projection failure) returns a status with the reason and leaves the last
// good state untouched. Everything is allocated at construction: step()
// performs no heap allocation on success (given constraints and a
// joint-force callback that do not allocate).
#pragma once

#include <appell/actuators.hpp>
#include <appell/integrators.hpp>
#include <appell/simulator_options.hpp>

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace appell {

struct ContactProblemData;  // contact_problem.hpp

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
  const std::string& lastStateError() const;
  /// Projects the current state onto the constraints (e.g. initial conditions).
  StepStatus projectState();
  void setJointForces(JointForces tau);
  /// Servos (actuators.hpp) whose forces add to setJointForces' (throws
  /// std::invalid_argument naming an invalid one). Between events they are
  /// joint forces like any other; a Moreau–Jean step takes them implicitly,
  /// at the step's end and within their effort limits, so a stiff servo on a
  /// light link does not destabilize a 1 ms step (docs/contacts.md §10).
  void setActuators(std::vector<Actuator> actuators);

  /// One step of size h (the first attempt, for adaptive integrators).
  StepStatus step(double h);
  /// Steps until t_end: fixed-step integrators with steps of h (the last one
  /// shortened), adaptive ones starting from h and then following their own
  /// suggestion. Stops at the first failure and returns it.
  StepStatus advanceTo(double t_end, double h);

  // State.
  double time() const;
  const VecX& q() const;
  const VecX& v() const;

  // Reports of the current state (after the last step / setState).
  const ConstrainedResult& dynamics() const;   ///< v̇, λ, Aᵀλ, rank
  const VecX& lambda() const;
  const ContactFrame& contactFrame(int constraint) const;
  const ConstraintData& constraintData() const;
  double kineticEnergy() const;
  double potentialEnergy() const;
  double energy() const;
  double velocityResidual() const;  ///< ‖A v + b‖∞
  double gapResidual() const;       ///< max |g|
  int redundantRows() const;
  /// Coordinate-partition re-choices of an AppellSolver (0 for other solvers).
  int partitionChanges() const;
  const PositionProjectionResult& lastProjection() const;
  const VecX& lastImpulse() const;
  /// Contact events of the last step() / setState(), in time order (the
  /// buffer is reused: copy what you keep).
  const std::vector<ContactEvent>& events() const;
  /// Kinetic energy taken by the impacts since setState() (J, ≥ 0 up to
  /// round-off; an impact at setState() itself is not counted):
  /// E + impactEnergyLoss() is conserved by a passive scene.
  double impactEnergyLoss() const;
  /// Energy taken by sliding friction since setState() (J, ≥ 0): the power
  /// −vᵀQ_f of the friction forces Q_f the dynamics applied (μₖ λₙ |slip|
  /// per contact sliding along its slip), integrated over each step by the
  /// integrator's own stages and weights — to the method's order, like the
  /// state itself: E + impactEnergyLoss() + frictionWork() is conserved by a
  /// passive scene to the integration tolerance.
  double frictionWork() const;
  /// Work done on the system since setState() (J), by the same quadrature:
  /// by the joint forces (∫ τ·v dt) and by constraints that move in time
  /// (∫ −λᵀb dt: a turntable or a conveyor drives through its rows). The
  /// balance E + impactEnergyLoss() + frictionWork() − jointWork() −
  /// supportWork() = E(0) holds for every scene (impacts on moving supports
  /// are counted in impactEnergyLoss()).
  double jointWork() const;
  double supportWork() const;
  /// Energy the time-stepping scheme itself took since setState() (J, either
  /// sign): at θ = 1 a Moreau–Jean step ends at q + h v⁺, not at the
  /// trapezoidal position its work terms match, ½ m g² h² lower in a free
  /// fall (docs/contacts.md §10); 0 under the events. With it the balance above closes for a
  /// time-stepped scene too: E + impactEnergyLoss() + frictionWork() +
  /// schemeEnergyLoss() − jointWork() − supportWork() = E(0).
  double schemeEnergyLoss() const;
  /// Whether unilateral constraint `c` is closed now.
  bool isClosed(int constraint) const;
  const SimulatorCounters& counters() const;
  /// The scheme of the next step: Events or TimeStepping (docs/contacts.md §10).
  ContactScheme stepScheme() const;
  /// Under ContactScheme::Auto: opens a time-stepping window from the
  /// current state (a watchdog's switch), logged as a TimeStepping event at
  /// the next step. false when the scheme is not auto, no contact is
  /// unilateral, or a window is already open.
  bool openTimeSteppingWindow(const std::string& why);
  /// Why the last window opened (empty before the first).
  const std::string& windowReason() const;
  /// Copies the last step's contact problem into `out` (contact_problem.hpp);
  /// false when that step was not time-stepped or had no contact candidate.
  bool contactProblem(ContactProblemData& out) const;

  const Model& model() const;
  const ConstraintList& constraints() const;
  ConstrainedSolver& solver();
  Integrator& integrator();

 private:
  struct Impl;  // the stages and their state: engine/src/simulator/simulator_impl.hpp
  std::unique_ptr<Impl> impl_;
};

}  // namespace appell
