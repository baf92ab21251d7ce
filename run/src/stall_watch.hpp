// The run loop's stall watchdog (RunOptions::watchdog_fraction): over every
// stretch of `interval` seconds of the run's CPU time (the calling thread's:
// a machine busy with other work does not count against the run, and
// parallel sweeps each keep their own) the simulated time must advance
// by at least `fraction` of it. A run that does not — steps collapsing at a
// contact that cannot decide its mode, thousands of events per simulated
// millisecond — is stopped with a report that names what it was doing: the
// contacts that changed mode in that stretch, the events per simulated
// second and the last mode changes. It only stops runs: the automatic
// scheme's switch to time-stepping is decided inside the simulator by
// counts of its own work (TimeSteppingOptions::stall_work), so that a
// trajectory does not depend on the machine's load.
#pragma once

#include <appell/run.hpp>

#include <string>

namespace appell::run_detail {

class StallWatch {
 public:
  StallWatch(double fraction, double interval, double t0, std::size_t events0);
  /// After a step at simulated time t with `events` events logged so far:
  /// true when the stretch that just ended advanced too little (then
  /// report() describes it). Starts a new stretch at each check.
  bool stalled(double t, std::size_t events);
  /// "the run advanced … s of simulated time in … s of CPU time (…); N
  /// events per simulated second; contacts changing mode: …; last mode
  /// changes: …" from the summary's events of the stretch.
  std::string report(const RunSummary& s) const;

 private:
  static double cpuSeconds();  ///< this thread's CPU time
  double fraction_, interval_;
  double start_;
  double t_start_, sim_span_ = 0, cpu_span_ = 0;
  std::size_t events_start_, events_span_begin_ = 0;
};

}  // namespace appell::run_detail
