// The sweep engine (sweep_engine.hpp): axes parsed, cases generated, cases
// run on a pool of threads.
#include "sweep_engine.hpp"

#include "args.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <numbers>
#include <random>
#include <sstream>
#include <thread>

namespace appell::cli {

namespace {

double number(const std::string& where, const std::string& what, const std::string& text) {
  std::size_t used = 0;
  double x = 0;
  try {
    x = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || !std::isfinite(x))
    throw UsageError(where + ": " + what + " '" + text + "' is not a finite number");
  return x;
}

std::vector<std::string> split(const std::string& text, char sep) {
  std::vector<std::string> parts;
  std::stringstream in(text);
  for (std::string p; std::getline(in, p, sep);) parts.push_back(p);
  if (!text.empty() && text.back() == sep) parts.push_back("");
  return parts;
}

// uniform(LOW,HIGH) or normal(MEAN,SD): the law and its two numbers.
SweepAxis parseLaw(const std::string& where, SweepAxis axis, const std::string& spec) {
  const auto open = spec.find('(');
  const std::string law = spec.substr(0, open);
  if (spec.back() != ')') throw UsageError(where + ": " + law + "(…) is missing its ')'");
  const std::vector<std::string> args = split(spec.substr(open + 1, spec.size() - open - 2), ',');
  if (law != "uniform" && law != "normal")
    throw UsageError(where + ": unknown law '" + law + "' (uniform(LOW,HIGH) or normal(MEAN,SD))");
  const bool uniform = law == "uniform";
  if (args.size() != 2)
    throw UsageError(where + ": " + law + (uniform ? " takes LOW,HIGH" : " takes MEAN,SD") + ", got " +
                     std::to_string(args.size()) + " numbers");
  axis.law = uniform ? SweepAxis::Law::Uniform : SweepAxis::Law::Normal;
  axis.a = number(where, uniform ? "LOW" : "MEAN", args[0]);
  axis.b = number(where, uniform ? "HIGH" : "SD", args[1]);
  if (uniform && !(axis.b > axis.a))
    throw UsageError(where + ": empty range: HIGH must exceed LOW, got uniform(" + args[0] + "," + args[1] + ")");
  if (!uniform && !(axis.b > 0)) throw UsageError(where + ": SD must be positive, got " + args[1]);
  return axis;
}

}  // namespace

SweepAxis parseSweepAxis(const std::string& option, const std::string& spec) {
  const auto eq = spec.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == spec.size())
    throw UsageError(option + " expects NAME=START:STOP:COUNT" +
                     (option == "--sweep" ? std::string() : ", NAME=uniform(LOW,HIGH) or NAME=normal(MEAN,SD)") +
                     ", got '" + spec + "'");
  SweepAxis axis;
  axis.name = spec.substr(0, eq);
  const std::string where = option + " " + axis.name, rest = spec.substr(eq + 1);
  if (rest.find('(') != std::string::npos) return parseLaw(where, axis, rest);
  const std::vector<std::string> parts = split(rest, ':');
  if (parts.size() != 3) throw UsageError(where + ": expects START:STOP:COUNT, got '" + rest + "'");
  const double start = number(where, "START", parts[0]), stop = number(where, "STOP", parts[1]);
  const double count = number(where, "COUNT", parts[2]);
  if (!(count >= 1) || count != std::floor(count) || count > 100000)
    throw UsageError(where + ": COUNT must be a whole number from 1 to 100000, got " + parts[2]);
  const int n = static_cast<int>(count);
  if (n > 1 && start == stop)
    throw UsageError(where + ": empty range: START equals STOP, so the " + parts[2] +
                     " values would be one (give COUNT 1 for a single value)");
  for (int k = 0; k < n; ++k) axis.values.push_back(n == 1 ? start : start + (stop - start) * k / (n - 1));
  return axis;
}

std::vector<SweepCase> sweepCases(const std::vector<SweepAxis>& axes, long samples, std::uint64_t seed,
                                  long max_cases) {
  const bool random = std::any_of(axes.begin(), axes.end(), [](const SweepAxis& a) { return a.random(); });
  if (samples < 1) throw UsageError("--samples must be a whole number ≥ 1");
  if (!random && samples != 1)
    throw UsageError("--samples draws random values: give a --vary NAME=uniform(LOW,HIGH) or normal(MEAN,SD)");
  if (random && samples > max_cases) throw UsageError("--samples: more than " + std::to_string(max_cases) + " cases");
  long grid = 1;
  for (const SweepAxis& a : axes)
    if (!a.random()) {
      grid *= static_cast<long>(a.values.size());
      if (grid * samples > max_cases)
        throw UsageError("the sweep has more than " + std::to_string(max_cases) + " cases (the product of the "
                         "grid's counts" + std::string(random ? " times --samples" : "") + ")");
    }
  std::mt19937_64 engine(seed);
  auto uniform01 = [&] { return static_cast<double>(engine() >> 11) * 0x1.0p-53; };
  std::vector<SweepCase> cases;
  cases.reserve(static_cast<std::size_t>(grid * samples));
  for (long g = 0; g < grid; ++g) {
    SweepCase point(axes.size());
    long rest = g;  // mixed radix, the last grid axis fastest
    for (std::size_t i = axes.size(); i-- > 0;)
      if (!axes[i].random()) {
        const long n = static_cast<long>(axes[i].values.size());
        point[i] = axes[i].values[static_cast<std::size_t>(rest % n)];
        rest /= n;
      }
    for (long s = 0; s < samples; ++s) {
      for (std::size_t i = 0; i < axes.size(); ++i) {
        const SweepAxis& a = axes[i];
        if (a.law == SweepAxis::Law::Uniform) {
          point[i] = a.a + (a.b - a.a) * uniform01();
        } else if (a.law == SweepAxis::Law::Normal) {
          const double u1 = 1.0 - uniform01(), u2 = uniform01();  // u1 in (0, 1]: log finite
          point[i] = a.a + a.b * std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
        }
      }
      cases.push_back(point);
    }
  }
  return cases;
}

CaseOutcome forEachCase(std::size_t n, unsigned jobs, const std::function<void(std::size_t)>& run_case,
                        const std::atomic<bool>* stop) {
  CaseOutcome out{std::vector<std::string>(n), std::vector<char>(n, 0)};
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    while (!stop || !stop->load()) {
      const std::size_t k = next++;
      if (k >= n) return;
      out.started[k] = 1;
      try {
        run_case(k);
      } catch (const std::exception& e) {
        out.errors[k] = e.what();
        if (out.errors[k].empty()) out.errors[k] = "an exception without a message";
      }
    }
  };
  const unsigned threads = std::max(1u, std::min<unsigned>(jobs, static_cast<unsigned>(std::max<std::size_t>(n, 1))));
  if (threads == 1) {
    worker();  // -j1: on this thread, no pool
    return out;
  }
  std::vector<std::thread> pool;
  for (unsigned w = 0; w < threads; ++w) pool.emplace_back(worker);
  for (std::thread& t : pool) t.join();
  return out;
}

unsigned defaultJobs(std::size_t cases) {
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  return std::max(1u, std::min<unsigned>(cores, static_cast<unsigned>(std::max<std::size_t>(cases, 1))));
}

std::string exact(double x) {
  char buf[40];
  return std::string(buf, std::to_chars(buf, buf + sizeof buf, x).ptr);
}

}  // namespace appell::cli
