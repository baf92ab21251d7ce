// MuJoCo 2.2.2's side of the vehicle comparison (mujoco_vehicles.cpp): the
// solver settings a row runs with, the MJCF built from a VehicleModel, and a
// run that samples the chassis at given times outside its timed region.
#pragma once

#include "vehicle_problem.hpp"

#include <string>
#include <vector>

namespace peers {

/// One MuJoCo configuration (MJCF <option> and <default><geom>). Empty
/// solref / solimp: MuJoCo's defaults (0.02 1 and 0.9 0.95 0.001).
struct MujocoSettings {
  std::string name;                 ///< the row's label in the report
  double dt = 2e-3;                 ///< MuJoCo's default timestep
  std::string integrator = "Euler";  ///< "Euler" (semi-implicit) or "implicit"
  std::string cone = "pyramidal";   ///< MuJoCo's default; or "elliptic"
  std::string solver = "Newton";    ///< MuJoCo's default
  int iterations = 100;             ///< MuJoCo's default
  double tolerance = 1e-8;          ///< MuJoCo's default
  double impratio = 1;
  int noslip = 0;
  std::string solref, solimp;
  std::string wheel_shape = "sphere";  ///< or "cylinder"
  int condim = 3;
  double mu = 1;                    ///< sliding friction of every geom
};

std::string mujocoModelXml(const VehicleModel& v, const MujocoSettings& s);
/// Sum of the compiled model's body masses (a check on the MJCF).
double mujocoTotalMass(const VehicleModel& v, const MujocoSettings& s);
/// Runs v.duration seconds in steps of s.dt from the resting initial pose
/// (link origin at axle height = wheel radius, wheels just touching).
VehicleRun runMujocoVehicle(const VehicleModel& v, const MujocoSettings& s, const std::vector<double>& sample_times);

}  // namespace peers
