// Structural check of a URDF <robot> element, done on the XML so that every
// message carries a line number. urdfdom reports its own errors only through
// console_bridge, without lines, and silently accepts some broken trees (a
// link with two parent joints keeps the last one), so the loader does not rely
// on it for validation.
#include "urdf/urdf_internal.hpp"

#include <Eigen/Eigenvalues>

#include <cmath>
#include <set>
#include <sstream>

namespace appell::io {

const TiXmlElement* parseDocument(const XmlSource& src, TiXmlDocument& doc,
                                  const std::string& xml) {
  doc.Parse(xml.c_str(), nullptr, TIXML_ENCODING_UTF8);
  if (doc.Error()) {
    std::string where = src.file;
    if (doc.ErrorRow() > 0)
      where += ":" + std::to_string(doc.ErrorRow()) + ":" + std::to_string(doc.ErrorCol());
    throw SceneError(where + ": malformed XML: " + doc.ErrorDesc());
  }
  const TiXmlElement* robot = doc.RootElement();
  if (!robot) fail(src, "malformed XML: no root element");
  if (std::string(robot->Value()) != "robot")
    fail(src, robot, "the root element must be <robot>");
  return robot;
}

namespace {

void checkInertial(const XmlSource& src, const TiXmlElement* inertial) {
  origin(src, inertial);
  const TiXmlElement* mass = inertial->FirstChildElement("mass");
  if (!mass) fail(src, inertial, "missing <mass>");
  const double m = number(src, mass, "value");
  if (m <= 0)
    fail(src, mass, "mass must be positive, got " + std::to_string(m) +
                        " (leave out <inertial> for a massless link)");
  const TiXmlElement* in = inertial->FirstChildElement("inertia");
  if (!in) fail(src, inertial, "missing <inertia>");
  const char* names[6] = {"ixx", "ixy", "ixz", "iyy", "iyz", "izz"};
  double c[6];
  for (int k = 0; k < 6; ++k) c[k] = number(src, in, names[k]);
  Mat3 J;
  J << c[0], c[1], c[2], c[1], c[3], c[4], c[2], c[4], c[5];
  // A rotational inertia about the centre of mass is positive definite and
  // its principal moments satisfy I₁ + I₂ ≥ I₃ (each moment is a sum of two
  // second moments of the mass distribution); otherwise no body has it.
  const Vec3 d = Eigen::SelfAdjointEigenSolver<Mat3>(J).eigenvalues();
  std::ostringstream s;
  s << d(0) << ", " << d(1) << ", " << d(2);
  if (d.minCoeff() <= 0)
    fail(src, in, "inertia tensor is not positive definite (principal moments " + s.str() + ")");
  const double tol = 1e-12 * d.cwiseAbs().maxCoeff();
  if (d(0) + d(1) < d(2) - tol)
    fail(src, in, "principal moments " + s.str() +
                      " violate the triangle inequality I1 + I2 >= I3");
}

void checkGeometry(const XmlSource& src, const TiXmlElement* holder) {
  origin(src, holder);
  const TiXmlElement* g = holder->FirstChildElement("geometry");
  if (!g) fail(src, holder, "missing <geometry>");
  const TiXmlElement* shape = g->FirstChildElement();
  if (!shape) fail(src, g, "empty <geometry>");
  if (shape->NextSiblingElement()) fail(src, g, "more than one shape in <geometry>");
  const std::string type = shape->Value();
  auto positive = [&](const char* attr, double x) {
    if (x <= 0) fail(src, shape, std::string("'") + attr + "' must be positive");
  };
  if (type == "box") {
    const Vec3 s = vec3(src, shape, "size");
    if (s.minCoeff() <= 0) fail(src, shape, "box sizes must be positive");
  } else if (type == "cylinder") {
    positive("radius", number(src, shape, "radius"));
    positive("length", number(src, shape, "length"));
  } else if (type == "sphere") {
    positive("radius", number(src, shape, "radius"));
  } else if (type == "mesh") {
    if (text(src, shape, "filename").empty()) fail(src, shape, "empty 'filename'");
    const Vec3 sc = vec3(src, shape, "scale", Vec3::Ones());
    if (sc.cwiseAbs().minCoeff() == 0) fail(src, shape, "'scale' has a zero component");
  } else {
    fail(src, shape, "unsupported geometry <" + type + "> (supported: box, cylinder, sphere, mesh)");
  }
}

bool needsAxis(const std::string& type) {
  return type == "revolute" || type == "continuous" || type == "prismatic" || type == "planar";
}

}  // namespace

UrdfIndex checkUrdf(const XmlSource& src, const TiXmlElement* robot) {
  UrdfIndex ix;
  if (text(robot, "name", "").empty()) fail(src, robot, "the robot has no name");

  for (const TiXmlElement* l = robot->FirstChildElement("link"); l;
       l = l->NextSiblingElement("link")) {
    const std::string name = text(src, l, "name");
    if (name.empty()) fail(src, l, "empty link name");
    if (ix.links.count(name)) fail(src, l, "link name '" + name + "' is used twice");
    ix.links[name] = l;
    ix.link_order.push_back(name);
    if (const TiXmlElement* in = l->FirstChildElement("inertial")) {
      if (in->NextSiblingElement("inertial")) fail(src, l, "more than one <inertial>");
      checkInertial(src, in);
    }
    for (const char* kind : {"visual", "collision"})
      for (const TiXmlElement* v = l->FirstChildElement(kind); v; v = v->NextSiblingElement(kind))
        checkGeometry(src, v);
  }
  if (ix.links.empty()) fail(src, robot, "no <link> elements");
  ix.has_world = ix.links.count("world") > 0;

  static const std::set<std::string> kTypes = {"fixed",  "revolute", "continuous",
                                               "prismatic", "planar", "floating"};
  for (const TiXmlElement* j = robot->FirstChildElement("joint"); j;
       j = j->NextSiblingElement("joint")) {
    const std::string name = text(src, j, "name");
    if (name.empty()) fail(src, j, "empty joint name");
    if (ix.joints.count(name)) fail(src, j, "joint name '" + name + "' is used twice");
    const std::string type = text(src, j, "type");
    if (!kTypes.count(type))
      fail(src, j, "unsupported joint type '" + type +
                       "' (supported: fixed, revolute, continuous, prismatic, planar, floating)");
    const TiXmlElement* pe = j->FirstChildElement("parent");
    const TiXmlElement* ce = j->FirstChildElement("child");
    if (!pe) fail(src, j, "missing <parent>");
    if (!ce) fail(src, j, "missing <child>");
    const std::string parent = text(src, pe, "link");
    const std::string child = text(src, ce, "link");
    if (!ix.links.count(parent)) fail(src, pe, "parent link '" + parent + "' is not declared");
    if (!ix.links.count(child)) fail(src, ce, "child link '" + child + "' is not declared");
    if (parent == child) fail(src, j, "link '" + child + "' is its own parent");
    if (child == "world") fail(src, ce, "the world cannot be a child link");
    if (auto it = ix.parent_joint.find(child); it != ix.parent_joint.end())
      fail(src, j, "link '" + child + "' has two parents (joints '" + it->second + "' and '" +
                       name + "')");
    if (j->FirstChildElement("mimic"))
      fail(src, j->FirstChildElement("mimic"),
           "mimic joints are not supported (the coupling is a holonomic constraint this "
           "loader does not create)");
    origin(src, j);
    if (const TiXmlElement* a = j->FirstChildElement("axis")) {
      const Vec3 axis = vec3(src, a, "xyz");
      if (needsAxis(type) && axis.norm() < 1e-12) fail(src, a, "joint axis is zero");
    }
    const TiXmlElement* lim = j->FirstChildElement("limit");
    if (lim) {
      const double lo = number(src, lim, "lower", 0.0), hi = number(src, lim, "upper", 0.0);
      number(src, lim, "effort", 0.0);
      number(src, lim, "velocity", 0.0);
      if (type != "continuous" && lo > hi)
        fail(src, lim, "lower limit " + std::to_string(lo) + " exceeds upper limit " +
                           std::to_string(hi));
    } else if (type == "revolute" || type == "prismatic") {
      fail(src, j, "a " + type + " joint needs a <limit> element (URDF requires it)");
    }
    ix.joints[name] = j;
    ix.joint_order.push_back(name);
    ix.parent_joint[child] = name;
    ix.child_joints[parent].push_back(name);
  }

  // One tree: exactly one link without a parent, and every link reachable.
  std::vector<std::string> roots;
  for (const auto& n : ix.link_order)
    if (!ix.parent_joint.count(n)) roots.push_back(n);
  if (ix.has_world && ix.parent_joint.count("world") == 0 && roots.size() > 1) {
    std::string others;
    for (const auto& r : roots)
      if (r != "world") others += (others.empty() ? "'" : ", '") + r + "'";
    fail(src, ix.links.at(roots[roots[0] == "world" ? 1 : 0]),
         "disconnected links: " + others + " not attached to 'world' (a URDF is one tree)");
  }
  if (roots.size() > 1)
    fail(src, ix.links.at(roots[1]),
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
      const TiXmlElement* je = ix.joints.at(*j);
      stack.push_back(je->FirstChildElement("child")->Attribute("link"));
    }
  }
  for (const auto& n : ix.link_order)
    if (!seen.count(n))
      fail(src, ix.links.at(n), "link '" + n + "' is not connected to the root '" + ix.root +
                                    "' (its joints form a cycle)");
  return ix;
}

}  // namespace appell::io
