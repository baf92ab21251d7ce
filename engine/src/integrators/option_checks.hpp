// Checks shared by the validation of the integrator's and the simulator's
// options (options.cpp files): each names the option and the value it got,
// so that a NaN or a negative tolerance is refused where it is set rather
// than found later as a step loop that never ends.
#pragma once

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace appell::detail {

/// Throws std::invalid_argument "<owner>: <name> must be <rule> (got <value>)".
[[noreturn]] inline void badOption(const char* owner, const char* name, const char* rule, double value) {
  std::ostringstream os;
  os << owner << ": " << name << " must be " << rule << " (got " << value << ")";
  throw std::invalid_argument(os.str());
}

inline void requirePositive(const char* owner, const char* name, double value) {
  if (!(value > 0) || !std::isfinite(value)) badOption(owner, name, "finite and > 0", value);
}

inline void requireNonNegative(const char* owner, const char* name, double value) {
  if (!(value >= 0) || !std::isfinite(value)) badOption(owner, name, "finite and >= 0", value);
}

inline void requireAtLeast(const char* owner, const char* name, int value, int least) {
  if (value < least) {
    std::ostringstream rule;
    rule << "at least " << least;
    badOption(owner, name, rule.str().c_str(), value);
  }
}

}  // namespace appell::detail
