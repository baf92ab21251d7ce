// Checks of the numbers Python hands the module, each error naming the
// argument: a step, a tolerance or a vector that is NaN, infinite, of the
// wrong sign or size is a ValueError (std::invalid_argument) where it is
// passed, never a silent fallback to a default or a NaN inside a step.
#pragma once

#include <appell/spatial.hpp>

#include <optional>

namespace appell::python {

/// None → `fallback`; otherwise the value, which must be finite and > 0.
double positiveArgument(std::optional<double> value, double fallback, const char* what);
/// x must have n entries, all finite (the error names the first that is not).
void checkVector(const VecX& x, Eigen::Index n, const char* what);

}  // namespace appell::python
