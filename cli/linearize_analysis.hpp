// One linearization of a scene as `appell linearize` does it (its options
// --equilibrium, --cyclic, --family, --zero-tol, --fd-step, --formulation):
// shared by linearize, its --sweep and `appell sweep --analysis linearize`.
#pragma once

#include "args.hpp"

#include <appell/linearization.hpp>
#include <appell/scene.hpp>
#include <appell/constrained_dynamics.hpp>

#include <complex>
#include <string>
#include <vector>

namespace appell::cli {

/// A linearization and its verdict.
struct Analysis {
  bool ok = false;             ///< a verdict: the reference is an equilibrium / steady motion
  std::string message;         ///< why not, when !ok
  LinearizationResult result;
  std::vector<std::complex<double>> eigenvalues;  ///< largest real part first
  double tol = 0, max_real = 0;
  int zeros = 0;
  bool family = false;         ///< --family: the family's direction removed
  double family_residual = 0;  ///< |L z₀| / |L|, z₀ the family's direction
  /// The threshold of growth: the zero tolerance, or 0 once a family's own
  /// null direction is removed (its boundaries are where a real part crosses 0).
  double growthThreshold() const { return family ? 0.0 : tol; }
  bool unstable() const { return max_real > growthThreshold(); }
};

/// The eigenvalues of the quotient by a family of steady motions along v.
std::vector<std::complex<double>> familyQuotient(const LinearizationResult& r, const VecX& v, double& residual);

/// One linearization of `scene` as the options in `args` say; `print` says
/// what an --equilibrium search found.
Analysis analyse(const Scene& scene, const Args& args, const std::vector<int>& cyclic, Formulation form,
                 bool print);

/// --cyclic's names as coordinate indices, --formulation (or the scene's).
std::vector<int> cyclicCoordinates(const Scene& scene, const Args& args);
Formulation linearizeFormulation(const Scene& scene, const Args& args);

/// "unstable", "not growing" or "none" (no verdict), as JSON and the sweeps print it.
const char* verdict(const Analysis& a);

}  // namespace appell::cli
