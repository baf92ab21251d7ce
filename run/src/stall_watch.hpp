// The run loop's stall watchdog (RunOptions::watchdog_fraction): over every
// stretch of `interval` seconds of wall time the simulated time must advance
// by at least `fraction` of it. A run that does not — steps collapsing at a
// contact that cannot decide its mode, thousands of events per simulated
// millisecond — is either switched to time-stepping (the automatic scheme)
// or stopped with a report that names what it was doing: the contacts that
// changed mode in that stretch, the events per simulated second and the last
// mode changes.
#pragma once

#include <appell/run.hpp>

#include <chrono>
#include <string>

namespace appell::run_detail {

class StallWatch {
 public:
  StallWatch(double fraction, double interval, double t0, std::size_t events0);
  /// After a step at simulated time t with `events` events logged so far:
  /// true when the stretch that just ended advanced too little (then
  /// report() describes it). Starts a new stretch at each check.
  bool stalled(double t, std::size_t events);
  /// "the run advanced … s of simulated time in … s of wall time (…); N
  /// events per simulated second; contacts changing mode: …; last mode
  /// changes: …" from the summary's events of the stretch.
  std::string report(const RunSummary& s) const;

 private:
  using Clock = std::chrono::steady_clock;
  double fraction_, interval_;
  Clock::time_point start_;
  double t_start_, sim_span_ = 0, wall_span_ = 0;
  std::size_t events_start_, events_span_begin_ = 0;
};

}  // namespace appell::run_detail
