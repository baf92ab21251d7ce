// Snapping CAD-rounded origin angles to multiples of π/2 (opt in:
// LoadOptions::snap_angles, <simulation snap_angles="…">, `--snap-angles`).
//
// CAD exporters write angles rounded to a few digits: rpy="-1.57 0 0" for a
// wheel turned a quarter, 7.96e-4 rad short of π/2. For a rigid model that
// is a real tilt: a wheel cambered by 8e-4 rad touches the ground 8e-5 m off
// its axle line, and rows that the exact design makes dependent (the two
// wheels' lateral no-slip rows of a differential drive) become independent
// by that margin — the robot can no longer turn (docs/ros-package.md). The
// snap restores the design where the user says the rounding is rounding:
// every angle within the tolerance of kπ/2 becomes kπ/2 exactly (as a
// double, k · π/2), each change reported. Angles already at kπ/2 to within
// 1e-15 rad are left alone and not reported.
#include "urdf/snap_angles.hpp"

#include <cmath>
#include <numbers>
#include <sstream>

namespace appell::io {

namespace {

constexpr double kQuarter = std::numbers::pi / 2;

/// The "-π/2", "π", "0" of k·π/2.
std::string multipleName(long k) {
  if (k == 0) return "0";
  const char* sign = k < 0 ? "-" : "";
  const long a = std::labs(k);
  if (a % 2 == 0) return std::string(sign) + (a == 2 ? "" : std::to_string(a / 2)) + "π";
  return std::string(sign) + (a == 1 ? "" : std::to_string(a)) + "π/2";
}

/// Snaps the <origin rpy> of `holder` in place (`R` its rotation); returns
/// what changed ("" if nothing), e.g. "roll -1.57 → -π/2 (7.96e-04 rad)".
std::string snapOrigin(const XmlSource& src, const TiXmlElement* holder, double tol, Mat3& R) {
  const TiXmlElement* o = holder ? holder->FirstChildElement("origin") : nullptr;
  if (!o || !has(o, "rpy")) return "";
  Vec3 rpy = vec3(src, o, "rpy");
  std::ostringstream what;
  static constexpr const char* kNames[] = {"roll", "pitch", "yaw"};
  for (int i = 0; i < 3; ++i) {
    const long k = std::lround(rpy[i] / kQuarter);
    const double snapped = static_cast<double>(k) * kQuarter;
    const double moved = std::abs(rpy[i] - snapped);
    if (!(moved <= tol) || moved <= 1e-15) continue;
    what.precision(6);
    what << (what.tellp() > 0 ? ", " : "") << kNames[i] << " " << rpy[i] << " → "
         << multipleName(k);
    what.precision(2);
    what << std::scientific << " (" << moved << " rad)" << std::defaultfloat;
    rpy[i] = snapped;
  }
  if (what.tellp() == 0) return "";
  R = rpyToMatrix(rpy);
  return what.str();
}

}  // namespace

std::vector<std::string> snapAngles(const XmlSource& src, double tol, UrdfRobot& urdf) {
  if (!(tol > 0 && tol <= kMaxSnapAngle))
    fail(src, "snap_angles must lie in (0, 0.05] rad: angles further from a multiple of π/2 are "
              "design, not rounding");
  std::vector<std::string> report;
  for (const std::string& name : urdf.joint_order) {
    UrdfJoint& j = urdf.joints.at(name);
    const std::string what = snapOrigin(src, j.element, tol, j.origin.R);
    if (!what.empty()) report.push_back("snapped joint '" + name + "' origin rpy: " + what);
  }
  for (const std::string& name : urdf.link_order) {
    UrdfLink& link = urdf.links.at(name);
    for (auto* list : {&link.visual, &link.collision}) {
      const char* kind = list == &link.visual ? "visual" : "collision";
      for (UrdfGeometry& g : *list) {
        // shape → <geometry> → <visual>/<collision>, which holds the origin.
        const TiXmlNode* holder = g.shape ? g.shape->Parent()->Parent() : nullptr;
        const std::string what =
            snapOrigin(src, holder ? holder->ToElement() : nullptr, tol, g.geometry.origin.R);
        if (!what.empty())
          report.push_back("snapped link '" + name + "' " + kind + " origin rpy: " + what);
      }
    }
  }
  return report;
}

}  // namespace appell::io
