// The one sweep engine of the command line (appell sweep, run --sweep,
// linearize --sweep): the cases of a sweep — a grid of values (the product
// over several names, the last varying fastest) or seeded random draws —
// and a pool of threads that runs them, each case independent of the others
// and its result stored at its own index, so the rows come out in case order
// and with the same numbers whatever the number of threads.
//
// Random draws are reproducible across machines and compilers: a 64-bit
// Mersenne Twister (std::mt19937_64, whose sequence the C++ standard fixes)
// seeded with --seed, turned into uniform numbers by its top 53 bits
// (k · 2⁻⁵³, as the 53-bit generators of Matsumoto & Nishimura, 1998) and
// into normal ones by the Box–Muller transform (Box & Muller, 1958, "A note
// on the generation of random normal deviates") — not by the standard
// library's distributions, whose algorithms each implementation chooses.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace appell::cli {

/// How one name of a sweep varies.
struct SweepAxis {
  enum class Law { Grid, Uniform, Normal };
  std::string name;             ///< an override name (appell/overrides.hpp)
  Law law = Law::Grid;
  std::vector<double> values;   ///< Grid: COUNT values from START to STOP
  double a = 0, b = 0;          ///< Uniform: [a, b); Normal: mean a, standard deviation b
  bool random() const { return law != Law::Grid; }
};

/// Parses NAME=START:STOP:COUNT, NAME=uniform(LOW,HIGH) or
/// NAME=normal(MEAN,SD); `option` ("--vary", "--sweep") names the argument
/// in the errors, which say what is wrong with which part.
SweepAxis parseSweepAxis(const std::string& option, const std::string& spec);

/// One case: a value per axis, in the axes' order.
using SweepCase = std::vector<double>;

/// The cases of `axes`: every combination of the grid axes (the last
/// fastest), and for each `samples` draws of the random axes (one stream
/// from `seed`, drawn case by case and axis by axis). Without random axes
/// `samples` must be 1. Throws UsageError past `max_cases`.
std::vector<SweepCase> sweepCases(const std::vector<SweepAxis>& axes, long samples, std::uint64_t seed,
                                  long max_cases = 1000000);

/// Runs case(k) for k = 0 … n−1 on `jobs` threads (each takes the next case
/// not yet started, so a slow case does not hold up a fixed share), and
/// stops starting new ones once `stop` is set. An exception a case throws is
/// its error message (errors[k]), never the end of the sweep; started[k]
/// says whether case k ran.
struct CaseOutcome {
  std::vector<std::string> errors;
  std::vector<char> started;
};
CaseOutcome forEachCase(std::size_t n, unsigned jobs, const std::function<void(std::size_t)>& run_case,
                        const std::atomic<bool>* stop = nullptr);

/// The default number of threads: the cores, at most one per case.
unsigned defaultJobs(std::size_t cases);

/// The shortest text that reads back as the same double (std::to_chars):
/// the sweep tables' numbers, exact.
std::string exact(double x);

}  // namespace appell::cli
