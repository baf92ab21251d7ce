// The divergence watch: is the integration still telling the truth about the
// energy? It reads the work balance of every scene (docs/contacts.md, "The
// work balance of every scene"),
//     D = E + impact losses + friction work − joint work − support work − E₀,
// which is zero for the exact motion, and judges |D| against a scale that,
// like D itself, does not depend on where the potential energy's zero is:
//     S = the largest, so far, of the kinetic energy T, the potential energy
//         exchanged |V − V₀|, |joint work|, |support work|, the impact
//         losses and |friction work|
// — the energy that actually moved. (Judged against |E₀| instead, a body
// spinning 1000 m up had its error divided by its height: 4.5× its whole
// rotational energy passed as "0.045 relative".) A floor of 10⁻⁹·max(|E₀|,
// |E|) keeps round-off in E, which does grow with the datum's distance, from
// counting as divergence for a body at rest.
// The same watch serves the run library (runScene), the command line (its
// --max-energy-error) and the Python module (Simulation's max_energy_error).
#pragma once

#include <appell/simulator.hpp>

namespace appell {

class DivergenceWatch {
 public:
  /// `max_relative_error`: the bound on |D| / S; ∞ (or NaN) switches the watch off.
  explicit DivergenceWatch(double max_relative_error = 5e-2);
  /// Takes E₀, V₀ and the first scale from the simulator's current state.
  void start(const Simulator& sim);
  /// After an accepted step: updates S with the state reached and returns
  /// false when |D| exceeds bound·S + the round-off floor.
  bool check(const Simulator& sim);
  bool enabled() const { return enabled_; }
  double bound() const { return bound_; }
  double deviation() const { return deviation_; }  ///< |D| at the last check (J)
  double scale() const { return scale_; }          ///< S (J, at least 1e-12)
  double relative() const { return deviation_ / scale_; }
  double energy0() const { return energy0_; }

 private:
  double bound_;
  bool enabled_;
  double energy0_ = 0, potential0_ = 0, scale_ = 1e-12, deviation_ = 0;
};

}  // namespace appell
