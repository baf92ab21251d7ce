// The one walk over a URDF <robot> element: every value is checked where it
// is read, so every message carries a line number, and what is read is kept
// (UrdfRobot) for buildRobot. No second parser sees the text: urdfdom, the
// ROS parser, would re-parse it from the string (its only entry points),
// reports errors without lines, and silently accepts some broken trees (a link
// with two parent joints keeps the last one). The elements the loader does not
// use but URDF 1.0 defines (materials, joint dynamics, safety controllers,
// calibration) are still checked as urdfdom checks them, so a file this loader
// accepts is a valid URDF for ROS tools too.
#include "urdf/urdf_internal.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <set>
#include <vector>
#include <sstream>

namespace appell::io {

// The XML pre-scan: the deepest element nesting, counted the way TinyXML's
// recursive parser nests (one C++ frame per element level: a file nested 10⁵
// deep overflows its stack), without parsing. Each '<' is classified as
// TinyXML 2.6's TiXmlNode::Identify does:
//   "<?xml"          declaration — ends at its first '>' here (TinyXML may
//                    read on inside a quoted version: we never count less)
//   "<!--", "<![CDATA["  comment / CDATA — end at "-->" / "]]>", as there
//   "<!", "<?"       DOCTYPE, processing instruction: an unknown node that
//                    ends at the first '>', quotes or not
//   "</"             an end tag (at depth 0 TinyXML reads it as an unknown node)
//   '<' + a letter, '_' or a byte ≥ 127 (TinyXML's IsAlpha)   an element,
//                    whose tag ends at the first '>' outside a quoted value
//                    (TinyXML reads quoted attribute values whole too, and
//                    refuses a quote anywhere else in a tag)
//   anything else    also an unknown node to TinyXML, ending at the first
//                    '>' — `<1 " >` is one — refused here as junk: skipping
//                    its quote as an attribute's once made the pre-scan see
//                    one tag where the parser then nested 70 000 elements.
namespace {

bool startsWith(const std::string& xml, std::size_t i, const char* prefix, bool ignore_case = false) {
  for (std::size_t k = 0; prefix[k]; ++k) {
    if (i + k >= xml.size()) return false;
    const char c = xml[i + k];
    const bool same = ignore_case ? std::tolower(static_cast<unsigned char>(c)) == prefix[k] : c == prefix[k];
    if (!same) return false;
  }
  return true;
}


[[noreturn]] void junkNode(const XmlSource& src, const std::string& xml, std::size_t i,
                           const char* why = "is not an element, an end tag, a comment or a declaration") {
  const long line = 1 + std::count(xml.begin(), xml.begin() + static_cast<long>(i), '\n');
  const std::size_t end = xml.find('>', i);
  const std::string node = xml.substr(i, end == std::string::npos ? 16 : std::min<std::size_t>(end - i + 1, 64));
  throw SceneError(src.file + ":" + std::to_string(line) + ": malformed XML: '" + clipped(node) + "' " + why);
}

}  // namespace

static int nestingDepth(const XmlSource& src, const std::string& xml, int limit) {
  int depth = 0, deepest = 0;
  const std::size_t n = xml.size();
  for (std::size_t i = xml.find('<'); i < n; i = xml.find('<', i + 1)) {
    std::size_t end = std::string::npos;
    if (startsWith(xml, i, "<!--")) {
      end = xml.find("-->", i + 4);
    } else if (startsWith(xml, i, "<![CDATA[")) {
      end = xml.find("]]>", i + 9);
    } else if (startsWith(xml, i, "<?xml", true) || startsWith(xml, i, "<!") || startsWith(xml, i, "<?")) {
      end = xml.find('>', i);
    } else if (startsWith(xml, i, "</")) {
      end = xml.find('>', i);
      if (depth == 0) junkNode(src, xml, i, "closes no open element");
      --depth;
    } else if (i + 1 < n && (std::isalpha(static_cast<unsigned char>(xml[i + 1])) || xml[i + 1] == '_' ||
                             static_cast<unsigned char>(xml[i + 1]) >= 127)) {
      end = tagEnd(xml, i);
      if (end != std::string::npos && xml[end - 1] != '/') deepest = std::max(deepest, ++depth);
      if (deepest > limit) return deepest;
    } else {
      junkNode(src, xml, i);
    }
    if (end == std::string::npos) break;  // unterminated: the parser's error
    i = end;
  }
  return deepest;
}

namespace {

// A .urdf.xacro given as it is: xacro elements (<xacro:macro>, …) or
// substitutions (${…}, $(find …)) left in. One error, at the first one, says
// what to do, instead of a cascade of "is not a number" and unknown elements.
// Only content counts: xacro's own output keeps the xmlns:xacro declaration
// on <robot> and holds no xacro at all, and urdfdom, Pinocchio, MuJoCo and
// Drake ignore namespace declarations — so does this check.
void rejectXacro(const XmlSource& src, const TiXmlElement* robot) {
  const std::string how =
      ": the file still holds unexpanded xacro — expand it first: xacro FILE.urdf.xacro > FILE.urdf";
  std::vector<const TiXmlElement*> pending{robot};  // the depth is bounded above; no recursion anyway
  while (!pending.empty()) {
    const TiXmlElement* e = pending.back();
    pending.pop_back();
    const std::string tag = e->Value();
    if (tag.rfind("xacro:", 0) == 0) fail(src, e, "element <" + tag + ">" + how);
    for (const TiXmlAttribute* a = e->FirstAttribute(); a; a = a->Next()) {
      const std::string value = a->Value();
      if (value.find("${") != std::string::npos || value.find("$(") != std::string::npos)
        fail(src, e, std::string("attribute ") + a->Name() + "=\"" + clipped(value) + "\"" + how);
    }
    for (const TiXmlNode* c = e->LastChild(); c; c = c->PreviousSibling())  // document order
      if (const TiXmlElement* ce = c->ToElement()) pending.push_back(ce);
  }
}

}  // namespace

const TiXmlElement* parseXml(const XmlSource& src, TiXmlDocument& doc, const std::string& xml) {
  constexpr int kMaxDepth = 256;  // a URDF is 3–4 levels deep
  if (nestingDepth(src, xml, kMaxDepth) > kMaxDepth)
    fail(src, "malformed XML: elements nested more than " + std::to_string(kMaxDepth) +
                  " deep (a URDF needs 4)");
  // TinyXML may look one byte past a truncated UTF-8 sequence at the very
  // end: give it a copy padded with NULs.
  std::string padded = xml;
  padded.append(8, '\0');
  doc.Parse(padded.c_str(), nullptr, TIXML_ENCODING_UTF8);
  if (doc.Error()) {
    std::string where = src.file;
    if (doc.ErrorRow() > 0)
      where += ":" + std::to_string(doc.ErrorRow()) + ":" + std::to_string(doc.ErrorCol());
    throw SceneError(where + ": malformed XML: " + doc.ErrorDesc());
  }
  const TiXmlElement* root = doc.RootElement();
  if (!root) fail(src, "malformed XML: no root element");
  rejectXacro(src, root);
  return root;
}

namespace {

using Rgba = std::array<double, 4>;
/// Robot-level materials by name: their colour (none for a texture-only one).
using MaterialColours = std::map<std::string, std::optional<Rgba>>;

// URDF 1.0 is the only version there is; urdfdom rejects any other, and
// so does this loader. The attribute is "<major>.<minor>", both integers.
void checkVersion(const XmlSource& src, const TiXmlElement* robot) {
  const char* version = robot->Attribute("version");
  if (!version) return;
  const std::string v = version;
  const auto dot = v.find('.');
  auto integer = [](const std::string& s) {
    return !s.empty() && s.find_first_not_of("0123456789") == std::string::npos;
  };
  if (dot == std::string::npos || !integer(v.substr(0, dot)) || !integer(v.substr(dot + 1)))
    fail(src, robot, "version \"" + v + "\" is not of the form <major>.<minor> (integers)");
  auto value = [](const std::string& s) {  // without leading zeros ("" is 0)
    const auto k = s.find_first_not_of('0');
    return k == std::string::npos ? std::string() : s.substr(k);
  };
  if (value(v.substr(0, dot)) != "1" || !value(v.substr(dot + 1)).empty())
    fail(src, robot, "version \"" + v + "\" is not supported (only URDF 1.0 is)");
}

Inertia readInertial(const XmlSource& src, const TiXmlElement* inertial) {
  const SE3 X = origin(src, inertial);
  const TiXmlElement* mass = inertial->FirstChildElement("mass");
  if (!mass) fail(src, inertial, "missing <mass>");
  const double m = number(src, mass, "value");
  if (m < 0) fail(src, mass, "mass must not be negative, got " + std::to_string(m));
  const TiXmlElement* in = inertial->FirstChildElement("inertia");
  if (!in) fail(src, inertial, "missing <inertia>");
  const char* names[6] = {"ixx", "ixy", "ixz", "iyy", "iyz", "izz"};
  double c[6];
  for (int k = 0; k < 6; ++k) c[k] = number(src, in, names[k]);
  // mass="0" (CAD exporters write it for frames and sensors) is a massless
  // link, whatever inertia it lists: a rotational inertia without mass is
  // no mass distribution. Whether the result is a valid rigid body is decided
  // per rigid group (ModelBuilder: a moving link with the links fixed to it,
  // merged as ROS tools do), so a point mass or a sensor frame on a fixed
  // joint loads; errors about one link's own inertia point at its <inertia>.
  if (m == 0) return Inertia{};
  Mat3 J;
  J << c[0], c[1], c[2], c[1], c[3], c[4], c[2], c[4], c[5];
  Inertia I;
  I.mass = m;
  I.com = X.p;
  // The inertial frame may be rotated with respect to the link frame: the
  // tensor given in it is R J Rᵀ in the link frame (about the same point).
  I.inertia_com = X.R * J * X.R.transpose();
  I.inertia_com = 0.5 * (I.inertia_com + I.inertia_com.transpose());
  return I;
}

// <color rgba> must be four numbers in [0, 1]; a top-level <material> must define a
// colour or a texture (a <material> inside <visual> may only name one).
// Returns the colour, if the material gives one.
std::optional<Rgba> checkMaterial(const XmlSource& src, const TiXmlElement* material, bool top_level) {
  text(src, material, "name");
  const TiXmlElement* color = material->FirstChildElement("color");
  std::optional<Rgba> rgba;
  if (color) {
    const std::vector<double> c = numbers(src, color, "rgba", 4);
    for (double x : c)
      if (x < 0 || x > 1) fail(src, color, "colour components must lie in [0, 1]");
    rgba = Rgba{c[0], c[1], c[2], c[3]};
  }
  const TiXmlElement* texture = material->FirstChildElement("texture");
  if (top_level && !color && !(texture && has(texture, "filename")))
    fail(src, material, "a material needs a <color rgba> or a <texture filename>");
  return rgba;
}

// A visual's colour, as URDF resolves it: its <material>'s own <color>, else
// the robot-level material of that name. A name defined nowhere is drawn in
// the default colour, with a warning (urdfdom refuses the file; RViz users
// meet such files after a xacro that dropped the materials' include).
std::optional<Rgba> visualColour(const XmlSource& src, const TiXmlElement* material,
                                 const MaterialColours& materials, std::vector<std::string>& warnings) {
  if (std::optional<Rgba> own = checkMaterial(src, material, false)) return own;
  const std::string name = material->Attribute("name");
  if (const auto it = materials.find(name); it != materials.end()) return it->second;
  warnings.push_back(src.file + (material->Row() > 0 ? ":" + std::to_string(material->Row()) : "") +
                     ": " + describe(material) + ": material '" + name +
                     "' is not defined at the robot level: drawn in the default colour");
  return std::nullopt;
}

UrdfGeometry readGeometry(const XmlSource& src, const TiXmlElement* holder) {
  UrdfGeometry out;
  Geometry& g = out.geometry;
  g.origin = origin(src, holder);
  g.name = text(holder, "name", "");
  const TiXmlElement* ge = holder->FirstChildElement("geometry");
  if (!ge) fail(src, holder, "missing <geometry>");
  const TiXmlElement* shape = ge->FirstChildElement();
  if (!shape) fail(src, ge, "empty <geometry>");
  if (shape->NextSiblingElement()) fail(src, ge, "more than one shape in <geometry>");
  out.shape = shape;
  const std::string type = shape->Value();
  auto positive = [&](const char* attr) {
    const double x = number(src, shape, attr);
    if (x <= 0) fail(src, shape, std::string("'") + attr + "' must be positive");
    return x;
  };
  if (type == "box") {
    g.type = GeometryType::Box;
    g.box_size = vec3(src, shape, "size");
    if (g.box_size.minCoeff() <= 0) fail(src, shape, "box sizes must be positive");
  } else if (type == "cylinder") {
    g.type = GeometryType::Cylinder;
    g.radius = positive("radius");
    g.length = positive("length");
  } else if (type == "sphere") {
    g.type = GeometryType::Sphere;
    g.radius = positive("radius");
  } else if (type == "mesh") {
    g.type = GeometryType::Mesh;
    g.mesh_uri = text(src, shape, "filename");
    if (g.mesh_uri.empty()) fail(src, shape, "empty 'filename'");
    g.mesh_scale = vec3(src, shape, "scale", Vec3::Ones());
    if (g.mesh_scale.cwiseAbs().minCoeff() == 0) fail(src, shape, "'scale' has a zero component");
  } else {
    fail(src, shape, "unsupported geometry <" + type + "> (supported: box, cylinder, sphere, mesh)");
  }
  return out;
}

UrdfLink readLink(const XmlSource& src, const TiXmlElement* l, const MaterialColours& materials,
                  std::vector<std::string>& warnings) {
  UrdfLink link;
  link.element = l;
  link.name = text(src, l, "name");
  if (link.name.empty()) fail(src, l, "empty link name");
  if (const TiXmlElement* in = l->FirstChildElement("inertial")) {
    if (in->NextSiblingElement("inertial")) fail(src, l, "more than one <inertial>");
    link.inertia = readInertial(src, in);
    link.inertia_element = in->FirstChildElement("inertia");
  }
  for (const TiXmlElement* v = l->FirstChildElement("visual"); v; v = v->NextSiblingElement("visual")) {
    link.visual.push_back(readGeometry(src, v));
    if (const TiXmlElement* m = v->FirstChildElement("material"))
      link.visual.back().geometry.rgba = visualColour(src, m, materials, warnings);
  }
  for (const TiXmlElement* c = l->FirstChildElement("collision"); c;
       c = c->NextSiblingElement("collision"))
    link.collision.push_back(readGeometry(src, c));
  return link;
}

// The URDF joint types, each with the Model's joint type (URDF has no ball joint).
struct JointTypeName {
  const char* name;
  JointType type;
};
constexpr JointTypeName kJointTypes[] = {
    {"fixed", JointType::Fixed},         {"revolute", JointType::Revolute},
    {"continuous", JointType::Continuous}, {"prismatic", JointType::Prismatic},
    {"planar", JointType::Planar},       {"floating", JointType::Floating}};

JointType jointType(const XmlSource& src, const TiXmlElement* j) {
  const std::string type = text(src, j, "type");
  std::string known;
  for (const JointTypeName& t : kJointTypes) {
    if (type == t.name) return t.type;
    known += (known.empty() ? "" : ", ") + std::string(t.name);
  }
  fail(src, j, "unsupported joint type '" + type + "' (supported: " + known + ")");
}

bool hasAxis(JointType type) { return type != JointType::Fixed && type != JointType::Floating; }

// <dynamics>, <safety_controller> and <calibration> do not enter the model;
// their numbers are still checked (URDF requires damping or friction in
// <dynamics> and k_velocity in <safety_controller>).
void checkUnusedJointElements(const XmlSource& src, const TiXmlElement* j) {
  if (const TiXmlElement* d = j->FirstChildElement("dynamics")) {
    if (!has(d, "damping") && !has(d, "friction"))
      fail(src, d, "needs 'damping' or 'friction'");
    number(src, d, "damping", 0.0);
    number(src, d, "friction", 0.0);
  }
  if (const TiXmlElement* s = j->FirstChildElement("safety_controller")) {
    number(src, s, "k_velocity");
    for (const char* a : {"soft_lower_limit", "soft_upper_limit", "k_position"}) number(src, s, a, 0.0);
  }
  if (const TiXmlElement* c = j->FirstChildElement("calibration"))
    for (const char* a : {"rising", "falling"}) number(src, c, a, 0.0);
}

UrdfJoint readJoint(const XmlSource& src, const TiXmlElement* j) {
  UrdfJoint joint;
  joint.element = j;
  joint.name = text(src, j, "name");
  if (joint.name.empty()) fail(src, j, "empty joint name");
  joint.type = jointType(src, j);
  const TiXmlElement* pe = j->FirstChildElement("parent");
  const TiXmlElement* ce = j->FirstChildElement("child");
  if (!pe) fail(src, j, "missing <parent>");
  if (!ce) fail(src, j, "missing <child>");
  joint.parent = text(src, pe, "link");
  joint.child = text(src, ce, "link");
  if (const TiXmlElement* m = j->FirstChildElement("mimic")) {
    if (m->NextSiblingElement("mimic")) fail(src, m->NextSiblingElement("mimic"), "a joint has one <mimic>");
    UrdfMimic mimic;
    mimic.element = m;
    mimic.joint = text(src, m, "joint");
    mimic.multiplier = number(src, m, "multiplier", 1.0);
    mimic.offset = number(src, m, "offset", 0.0);
    joint.mimic = mimic;
  }
  joint.origin = origin(src, j);
  if (const TiXmlElement* a = j->FirstChildElement("axis")) {
    Vec3 axis = vec3(src, a, "xyz");
    // Scaled first: "1e308 1e308 0" is a direction, but its norm overflows.
    if (const double big = axis.cwiseAbs().maxCoeff(); big > 0) axis /= big;
    if (hasAxis(joint.type)) {
      if (axis.norm() < 1e-12) fail(src, a, "joint axis is zero");
      joint.axis = axis;
    }
  }
  const std::string type = text(src, j, "type");
  if (const TiXmlElement* lim = j->FirstChildElement("limit")) {
    // URDF: lower and upper default to 0; effort and velocity are required.
    const double lo = number(src, lim, "lower", 0.0), hi = number(src, lim, "upper", 0.0);
    joint.limits.effort = number(src, lim, "effort");
    joint.limits.velocity = number(src, lim, "velocity");
    if (joint.type != JointType::Continuous) {
      if (lo > hi)
        fail(src, lim, "lower limit " + std::to_string(lo) + " exceeds upper limit " +
                           std::to_string(hi));
      joint.limits.lower = lo;
      joint.limits.upper = hi;
    }
  } else if (joint.type == JointType::Revolute || joint.type == JointType::Prismatic) {
    fail(src, j, "a " + type + " joint needs a <limit> element (URDF requires it)");
  }
  checkUnusedJointElements(src, j);
  return joint;
}

}  // namespace

// A <mimic> names a one-degree-of-freedom joint of this robot, and the
// couplings do not go round in a circle (a joint that follows itself through
// others is either redundant or contradicts itself). Chains are fine: each
// link of the chain is its own constraint row. A <mimic> on a fixed joint
// moves nothing: it is dropped with a warning, as Pinocchio ignores it
// (CAD exporters and xacro macros leave it on joints later fixed).
void checkMimics(const XmlSource& src, UrdfRobot& ix) {
  for (const std::string& name : ix.joint_order) {
    UrdfJoint& j = ix.joints.at(name);
    if (!j.mimic) continue;
    const UrdfMimic& m = *j.mimic;
    if (j.type == JointType::Fixed) {
      ix.warnings.push_back(located(src, m.element, "a fixed joint moves nothing: its <mimic> of '" +
                                                        m.joint + "' is ignored"));
      j.mimic.reset();
      continue;
    }
    const std::string instead = " — remove the <mimic>, or couple revolute, continuous or prismatic joints";
    if (!oneDofJoint(j.type))
      fail(src, m.element, std::string("a ") + toString(j.type) +
                               " joint cannot mimic (only revolute, continuous and prismatic joints)" + instead);
    const auto leader = ix.joints.find(m.joint);
    if (leader == ix.joints.end())
      fail(src, m.element, "mimics joint '" + m.joint + "', which is not declared (name a joint of this robot)");
    if (m.joint == name) fail(src, m.element, "joint '" + name + "' mimics itself" + instead);
    if (!oneDofJoint(leader->second.type))
      fail(src, m.element, "mimics '" + m.joint + "', a " + toString(leader->second.type) +
                               " joint (only revolute, continuous and prismatic joints can be followed)" +
                               instead);
    // Follow the chain of leaders; at most one step per joint.
    std::string at = m.joint;
    for (std::size_t steps = 0; steps <= ix.joint_order.size(); ++steps) {
      const UrdfJoint& l = ix.joints.at(at);
      if (!l.mimic || !ix.joints.count(l.mimic->joint)) break;
      at = l.mimic->joint;
      if (at == name)
        fail(src, m.element, "the mimic couplings of '" + name + "' come back to it (a cycle through '" +
                                 m.joint + "'): one joint of the cycle must lead");
    }
  }
}

UrdfRobot readUrdf(const XmlSource& src, const TiXmlElement* robot) {
  UrdfRobot ix;
  if (text(robot, "name", "").empty()) fail(src, robot, "the robot has no name");
  checkVersion(src, robot);

  MaterialColours materials;
  for (const TiXmlElement* m = robot->FirstChildElement("material"); m;
       m = m->NextSiblingElement("material")) {
    const std::optional<Rgba> rgba = checkMaterial(src, m, true);
    if (!materials.emplace(m->Attribute("name"), rgba).second)
      fail(src, m, "material name '" + std::string(m->Attribute("name")) + "' is used twice");
  }

  for (const TiXmlElement* l = robot->FirstChildElement("link"); l;
       l = l->NextSiblingElement("link")) {
    UrdfLink link = readLink(src, l, materials, ix.warnings);
    if (ix.links.count(link.name)) fail(src, l, "link name '" + link.name + "' is used twice");
    ix.link_order.push_back(link.name);
    ix.links.emplace(link.name, std::move(link));
  }
  if (ix.links.empty()) fail(src, robot, "no <link> elements");
  ix.has_world = ix.links.count("world") > 0;

  for (const TiXmlElement* j = robot->FirstChildElement("joint"); j;
       j = j->NextSiblingElement("joint")) {
    UrdfJoint joint = readJoint(src, j);
    const std::string& name = joint.name;
    const std::string& parent = joint.parent;
    const std::string& child = joint.child;
    const TiXmlElement* pe = j->FirstChildElement("parent");
    const TiXmlElement* ce = j->FirstChildElement("child");
    if (ix.joints.count(name)) fail(src, j, "joint name '" + name + "' is used twice");
    if (!ix.links.count(parent)) fail(src, pe, "parent link '" + parent + "' is not declared");
    if (!ix.links.count(child)) fail(src, ce, "child link '" + child + "' is not declared");
    if (parent == child) fail(src, j, "link '" + child + "' is its own parent");
    if (child == "world") fail(src, ce, "the world cannot be a child link");
    if (auto it = ix.parent_joint.find(child); it != ix.parent_joint.end())
      fail(src, j, "link '" + child + "' has two parents (joints '" + it->second + "' and '" +
                       name + "')");
    ix.joint_order.push_back(name);
    ix.parent_joint[child] = name;
    ix.child_joints[parent].push_back(name);
    ix.joints.emplace(name, std::move(joint));
  }

  // One tree: exactly one link without a parent, and every link reachable.
  std::vector<std::string> roots;
  for (const auto& n : ix.link_order)
    if (!ix.parent_joint.count(n)) roots.push_back(n);
  if (ix.has_world && ix.parent_joint.count("world") == 0 && roots.size() > 1) {
    std::string others;
    for (const auto& r : roots)
      if (r != "world") others += (others.empty() ? "'" : ", '") + r + "'";
    fail(src, ix.links.at(roots[roots[0] == "world" ? 1 : 0]).element,
         "disconnected links: " + others + " not attached to 'world' (a URDF is one tree)");
  }
  if (roots.size() > 1)
    fail(src, ix.links.at(roots[1]).element,
         "disconnected links: '" + roots[0] + "' and '" + roots[1] +
             "' both have no parent joint (a URDF is one tree)");
  if (roots.empty()) fail(src, robot, "no root link: the joints form a cycle");
  ix.root = roots[0];

  std::set<std::string> seen;
  std::vector<std::string> stack = {ix.root};
  while (!stack.empty()) {
    const std::string l = stack.back();
    stack.pop_back();
    seen.insert(l);
    if (l != "world") ix.body_order.push_back(l);
    const auto it = ix.child_joints.find(l);
    if (it == ix.child_joints.end()) continue;
    // Push in reverse so children come out in document order (depth first).
    for (auto j = it->second.rbegin(); j != it->second.rend(); ++j) {
      stack.push_back(ix.joints.at(*j).child);
    }
  }
  for (const auto& n : ix.link_order)
    if (!seen.count(n))
      fail(src, ix.links.at(n).element, "link '" + n + "' is not connected to the root '" + ix.root +
                                    "' (its joints form a cycle)");
  checkMimics(src, ix);
  return ix;
}

}  // namespace appell::io
