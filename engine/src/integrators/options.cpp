// Validation of IntegratorOptions: every tolerance and step bound finite and
// positive, h_min ≤ h_max, the safety factor in (0, 1]. makeIntegrator calls
// it, so every integrator (and every Simulator) starts from options that
// cannot make a step controller loop: with rtol = NaN the error norm is NaN,
// no step is ever accepted and h shrinks to NaN, which no `h < h_min`
// comparison catches.
#include <appell/integrators.hpp>

#include "integrators/option_checks.hpp"

namespace appell {

void validateOptions(const IntegratorOptions& o) {
  constexpr const char* kOwner = "IntegratorOptions";
  detail::requirePositive(kOwner, "rtol", o.rtol);
  detail::requirePositive(kOwner, "atol", o.atol);
  detail::requirePositive(kOwner, "h_min", o.h_min);
  detail::requirePositive(kOwner, "h_max", o.h_max);
  if (o.h_min > o.h_max) {
    std::ostringstream os;
    os << kOwner << ": h_min must not exceed h_max (got h_min = " << o.h_min << ", h_max = " << o.h_max
       << ")";
    throw std::invalid_argument(os.str());
  }
  detail::requirePositive(kOwner, "safety", o.safety);
  if (o.safety > 1) detail::badOption(kOwner, "safety", "in (0, 1]", o.safety);
  detail::requirePositive(kOwner, "implicit_tol", o.implicit_tol);
  detail::requireAtLeast(kOwner, "implicit_max_iterations", o.implicit_max_iterations, 1);
}

}  // namespace appell
