// The datum-free divergence watch (divergence_watch.hpp states the rule).
#include <appell/divergence_watch.hpp>

#include <algorithm>
#include <cmath>

namespace appell {

DivergenceWatch::DivergenceWatch(double max_relative_error)
    : bound_(max_relative_error), enabled_(std::isfinite(max_relative_error)) {}

void DivergenceWatch::start(const Simulator& sim) {
  energy0_ = sim.energy();
  potential0_ = sim.energy() - sim.kineticEnergy();
  scale_ = std::max(sim.kineticEnergy(), 1e-12);
  deviation_ = 0;
}

bool DivergenceWatch::check(const Simulator& sim) {
  const double energy = sim.energy();
  const double potential = energy - sim.kineticEnergy();
  deviation_ = std::abs(energy + sim.impactEnergyLoss() + sim.frictionWork() +
                        sim.schemeEnergyLoss() - sim.jointWork() - sim.supportWork() - energy0_);
  scale_ = std::max({scale_, sim.kineticEnergy(), std::abs(potential - potential0_), std::abs(sim.jointWork()),
                     std::abs(sim.supportWork()), std::abs(sim.impactEnergyLoss()), std::abs(sim.frictionWork()),
                     std::abs(sim.schemeEnergyLoss())});
  if (!enabled_) return true;
  const double round_off = 1e-9 * std::max(std::abs(energy0_), std::abs(energy));
  return deviation_ <= bound_ * scale_ + round_off;  // false for a NaN deviation too
}

}  // namespace appell
