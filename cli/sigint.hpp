// SIGINT as a request to stop: while a SigintGuard lives, Ctrl-C sets a flag
// (RunOptions::stop) instead of killing the process — a run stops after its
// current step, a sweep's runs stop and no new one starts — and what was
// finished is still printed; the exit status is then kInterrupted.
#pragma once

#include <atomic>
#include <csignal>

namespace appell::cli {

constexpr int kInterrupted = 130;  // 128 + SIGINT, as a shell reports it

inline std::atomic<bool> g_interrupted{false};

class SigintGuard {
 public:
  SigintGuard() : previous_(std::signal(SIGINT, [](int) { g_interrupted = true; })) { g_interrupted = false; }
  ~SigintGuard() { std::signal(SIGINT, previous_); }
  SigintGuard(const SigintGuard&) = delete;
  SigintGuard& operator=(const SigintGuard&) = delete;
  const std::atomic<bool>& flag() const { return g_interrupted; }

 private:
  void (*previous_)(int);
};

}  // namespace appell::cli
