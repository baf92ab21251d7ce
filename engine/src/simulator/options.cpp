// Validation of SimulatorOptions: the projection's, the contact events' and
// Baumgarte's numbers finite and of the right sign, iteration counts at least
// one. The Simulator's constructor calls it (with validateOptions of the
// integrator's options, through makeIntegrator), so a tolerance of NaN —
// which compares false with everything and so disables the test it sits in —
// is refused by name instead of silently turning a check off.
#include <appell/simulator.hpp>

#include "integrators/option_checks.hpp"

namespace appell {

namespace {

void validateProjection(const ProjectionOptions& p) {
  constexpr const char* kOwner = "SimulatorOptions";
  detail::requirePositive(kOwner, "projection.gap_tol", p.gap_tol);
  detail::requireNonNegative(kOwner, "projection.stall_tol", p.stall_tol);
  detail::requireAtLeast(kOwner, "projection.max_iterations", p.max_iterations, 1);
  detail::requireNonNegative(kOwner, "projection.rank.rank_abs_tol", p.rank.rank_abs_tol);
  detail::requireNonNegative(kOwner, "projection.rank.rank_rel_tol", p.rank.rank_rel_tol);
  detail::requireNonNegative(kOwner, "projection.rank.consistency_tol", p.rank.consistency_tol);
}

void validateContacts(const ContactEventOptions& c) {
  constexpr const char* kOwner = "SimulatorOptions";
  detail::requireNonNegative(kOwner, "contacts.gap_tol", c.gap_tol);
  detail::requireNonNegative(kOwner, "contacts.speed_tol", c.speed_tol);
  detail::requireNonNegative(kOwner, "contacts.force_tol", c.force_tol);
  detail::requirePositive(kOwner, "contacts.time_tol", c.time_tol);
  detail::requireNonNegative(kOwner, "contacts.rest_speed", c.rest_speed);
  detail::requireNonNegative(kOwner, "contacts.settle_time", c.settle_time);
  detail::requireNonNegative(kOwner, "contacts.feature_window", c.feature_window);
  detail::requireAtLeast(kOwner, "contacts.max_mode_iterations", c.max_mode_iterations, 1);
  detail::requireAtLeast(kOwner, "contacts.max_locate_iterations", c.max_locate_iterations, 1);
}

}  // namespace

void validateOptions(const SimulatorOptions& o) {
  validateProjection(o.projection);
  validateContacts(o.contacts);
  if (o.baumgarte.enabled) {
    detail::requireNonNegative("SimulatorOptions", "baumgarte.alpha", o.baumgarte.alpha);
    detail::requireNonNegative("SimulatorOptions", "baumgarte.beta", o.baumgarte.beta);
  }
}

}  // namespace appell
