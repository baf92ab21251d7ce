// Checks of the numbers Python hands the module (arguments.hpp).
#include "arguments.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace appell::python {

double positiveArgument(std::optional<double> value, double fallback, const char* what) {
  if (!value) return fallback;
  if (!(*value > 0) || !std::isfinite(*value)) {
    std::ostringstream os;
    os << what << " must be finite and > 0 (got " << *value << ")";
    throw std::invalid_argument(os.str());
  }
  return *value;
}

void checkVector(const VecX& x, Eigen::Index n, const char* what) {
  if (x.size() != n)
    throw std::invalid_argument(std::string(what) + " must have size " + std::to_string(n) + ", not " +
                                std::to_string(x.size()));
  for (Eigen::Index i = 0; i < n; ++i)
    if (!std::isfinite(x[i])) {
      std::ostringstream os;
      os << what << "[" << i << "] is " << x[i] << ": every entry must be finite";
      throw std::invalid_argument(os.str());
    }
}

}  // namespace appell::python
