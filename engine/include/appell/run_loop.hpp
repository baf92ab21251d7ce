// The one stepping loop: a Simulator stepped to t_end through its public API,
// with an observer that sees every accepted step. Simulator::advanceTo,
// runScene (run/, hence `appell run`) and Python's Simulation.advance_to /
// record are this loop with different observers.
//
//   rows(start)
//   while t_end not reached:
//     status = sim.step(next step size)        failure: ends (LoopEnd::Failed)
//     observer.check(sim, status)              false: ends (LoopEnd::Observer)
//     observer.events(sim)                     when the step ended at events
//     observer.accepted(sim, status)           false: ends (LoopEnd::Observer)
//     observer.row(sim)                        every row_every-th step (and at events)
//     stop = observer.stopRequested(); observer.progress(sim)
//     stop: ends (LoopEnd::Stopped)
//   row(last state) unless the last state was a row
//
// Step sizes: fixed-step integrators take h; adaptive ones start from h (or a
// carried suggestion) and follow the integrator's StepStatus::h_next, except
// after a step shortened to land on t_end (that says nothing about the next
// one). How the end is reached is LoopSpec::finish (two rules, kept so that
// neither caller's trajectories change: they differ only in the last step).
// The loop allocates nothing; the observer's calls are virtual.
#pragma once

#include <appell/simulator.hpp>

namespace appell {

/// Sees a loop's accepted steps (run_loop.hpp's sequence). Every hook has a
/// default that does nothing (and continues).
class StepObserver {
 public:
  virtual ~StepObserver() = default;
  /// First, after each accepted step: watches that may reject the state it
  /// reached (a divergence, a drift). false ends the loop; the observer
  /// keeps why, and may set the simulator back to an earlier state.
  virtual bool check(Simulator& sim, const StepStatus& status);
  /// The step ended at contact events (sim.events(), non-empty).
  virtual void events(const Simulator& sim);
  /// Then: the step's bookkeeping (statistics, watchdogs). false ends the loop.
  virtual bool accepted(Simulator& sim, const StepStatus& status);
  /// A row of output: the state at the start, after every row_every-th
  /// accepted step (and each step with events, if LoopSpec::row_at_events),
  /// and the last state reached when that was not a row.
  virtual void row(const Simulator& sim);
  /// Polled after each accepted step's row: true ends the loop, cleanly
  /// (LoopEnd::Stopped) — a SIGINT flag, another thread's request.
  virtual bool stopRequested();
  /// Last, after each accepted step (a progress bar).
  virtual void progress(const Simulator& sim);
};

struct LoopSpec {
  double t_end = 0;
  double h = 0;  ///< fixed step, or an adaptive integrator's first step (finite, > 0)
  /// An adaptive step size carried from an earlier loop (≤ 0: start from h).
  double h_suggest = 0;
  enum class Finish {
    /// Stop within ε = 1e-12·max(1, |t_end|) of t_end; a remainder below ε
    /// is absorbed into the last step (Simulator::advanceTo, Python).
    Absorb,
    /// Each step clipped at t_end; stop once t ≥ t_end·(1 − 1e-12), a
    /// relative bound (runScene; t_end > 0).
    Clip,
  };
  Finish finish = Finish::Absorb;
  int row_every = 1;          ///< a row after every N-th accepted step (N ≥ 1)
  bool row_at_events = false; ///< …and after every step that ended at events
};

enum class LoopEnd {
  Reached,   ///< t_end reached
  Failed,    ///< a step failed (status says why; the simulator kept the last good state)
  Observer,  ///< check() or accepted() returned false
  Stopped,   ///< stopRequested() returned true
};

struct LoopResult {
  LoopEnd end = LoopEnd::Reached;
  StepStatus status;   ///< of the last step taken (default: none was needed)
  long steps = 0;      ///< accepted steps
  /// The adaptive suggestion to carry into a next loop (LoopSpec::h_suggest);
  /// the given one for fixed-step integrators.
  double h_suggest = 0;
  /// The last step was aimed at t_end and took all of it: t equals t_end up
  /// to the round-off of t + (t_end − t).
  bool landed = false;
};

/// Steps `sim` to spec.t_end (the sequence at the top of this file). Throws
/// std::invalid_argument if h is not finite and positive, t_end not finite,
/// row_every below 1, or (Clip) t_end not positive.
LoopResult runLoop(Simulator& sim, const LoopSpec& spec, StepObserver* observer = nullptr);

namespace detail {
/// Simulator::advanceTo: the loop with the suggestion the simulator carries
/// between calls and its clock, set exactly to t_end when the loop landed.
StepStatus advanceCarrying(Simulator& sim, double t_end, double h, double& h_suggest,
                           double& clock);
}  // namespace detail

}  // namespace appell
