// Opt-in snap of CAD-rounded origin angles (snap_angles.cpp).
#pragma once

#include "urdf/urdf_internal.hpp"

#include <string>
#include <vector>

namespace appell::io {

/// Largest snap tolerance accepted (rad): beyond it the angles snapped would
/// be design, not rounding.
inline constexpr double kMaxSnapAngle = 0.05;  // (the messages say 0.05)

/// Snaps each roll, pitch and yaw of the joints' <origin rpy> and of the
/// links' <visual>/<collision> <origin rpy> that lies within `tol` (rad,
/// 0 < tol ≤ kMaxSnapAngle) of a multiple of π/2, but not on it, to that
/// multiple, and rebuilds the origin's rotation. Returns one line per origin
/// changed, naming the joint or link, the angles and by how much each moved.
std::vector<std::string> snapAngles(const XmlSource& src, double tol, UrdfRobot& urdf);

}  // namespace appell::io
