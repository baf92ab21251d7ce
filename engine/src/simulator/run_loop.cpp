// The one stepping loop (run_loop.hpp): step sizes, the end rule, and the
// observer's hooks in their order.
#include <appell/run_loop.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace appell {

bool StepObserver::check(Simulator&, const StepStatus&) { return true; }
void StepObserver::events(const Simulator&) {}
bool StepObserver::accepted(Simulator&, const StepStatus&) { return true; }
void StepObserver::row(const Simulator&) {}
bool StepObserver::stopRequested() { return false; }
void StepObserver::progress(const Simulator&) {}

namespace {

void checkSpec(const LoopSpec& spec) {
  if (!(spec.h > 0) || !std::isfinite(spec.h) || !std::isfinite(spec.t_end))
    throw std::invalid_argument("runLoop: h must be positive and finite, and t_end finite");
  if (spec.row_every < 1)
    throw std::invalid_argument("runLoop: row_every must be at least 1, got " +
                                std::to_string(spec.row_every));
  if (spec.finish == LoopSpec::Finish::Clip && !(spec.t_end > 0))
    throw std::invalid_argument("runLoop: a clipped finish needs t_end > 0");
}

// Whether t is short of t_end by more than the finish rule's tolerance.
bool shortOfEnd(const LoopSpec& spec, double t, double eps) {
  if (spec.finish == LoopSpec::Finish::Clip) return t < spec.t_end * (1 - 1e-12);
  return spec.t_end - t > eps;
}

// The hooks after an accepted step; false: the loop ends (`end` says how).
bool observeStep(StepObserver& o, Simulator& sim, const StepStatus& st, long steps,
                 const LoopSpec& spec, bool& row_taken, LoopEnd& end) {
  if (!o.check(sim, st)) {
    end = LoopEnd::Observer;
    return false;
  }
  const bool at_events = !sim.events().empty();
  if (at_events) o.events(sim);
  if (!o.accepted(sim, st)) {
    end = LoopEnd::Observer;
    return false;
  }
  row_taken = steps % spec.row_every == 0 || (spec.row_at_events && at_events);
  if (row_taken) o.row(sim);
  const bool stop = o.stopRequested();
  o.progress(sim);
  if (stop) end = LoopEnd::Stopped;
  return !stop;
}

}  // namespace

LoopResult runLoop(Simulator& sim, const LoopSpec& spec, StepObserver* observer) {
  checkSpec(spec);
  LoopResult r;
  const bool adaptive = sim.integrator().adaptive();
  double h_suggest = spec.h_suggest > 0 ? spec.h_suggest : spec.h;
  // Absorb: a remainder below eps goes into the last step rather than be left.
  const double eps = 1e-12 * std::max(1.0, std::abs(spec.t_end));
  const double absorb = spec.finish == LoopSpec::Finish::Absorb ? eps : 0.0;
  bool row_taken = true;
  if (observer) observer->row(sim);
  while (shortOfEnd(spec, sim.time(), eps)) {
    const double remaining = spec.t_end - sim.time();
    const double want = adaptive ? h_suggest : spec.h;
    const bool last = want >= remaining - absorb;
    r.status = sim.step(last ? remaining : want);
    if (!r.status.ok) {
      r.end = LoopEnd::Failed;
      break;
    }
    ++r.steps;
    r.landed = last && r.status.h_taken == remaining;
    // A step shortened to land on t_end says nothing about the next one.
    if (adaptive && (!last || r.status.h_taken < remaining)) h_suggest = r.status.h_next;
    if (observer && !observeStep(*observer, sim, r.status, r.steps, spec, row_taken, r.end)) break;
  }
  // The last state reached is always a row (after a failure: the last good one).
  if (observer && !row_taken) observer->row(sim);
  r.h_suggest = adaptive ? h_suggest : spec.h_suggest;
  return r;
}

namespace detail {

StepStatus advanceCarrying(Simulator& sim, double t_end, double h, double& h_suggest,
                           double& clock) {
  if (!(h > 0) || !std::isfinite(h) || !std::isfinite(t_end))
    throw std::invalid_argument("Simulator::advanceTo: h must be positive and t_end finite");
  LoopSpec spec;
  spec.t_end = t_end;
  spec.h = h;
  spec.h_suggest = h_suggest;
  const LoopResult r = runLoop(sim, spec);
  h_suggest = r.h_suggest;
  // Land exactly on t_end (t + (t_end − t) may differ from t_end by an ulp).
  if (r.landed && r.end == LoopEnd::Reached) clock = t_end;
  return r.status;
}

}  // namespace detail

}  // namespace appell
