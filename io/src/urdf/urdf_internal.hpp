// Private pieces of the URDF loader shared between its source files.
//
// The URDF is parsed once, by TinyXML, into one DOM that every stage reads:
// readUrdf (read.cpp) walks the <robot> element once, checking each value as
// it reads it, so every message carries a line number; buildRobot (model.cpp)
// turns what it read into the Model and the link geometry; the <appell> block
// (scene/block.cpp) reads its own child of the same DOM.
#pragma once

#include <cstdint>

#include <appell/urdf.hpp>

#include "urdf/xml_util.hpp"

#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace appell::io {

/// One <visual> or <collision> element as read: the geometry with its mesh
/// not yet resolved, and the shape element (<box>, <mesh>, …) for messages.
struct UrdfGeometry {
  const TiXmlElement* shape = nullptr;
  Geometry geometry;
};

struct UrdfLink {
  const TiXmlElement* element = nullptr;
  std::string name;
  /// From <inertial>: the inertia tensor rotated into the link frame
  /// (I_link = R I Rᵀ about the centre of mass). Zero mass without <inertial>.
  Inertia inertia;
  const TiXmlElement* inertia_element = nullptr;  ///< its <inertia>, for messages
  std::vector<UrdfGeometry> visual, collision;  ///< document order
};

/// <mimic joint multiplier offset>: this joint follows `joint` as
/// q = multiplier · q_joint + offset (joint_coupling.hpp).
struct UrdfMimic {
  const TiXmlElement* element = nullptr;
  std::string joint;
  double multiplier = 1, offset = 0;
};

struct UrdfJoint {
  const TiXmlElement* element = nullptr;
  std::string name, parent, child;
  JointType type = JointType::Fixed;
  SE3 origin;                      ///< joint frame in the parent link's frame
  Vec3 axis = Vec3::UnitX();       ///< URDF's default when <axis> is absent
  JointLimits limits;              ///< infinite without <limit>
  std::optional<UrdfMimic> mimic;
};

/// What readUrdf found: every link and joint by name, in document order, and
/// the tree.
struct UrdfRobot {
  std::map<std::string, UrdfLink> links;
  std::map<std::string, UrdfJoint> joints;
  std::vector<std::string> link_order, joint_order;
  std::map<std::string, std::string> parent_joint;          ///< child link → joint
  std::map<std::string, std::vector<std::string>> child_joints;  ///< link → joints, document order
  std::string root;       ///< the root link ("world" when the robot is fixed)
  bool has_world = false;
  /// Links in depth-first order from the root (the root first), without "world".
  std::vector<std::string> body_order;
  /// What the reader tolerated and how, "file:line: <element>: reason" (e.g. a
  /// visual's material that names no robot-level material), for Scene::warnings.
  std::vector<std::string> warnings;
};

/// Reads the <robot> element, checking as it goes: the version, names,
/// numbers (finite), masses, inertia tensors, geometry sizes, joint types,
/// axes, limits, the elements the loader does not use but URDF defines
/// (materials, joint dynamics, safety controllers, calibration), and that the
/// links form one tree. Throws SceneError "file:line: <element>: reason".
UrdfRobot readUrdf(const XmlSource& src, const TiXmlElement* robot);

/// A parsed robot: the model and the geometry of each body.
struct Robot {
  Model model;
  std::vector<LinkGeometry> geometry;
  std::vector<std::string> warnings;  ///< what was left out and why (Scene::warnings)
};

/// Builds the model and the link geometry (meshes resolved and, if the
/// options say so, loaded) from what readUrdf read, with the inertias
/// repaired as asked; each inertia loaded with a defect or repaired adds a
/// warning "file:line: <link name=…>: body '…': …". A collision mesh that
/// cannot be found or read is an error on the links of `contact_links` (a
/// contact takes its shape from their collision geometry), elsewhere a
/// warning, the geometry left out.
Robot buildRobot(const XmlSource& src, const UrdfRobot& urdf, const std::string& base_dir,
                 const LoadOptions& options, const Vec3& gravity, const InertiaRepairs& repairs,
                 const std::set<std::string>& contact_links = {});

/// The repairs in force: each one LoadOptions sets, else the scene's.
InertiaRepairs inertiaRepairs(const LoadOptions& options, const InertiaRepairs& scene);

/// resolveMeshPath for any file a description or scene names: `what` ("mesh",
/// "robot") starts every message.
std::string resolveFile(const std::string& what, const std::string& uri, const std::string& base_dir,
                        const LoadOptions& options);

/// The warning a mesh URI earns when the loader tolerates its form:
/// `package:///NAME/…` is read as `package://NAME/…`. Empty when none.
std::string packageUriNote(const std::string& uri);

/// Whole file as a string; SceneError if it cannot be read.
/// A scene file's text; refuses directories, devices, files over
/// kMaxSceneBytes, UTF-16/32 and binary files, naming the file.
std::string readFile(const std::string& path);
inline constexpr std::uintmax_t kMaxSceneBytes = std::uintmax_t{256} << 20;
/// Absolute folder of a file path.
std::string folderOf(const std::string& path);

/// Parses the document and returns its root element, whatever its tag;
/// throws SceneError with the parser's line and column on malformed XML, and
/// on unexpanded xacro anywhere in it.
const TiXmlElement* parseXml(const XmlSource& src, TiXmlDocument& doc, const std::string& xml);
/// The documents one load reads (documents.cpp): a URDF, whose <robot> may
/// hold an <appell> block, or a scene file — a top-level <appell robot="…">
/// — and the description it names. Filled in place (the elements point into
/// the documents).
struct Documents {
  TiXmlDocument scene_doc;       ///< the file given (the URDF itself, or the scene file)
  TiXmlDocument robot_doc;       ///< the description a scene file names
  XmlSource src;                 ///< names each element's own file
  const TiXmlElement* robot = nullptr;  ///< the description's <robot>
  const TiXmlElement* block = nullptr;  ///< the <appell> in force; null: none
  bool scene_file = false;
  std::string robot_path;        ///< the description's file (resolved for a scene file)
  std::string robot_dir;         ///< resolves the description's meshes
  std::string block_dir;         ///< resolves the block's files (terrains)
  std::vector<std::string> warnings;  ///< a description's own block ignored
  /// " (the robot description scene.xml:2 names)" for a scene file, else empty.
  std::string named_by;
};

/// Runs `read`, a stage reading the description; for a scene file, an error
/// it throws (naming the description's file and line) also says which scene
/// file named the description.
template <class Read>
auto fromDescription(const Documents& d, Read&& read) -> decltype(read()) {
  try {
    return read();
  } catch (const SceneError& e) {
    if (d.named_by.empty()) throw;
    throw SceneError(std::string(e.what()) + d.named_by);
  }
}

/// Parses `xml` (read from `name`, in folder `base_dir`) and, for a scene
/// file, the description its `robot` names (resolved as a mesh URI is, from
/// the scene file's folder). A description with its own <appell> block gives
/// way to the scene file's, with a warning. Throws SceneError: a root that is
/// neither <robot> nor <appell>, a scene file without `robot`, a description
/// not found (every folder searched), not a URDF, or itself a scene file.
void openDocuments(Documents& d, const std::string& xml, const std::string& base_dir,
                   const std::string& name, const LoadOptions& options);

}  // namespace appell::io
