// Run options from the command line (run_options.hpp).
#include "run_options.hpp"

#include <cmath>
#include <limits>

namespace appell::cli {

RunOptions runOptionsFromArgs(const Scene& scene, const Args& args) {
  SimulationSettings s = scene.settings;
  s.duration = args.positiveNumber("duration", s.duration);
  s.dt = args.positiveNumber("dt", s.dt);
  s.tol = args.positiveNumber("tol", s.tol);
  if (args.has("tol") && !args.has("integrator") &&
      !adaptiveIntegrator(integratorFromString(s.integrator)))
    s.integrator = toString(IntegratorType::DormandPrince54);
  s.integrator = args.text("integrator", s.integrator);
  s.formulation = args.text("formulation", s.formulation);
  s.contacts = args.text("contacts", s.contacts);
  RunOptions options;
  try {
    options = runOptions(s);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  options.output_every = args.integer("every", 1);
  if (args.has("max-energy-error"))
    options.max_energy_error = args.text("max-energy-error") == "inf"
                                   ? std::numeric_limits<double>::infinity()
                                   : args.positiveNumber("max-energy-error", 5e-2);
  if (args.has("max-residual"))
    options.max_residual = args.text("max-residual") == "inf" ? std::numeric_limits<double>::infinity()
                                                              : args.positiveNumber("max-residual", 1e-6);
  if (args.has("settle-time")) {
    options.settle_time = args.number("settle-time", options.settle_time);
    if (!(options.settle_time >= 0) || !std::isfinite(options.settle_time))
      throw UsageError("--settle-time must be a finite number ≥ 0 (seconds), not '" +
                       args.text("settle-time") + "'");
  }
  if (options.output_every < 1) throw UsageError("option --every must be at least 1");
  options.project_positions = options.project_velocities = !args.has("no-projection");
  return options;
}

}  // namespace appell::cli
