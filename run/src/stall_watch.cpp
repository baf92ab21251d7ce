// The stall watchdog (stall_watch.hpp).
#include "stall_watch.hpp"

#include <time.h>

#include <algorithm>
#include <set>
#include <sstream>

namespace appell::run_detail {

StallWatch::StallWatch(double fraction, double interval, double t0, std::size_t events0)
    : fraction_(fraction), interval_(interval), start_(cpuSeconds()), t_start_(t0),
      events_start_(events0) {}

double StallWatch::cpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

bool StallWatch::stalled(double t, std::size_t events) {
  if (!(fraction_ > 0) || !(interval_ > 0)) return false;
  const double now = cpuSeconds();
  const double cpu = now - start_;
  if (cpu < interval_) return false;
  sim_span_ = t - t_start_;
  cpu_span_ = cpu;
  events_span_begin_ = events_start_;
  start_ = now;
  t_start_ = t;
  events_start_ = events;
  return sim_span_ < fraction_ * cpu;
}

std::string StallWatch::report(const RunSummary& s) const {
  std::ostringstream out;
  out.precision(3);
  const std::size_t first = std::min(events_span_begin_, s.events.size());
  const std::size_t count = s.events.size() - first;
  out << "the run stalled: it advanced " << sim_span_ << " s of simulated time in " << cpu_span_
      << " s of CPU time (less than the watchdog's " << fraction_ << " of it) up to t = "
      << s.time << " s; " << (sim_span_ > 0 ? count / sim_span_ : 0.0)
      << " contact events per simulated second";
  std::set<std::string> names;
  for (std::size_t i = first; i < s.events.size(); ++i) names.insert(s.events[i].contact);
  if (!names.empty()) {
    out << "; contacts changing mode:";
    for (const std::string& n : names) out << " '" << n << "'";
  }
  if (count > 0) {
    out << "; last mode changes:";
    for (std::size_t i = s.events.size() - std::min<std::size_t>(count, 5); i < s.events.size(); ++i)
      out << " t = " << s.events[i].t << " '" << s.events[i].contact << "' "
          << toString(s.events[i].kind) << (i + 1 < s.events.size() ? "," : "");
  } else {
    out << "; no contact changed mode: the step size collapsed";
  }
  return out.str();
}

}  // namespace appell::run_detail
