// The documents one load reads. A scene is either a URDF whose <robot> holds
// an <appell> block, or a scene file — a top-level <appell robot="…"> that
// names an unmodified robot description (package://, file://, absolute or
// relative to the scene file) and adds the simulation around it, as a
// MuJoCo model includes a robot or a ROS launch file spawns one from its
// package. Both paths end in the same pair: the description's <robot> and
// the <appell> element in force, with an XmlSource that names, for every
// element, the file it is in.
#include "urdf/urdf_internal.hpp"

namespace appell::io {

namespace {

const TiXmlElement* embeddedBlock(const XmlSource& src, const TiXmlElement* robot) {
  const TiXmlElement* block = robot->FirstChildElement("appell");
  if (block && block->NextSiblingElement("appell"))
    fail(src, block->NextSiblingElement("appell"), "more than one <appell> block");
  return block;
}

// The description's path, resolved as a mesh's is but from the scene file's folder.
std::string robotPath(const XmlSource& scene, const TiXmlElement* root, const std::string& base_dir,
                      const LoadOptions& options) {
  if (!has(root, "robot"))
    fail(scene, root,
         "a scene file names the robot description it simulates: robot=\"package://NAME/path/robot.urdf\" "
         "(or a path relative to the scene file); a URDF's root element is <robot>");
  const std::string uri = text(scene, root, "robot");
  try {
    return resolveFile("robot", uri, base_dir, options);
  } catch (const SceneError& e) {
    fail(scene, root, e.what());
  }
}

// Reads and parses the description; an error in it names the description's
// file and line, and then the scene file that asked for it.
const TiXmlElement* readDescription(const XmlSource& scene, const TiXmlElement* root,
                                    Documents& d) {
  d.named_by = " (the robot description " + where(scene, root) + " names)";
  const TiXmlElement* robot =
      fromDescription(d, [&] { return parseXml(d.src, d.robot_doc, readFile(d.robot_path)); });
  const std::string tag = robot->Value();
  if (tag == "appell")
    fail(scene, root, "robot '" + d.robot_path + "' is itself a scene file (its root is <appell>): "
                      "robot= names a URDF, whose root is <robot>");
  if (tag != "robot")
    fail(scene, root, "robot '" + d.robot_path + "': its root element is <" + clipped(tag) +
                      ">, not <robot>: robot= names a URDF");
  return robot;
}

}  // namespace

void openDocuments(Documents& d, const std::string& xml, const std::string& base_dir,
                   const std::string& name, const LoadOptions& options) {
  const XmlSource given{name, nullptr, {}};
  const TiXmlElement* root = parseXml(given, d.scene_doc, xml);
  const std::string tag = root->Value();
  if (tag == "robot") {  // a URDF, with its own block if any
    d.src = given;
    d.robot = root;
    d.robot_path = name;
    d.robot_dir = d.block_dir = base_dir;
    d.block = embeddedBlock(given, root);
    return;
  }
  if (tag != "appell")
    fail(given, root, "the root element must be <robot> (a URDF) or <appell robot=\"…\"> (a scene "
                      "file around a robot description)");
  d.scene_file = true;
  d.block = root;
  d.block_dir = base_dir;
  d.robot_path = robotPath(given, root, base_dir, options);
  d.robot_dir = folderOf(d.robot_path);
  d.src = XmlSource{d.robot_path, &d.scene_doc, name};
  d.robot = readDescription(given, root, d);
  // The scene file says how this robot is simulated; a block the
  // description carries (its author's own scene) gives way whole — merging
  // two sets of supports, contacts and settings would have no one meaning.
  if (const TiXmlElement* own = embeddedBlock(d.src, d.robot))
    d.warnings.push_back(located(d.src, own, "ignored: the scene file " + where(given, root) +
                                                 " replaces the description's own <appell> block whole"));
}

}  // namespace appell::io
