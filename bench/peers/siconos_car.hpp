// Siconos 4.4's side of the vehicle comparison (siconos_car.cpp): the parked
// car as one rigid NewtonEulerDS with four frictional point contacts, stepped
// by Siconos' TimeStepping + MoreauJeanOSI with a FrictionContact(3) problem
// (NSGS). Only this scene: bench/peers/README.md says why the skid-steer is
// not modelled in Siconos here.
#pragma once

#include "vehicle_problem.hpp"

#include <string>
#include <vector>

namespace peers {

struct SiconosSettings {
  std::string name;
  double h = 1e-3;               ///< time step (s)
  double theta = 0.5;            ///< MoreauJeanOSI's θ
  double tolerance = 1e-10;      ///< NSGS tolerance (Siconos' normalised residual)
  int max_iterations = 1000;     ///< NSGS sweeps
  double newton_tolerance = 1e-10;
  int newton_iterations = 20;
};

/// v.duration seconds of the parked car (v.wheels_locked) from rest with the
/// tyres just touching; the chassis sampled at `sample_times` (untimed).
VehicleRun runSiconosCar(const VehicleModel& v, const SiconosSettings& s, const std::vector<double>& sample_times);

}  // namespace peers
