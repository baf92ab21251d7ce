// Private pieces of the URDF loader shared between its source files.
#pragma once

#include <appell/urdf.hpp>

#include "urdf/xml_util.hpp"

#include <map>
#include <string>
#include <vector>

namespace appell::io {

/// What the structural check of the <robot> element found: every link and
/// joint element by name, in document order, and the tree.
struct UrdfIndex {
  std::map<std::string, const TiXmlElement*> links, joints;
  std::vector<std::string> link_order, joint_order;
  std::map<std::string, std::string> parent_joint;          ///< child link → joint
  std::map<std::string, std::vector<std::string>> child_joints;  ///< link → joints, document order
  std::string root;       ///< the root link ("world" when the robot is fixed)
  bool has_world = false;
  /// Links in depth-first order from the root (the root first), without "world".
  std::vector<std::string> body_order;
};

/// Checks the <robot> element before urdfdom sees it, with line numbers:
/// names, numbers (finite), masses, inertia tensors, geometry sizes, joint
/// types, axes, limits, and that the links form one tree. Throws SceneError.
UrdfIndex checkUrdf(const XmlSource& src, const TiXmlElement* robot);

/// A parsed robot: the model and the geometry of each body.
struct Robot {
  Model model;
  std::vector<LinkGeometry> geometry;
};

/// Builds the model through urdfdom from the same text (after checkUrdf).
Robot buildRobot(const XmlSource& src, const UrdfIndex& index, const std::string& xml,
                 const std::string& base_dir, const LoadOptions& options, const Vec3& gravity);

/// Whole file as a string; SceneError if it cannot be read.
std::string readFile(const std::string& path);
/// Absolute folder of a file path.
std::string folderOf(const std::string& path);

/// Parses the document and returns its <robot> element; throws SceneError
/// with the parser's line and column on malformed XML.
const TiXmlElement* parseDocument(const XmlSource& src, TiXmlDocument& doc,
                                  const std::string& xml);

}  // namespace appell::io
