// A scene's Simulator as the Python module sees it (plain C++, no pybind11):
// the Simulator keeps a reference to the scene's model, so the simulation owns
// a shared pointer to the scene; stepping loops collect the contact events of
// every step (Simulator::events() holds only the last step's) and can record
// the states they pass; row residuals, body poses and the busy flag that
// guards a simulation stepped on one thread from being used on another.
#pragma once

#include <appell/divergence_watch.hpp>
#include <appell/scene.hpp>
#include <appell/simulator.hpp>

#include <atomic>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace appell::python {

/// How to simulate a scene. Empty names and absent numbers mean "the scene's
/// own setting" (SimulationSettings of its <simulation> element); a number
/// given must be finite and positive (arguments.hpp), h_min ≤ h_max.
struct SimulationOptions {
  std::string integrator;          ///< a name of integratorTable()
  std::string formulation;         ///< a name of formulationTable()
  std::optional<double> dt;        ///< fixed step / first adaptive step
  std::optional<double> rtol;      ///< adaptive: relative tolerance (default: scene tol)
  std::optional<double> atol;      ///< adaptive: absolute tolerance (default: rtol / 100)
  double h_min = 1e-14;
  double h_max = 0.1;
  bool project_positions = true;
  bool project_velocities = true;
  bool contact_events = true;      ///< unilateral contacts may open (ContactEventOptions)
  double settle_time = ContactEventOptions{}.settle_time;  ///< ContactEventOptions::settle_time
  /// DivergenceWatch's bound (the run library's default); ∞ switches it off.
  double max_energy_error = 5e-2;
  std::string contacts;            ///< a name of contactSchemeTable() (empty: the scene's)
};

/// The states a stepping loop passed: one row per sample.
struct Recording {
  std::vector<double> t, energy, velocity_residual, gap_residual;
  std::vector<VecX> q, v, lambda;
  void sample(const Simulator& sim);
};

/// A contact event with its constraint's name.
struct NamedEvent {
  ContactEvent event;
  std::string constraint_name;
};

class Simulation {
 public:
  /// Throws std::invalid_argument for unknown names or bad numbers (as the
  /// C++ API does). The state starts at (0, scene.q0, scene.v0).
  Simulation(std::shared_ptr<const Scene> scene, const SimulationOptions& options);

  const Scene& scene() const { return *scene_; }
  const std::shared_ptr<const Scene>& scenePtr() const { return scene_; }
  Simulator& simulator() { return *sim_; }
  const Simulator& simulator() const { return *sim_; }
  double dt() const { return dt_; }
  const SimulationOptions& options() const { return options_; }

  /// Simulator::setState; returns its result (false: lastStateError()).
  bool setState(double t, const VecX& q, const VecX& v);
  /// One step of h (absent: dt()). Clears and refills events(). Throws
  /// std::invalid_argument for an h that is not finite and positive. A step
  /// after which the work balance is off by more than max_energy_error of the
  /// energy that moved (DivergenceWatch) is undone and reported as failed.
  StepStatus step(std::optional<double> h);
  /// Steps until t_end with the one loop (appell/run_loop.hpp, as
  /// Simulator::advanceTo: fixed steps of h, or the adaptive suggestion
  /// starting from h), collecting every step's events; when `record` is
  /// given, samples the start and every `every`-th step and the end.
  /// h absent: dt(); given, it must be finite and positive, and t_end finite.
  StepStatus advanceTo(double t_end, std::optional<double> h, Recording* record = nullptr,
                       int every = 1);
  /// Events of the last step() / advanceTo() / setState(), in time order.
  const std::vector<NamedEvent>& events() const { return events_; }

  /// A v + b of every row at the current state (open constraints included),
  /// and the holonomic gap of every row (0 where not holonomic).
  void rowResiduals(VecX& residual, VecX& gap);
  /// Pose of a body in the world: 4 × 4 homogeneous matrix.
  Eigen::Matrix4d bodyPose(int body);

  /// Marks the simulation in use for the lifetime of a Guard; a second
  /// guard (another thread) throws std::runtime_error instead of racing.
  class Guard {
   public:
    explicit Guard(const Simulation& s);
    ~Guard();
    Guard(const Guard&) = delete;
    Guard& operator=(const Guard&) = delete;

   private:
    const Simulation& s_;
  };

 private:
  class LoopObserver;
  void collectEvents();
  /// One step of the simulator, undone (and failed) if the watch says so.
  StepStatus watchedStep(double h);
  /// After a step: when the divergence watch rejects its state, sets the
  /// state back to (t, q, v) and says why.
  bool watchRejects(double t, const VecX& q, const VecX& v, std::string& why);

  std::shared_ptr<const Scene> scene_;
  SimulationOptions options_;
  double dt_ = 0;
  std::unique_ptr<Simulator> sim_;
  std::vector<NamedEvent> events_;
  DivergenceWatch watch_;
  // Own workspace for reports, so they never touch the simulator's.
  std::unique_ptr<Data> data_;
  std::unique_ptr<ConstraintData> cdata_;
  mutable std::atomic<bool> busy_{false};
};

}  // namespace appell::python
