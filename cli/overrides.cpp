// --set and --sweep (overrides.hpp): text to numbers, usage errors.
#include "overrides.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace appell::cli {

namespace {

std::vector<double> numbersOf(const std::string& name, const std::string& text) {
  std::vector<double> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    std::size_t used = 0;
    double x = 0;
    try {
      x = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    // μ may be ∞ (no friction limit); everything else is finite.
    const bool mu_inf = std::isinf(x) && x > 0 && name.size() > 3 && name.compare(name.size() - 3, 3, ".mu") == 0;
    if (used == 0 || used != item.size() || (!std::isfinite(x) && !mu_inf))
      throw UsageError("--set " + name + ": '" + item + "' is not a finite number");
    out.push_back(x);
  }
  if (out.empty()) throw UsageError("--set " + name + ": no value");
  return out;
}

}  // namespace

void applyOverride(Scene& scene, const std::string& name, const std::string& value, OverrideReport& report) {
  try {
    appell::applyOverride(scene, name, numbersOf(name, value), report);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--set ") + e.what());
  }
}

void completeSetVelocities(Scene& scene, OverrideReport& report) {
  try {
    appell::completeVelocities(scene, report);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--set: ") + e.what());
  }
}

OverrideReport applyOverrides(Scene& scene, const Args& args) {
  OverrideReport report;
  for (const std::string& s : args.all("set")) {
    const auto eq = s.find('=');
    if (eq == std::string::npos || eq == 0) throw UsageError("--set expects NAME=VALUE, got '" + s + "'");
    applyOverride(scene, s.substr(0, eq), s.substr(eq + 1), report);
  }
  completeSetVelocities(scene, report);
  return report;
}

}  // namespace appell::cli
