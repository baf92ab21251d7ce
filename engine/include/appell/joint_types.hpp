// The closed set of joint types as data: one entry per JointType, in the
// enum's order — its name, sizes, what it carries (an axis, a unit
// quaternion) and the names of its coordinates (CSV columns, --set names,
// Python's coordinate_names). Everything that is a fact about a type reads
// this table; what a type does (its motion subspace, retraction, rates)
// lives in switch statements with no default over JointType, so a new
// enumerator makes the compiler (-Wswitch, part of -Wall) name every one of
// them — jointTypeIndex() below first. docs/architecture.md, "Adding a
// joint type", lists the steps.
//
//   type        nq nv  q                          v (θ has v's layout)
//   fixed        0  0
//   revolute     1  1  angle                      rate
//   continuous   1  1  angle                      rate
//   prismatic    1  1  offset                     rate
//   planar       3  3  x, y, θ (joint frame)      vx, vy, ω (joint frame)
//   floating     7  6  x, y, z, qx, qy, qz, qw    ω (body), v (world)
//   ball         4  3  qx, qy, qz, qw             ω (body)
#pragma once

#include <appell/model.hpp>

#include <array>
#include <cstddef>
#include <span>
#include <string>
#include <vector>

namespace appell {

struct JointTypeInfo {
  JointType type;
  const char* name;       ///< toString(); the URDF <joint type="…"> where URDF has it
  int nq, nv;
  bool has_axis;          ///< an <axis>: rotation, translation or the plane's normal
  /// Offset in the joint's q of its unit quaternion (x, y, z, w); −1: none.
  int quaternion;
  /// Offset in the joint's θ (and v) of position coordinate 0 when the
  /// positions are local coordinates themselves (θ = Δq there); −1 when they
  /// are not (a ball's quaternion).
  int position_slot;
  /// Suffixes of the joint's name for its coordinates ("" for a joint with a
  /// single one: the joint's own name); nq position and nv velocity entries.
  std::array<const char*, 7> position_names;
  std::array<const char*, 6> velocity_names;
};

inline constexpr std::array<JointTypeInfo, 7> kJointTypes{{
    {JointType::Fixed, "fixed", 0, 0, false, -1, -1, {}, {}},
    {JointType::Revolute, "revolute", 1, 1, true, -1, 0, {""}, {""}},
    {JointType::Continuous, "continuous", 1, 1, true, -1, 0, {""}, {""}},
    {JointType::Prismatic, "prismatic", 1, 1, true, -1, 0, {""}, {""}},
    {JointType::Planar, "planar", 3, 3, true, -1, 0, {".x", ".y", ".theta"},
     {".vx", ".vy", ".omega"}},
    // θ = (rotation, world translation): x, y, z are slots 3–5.
    {JointType::Floating, "floating", 7, 6, false, 3, 3,
     {".x", ".y", ".z", ".qx", ".qy", ".qz", ".qw"}, {".wx", ".wy", ".wz", ".vx", ".vy", ".vz"}},
    {JointType::Ball, "ball", 4, 3, false, 0, -1, {".qx", ".qy", ".qz", ".qw"},
     {".wx", ".wy", ".wz"}},
}};

/// The entry of `type` in kJointTypes. No default: a new enumerator is
/// reported here first (-Wswitch), then at every other dispatch site.
constexpr std::size_t jointTypeIndex(JointType type) {
  switch (type) {
    case JointType::Fixed: return 0;
    case JointType::Revolute: return 1;
    case JointType::Continuous: return 2;
    case JointType::Prismatic: return 3;
    case JointType::Planar: return 4;
    case JointType::Floating: return 5;
    case JointType::Ball: return 6;
  }
  return kJointTypes.size();  // not an enumerator: no entry
}

namespace detail {
constexpr bool jointTableConsistent() {
  for (std::size_t k = 0; k < kJointTypes.size(); ++k) {
    const JointTypeInfo& e = kJointTypes[k];
    if (jointTypeIndex(e.type) != k || e.nv > e.nq || e.nq > 7 || e.nv > 6) return false;
    for (int i = 0; i < 7; ++i)
      if ((e.position_names[i] != nullptr) != (i < e.nq)) return false;
    for (int i = 0; i < 6; ++i)
      if ((e.velocity_names[i] != nullptr) != (i < e.nv)) return false;
    if (e.quaternion >= 0 && e.quaternion + 4 > e.nq) return false;
  }
  return true;
}
}  // namespace detail
static_assert(detail::jointTableConsistent(),
              "kJointTypes: one entry per JointType in the enum's order, nq position and nv "
              "velocity names, a quaternion inside q");

inline const JointTypeInfo& jointTypeInfo(JointType type) {
  return kJointTypes[jointTypeIndex(type)];
}
/// The entry `name` names (toString's spelling), or nullptr.
const JointTypeInfo* findJointType(const std::string& name);

/// The names of the nq position coordinates (velocities = false) or of the
/// nv velocity coordinates, in q or v order: joint name + the type's suffix
/// ("root_joint.x", "root_joint.qw", "steer").
std::vector<std::string> coordinateNames(const Model& model, bool velocities);

/// Index into the local coordinates θ (size nv: linearization, cyclic
/// coordinates; configuration.hpp) of the coordinate called `name` — by its
/// velocity's name ("root_joint.vx", "spin") or, where a position coordinate
/// is itself a local coordinate, by the position's name: a floating joint's
/// "root_joint.x" is θ slot 3. −1 when no coordinate has that name; throws
/// std::invalid_argument for a quaternion component (".qx"), which is not a
/// coordinate of its own, naming the rotation slots to use instead.
int localCoordinateIndex(const Model& model, const std::string& name);

}  // namespace appell
