// Parsing of the `<appell>` scene block (docs/scene-format.md).
#include "scene/block.hpp"
#include "urdf/snap_angles.hpp"

#include <appell/constrained_dynamics.hpp>
#include <appell/integrators.hpp>
#include <appell/simulator.hpp>

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>

namespace appell::io {

namespace {

Vec3 unitVector(const XmlSource& src, const TiXmlElement* e, const char* attr, const Vec3& fallback) {
  const Vec3 v = vec3(src, e, attr, fallback);
  if (v.norm() < 1e-12) fail(src, e, std::string("'") + attr + "' is a zero vector");
  return v.normalized();
}

double positive(const XmlSource& src, const TiXmlElement* e, const char* attr) {
  const double x = number(src, e, attr);
  if (x <= 0) fail(src, e, std::string("'") + attr + "' must be positive");
  return x;
}

SupportMotion parseMotion(const XmlSource& src, const TiXmlElement* support) {
  SupportMotion motion = StaticMotion{};
  int count = 0;
  for (const TiXmlElement* m = support->FirstChildElement(); m; m = m->NextSiblingElement()) {
    const std::string tag = m->Value();
    ++count;
    if (count > 1) fail(src, m, "a support has at most one motion element");
    if (tag == "turntable") {
      allowOnly(src, m, {"rate", "axis", "center"});
      motion = turntable(vec3(src, m, "center", Vec3::Zero()),
                         unitVector(src, m, "axis", Vec3::UnitZ()), number(src, m, "rate"));
    } else if (tag == "conveyor") {
      allowOnly(src, m, {"velocity"});
      motion = conveyor(vec3(src, m, "velocity"));
    } else if (tag == "twist") {
      allowOnly(src, m, {"angular", "linear"});
      ConstantTwistMotion t;
      // Read both before the comma initializer: a throw inside it would
      // leave Eigen's initializer half-filled (an assertion in debug builds).
      const Vec3 w = vec3(src, m, "angular", Vec3::Zero()), u = vec3(src, m, "linear", Vec3::Zero());
      t.twist << w, u;
      motion = t;
    } else if (tag == "tilt") {
      allowOnly(src, m, {"axis", "point", "amplitude", "frequency", "phase"});
      SinusoidalTiltMotion t;
      t.point = vec3(src, m, "point", Vec3::Zero());
      t.axis = unitVector(src, m, "axis", Vec3::UnitX());
      t.amplitude = number(src, m, "amplitude");
      t.frequency = number(src, m, "frequency");
      t.phase = number(src, m, "phase", 0.0);
      motion = t;
    } else {
      fail(src, m, "unknown support motion <" + tag + "> (known: turntable, conveyor, twist, tilt)");
    }
  }
  return motion;
}

SupportDecl parseSupport(const XmlSource& src, const TiXmlElement* e, const std::string& base_dir,
                         const LoadOptions& options, std::vector<std::string>& warnings) {
  SupportDecl d;
  d.element = e;
  d.name = text(src, e, "name");
  if (d.name.empty()) fail(src, e, "empty support name");
  const std::string type = text(e, "type", "plane");
  d.support.name = d.name;
  if (type == "plane") {
    allowOnly(src, e, {"name", "type", "normal", "offset", "point"});
    Plane p;
    p.normal = unitVector(src, e, "normal", Vec3::UnitZ());
    if (has(e, "point") && has(e, "offset"))
      fail(src, e, "give either 'point' or 'offset', not both");
    p.point = has(e, "point") ? vec3(src, e, "point") : number(src, e, "offset", 0.0) * p.normal;
    d.support.surface = p;
  } else if (type == "bowl" || type == "sphere") {
    allowOnly(src, e, {"name", "type", "center", "radius"});
    SphereSurface s;
    s.centre = vec3(src, e, "center", Vec3::Zero());
    s.radius = positive(src, e, "radius");
    s.side = type == "bowl" ? SphereSurface::Side::Inside : SphereSurface::Side::Outside;
    d.support.surface = s;
  } else if (type == "terrain") {
    allowOnly(src, e, {"name", "type", "filename", "scale"});
    d.terrain = true;
    const std::string uri = text(src, e, "filename");
    const Vec3 scale = vec3(src, e, "scale", Vec3::Ones());
    if (const std::string note = packageUriNote(uri); !note.empty()) warnings.push_back(located(src, e, note));
    try {
      d.terrain_path = resolveMeshPath(uri, base_dir, options);
      d.terrain_mesh = std::make_shared<const TriangleMesh>(loadMesh(d.terrain_path, scale));
    } catch (const SceneError& err) {
      fail(src, e, err.what());
    }
  } else {
    fail(src, e, "unknown support type '" + type + "' (known: plane, bowl, sphere, terrain)");
  }
  d.support.motion = parseMotion(src, e);
  if (d.terrain && isMoving(d.support.motion)) fail(src, e, "a terrain cannot move");
  return d;
}

ContactKind parseKind(const XmlSource& src, const TiXmlElement* e) {
  try {
    return contactKindFromString(text(e, "kind", "rolling"));
  } catch (const std::invalid_argument& err) {
    fail(src, e, err.what());
  }
}

// A shape's attributes, read from the <contact> element (errors name file,
// line and attribute).
class XmlShapeParameters : public ShapeParameters {
 public:
  XmlShapeParameters(const XmlSource& src, const TiXmlElement* e) : src_(src), e_(e) {}
  bool has(const char* name) const override { return io::has(e_, name); }
  double number(const char* name) const override { return io::number(src_, e_, name); }
  Vec3 vector(const char* name) const override { return vec3(src_, e_, name); }
  Mat3 rotation(const char* name) const override { return rpyToMatrix(vec3(src_, e_, name)); }

 private:
  const XmlSource& src_;
  const TiXmlElement* e_;
};

// An explicit shape, in the link frame: `point="x y z"`, or `shape="name"`
// with the attributes shapeTable() lists for it.
std::optional<Shape> parseExplicitShape(const XmlSource& src, const TiXmlElement* e) {
  const bool has_shape = has(e, "shape"), has_point = has(e, "point");
  if (has_shape && has_point) fail(src, e, "give either 'shape' or 'point', not both");
  static const char* const kCommon[] = {"name",      "link",        "kind",      "support",
                                        "mu",        "direction",   "restitution", "unilateral",
                                        "mu_static", "mu_kinetic", "mu_spin",  "points",
                                        "creep_speed", "normal_stiffness", "normal_damping"};
  auto allow = [&](const std::vector<const char*>& extra) {
    for (const TiXmlAttribute* a = e->FirstAttribute(); a; a = a->Next()) {
      const std::string n = a->Name();
      bool ok = false;
      for (const char* c : kCommon) ok = ok || n == c;
      for (const char* c : extra) ok = ok || n == c;
      if (!ok)
        fail(src, e, "attribute '" + n + "' does not apply to " +
                         (has_point ? std::string("a point contact")
                          : has_shape ? "shape=\"" + text(e, "shape", "") + "\""
                                      : std::string("a shape taken from the collision geometry")));
    }
  };
  if (has_point) {
    allow({"point"});
    return Shape{PointShape{vec3(src, e, "point")}};
  }
  if (!has_shape) {
    allow({"collision", "tyre_radius", "rim_points"});
    return std::nullopt;
  }
  const std::string name = text(src, e, "shape");
  if (name == kSoleShape) {  // the collision geometry as a sole (buildSceneContents)
    allow({"shape", "collision", "rim_points"});
    return std::nullopt;
  }
  const ShapeType* type = findShapeType(name);
  // A box, a solid cylinder or a mesh has no smooth contact point: it touches
  // with its vertices, and those come from the link's <collision> geometry.
  if (type && !type->make && type->role == ShapeRole::CollisionOnly)
    fail(src, e, "shape '" + name + "' is not declared in the <appell> block (" + type->cannot_roll +
                     "): a " + name +
                     " touches with its vertices, taken from the collision geometry of the link — give the link "
                     "<collision><geometry><" + name + " …/></geometry></collision> and write shape=\"" +
                     kSoleShape + "\" (collision=\"NAME\" picks one of several)");
  if (type && !type->make)
    fail(src, e, "shape '" + name + "' cannot carry a contact: " + type->cannot_roll);
  if (!type) fail(src, e, "unknown shape '" + name + "' (known: " + declarableShapeNames() + ")");
  std::vector<const char*> attributes = type->parameters;
  attributes.push_back("shape");
  allow(attributes);
  try {
    return type->make(XmlShapeParameters(src, e));
  } catch (const std::invalid_argument& err) {
    fail(src, e, err.what());
  }
}

ContactDecl parseContact(const XmlSource& src, const TiXmlElement* e) {
  ContactDecl d;
  d.element = e;
  ContactOptions& options = d.spec.options;
  options.name = text(src, e, "name");
  if (options.name.empty()) fail(src, e, "empty contact name");
  d.link = text(src, e, "link");
  d.support = text(src, e, "support");
  d.spec.kind = parseKind(src, e);
  const std::optional<Shape> shape = parseExplicitShape(src, e);
  d.explicit_shape = shape.has_value();
  d.sole = text(e, "shape", "") == kSoleShape;
  if (shape) d.spec.shape = *shape;
  const bool has_direction = has(e, "direction");
  if (has_direction) {
    options.blade_direction = vec3(src, e, "direction");
    if (options.blade_direction.norm() < 1e-12) fail(src, e, "knife edge 'direction' is a zero vector");
  }
  if (has(e, "tyre_radius") && !(shape && std::holds_alternative<Torus>(*shape))) {
    if (shape) fail(src, e, "'tyre_radius' applies to a cylinder collision or shape=\"torus\"");
    d.tyre_radius = positive(src, e, "tyre_radius");
  }
  d.collision = text(e, "collision", "");
  if (has(e, "rim_points")) {
    const double n = number(src, e, "rim_points");
    if (!(n >= 3 && n <= 256 && n == std::floor(n)))
      fail(src, e, "'rim_points' must be a whole number from 3 to 256 (vertices of each rim polygon)");
    if (d.tyre_radius > 0) fail(src, e, "give either 'tyre_radius' (a wheel) or 'rim_points' (a "
                                        "cylinder standing on a face), not both");
    d.rim_points = static_cast<int>(n);
  }
  if (has(e, "mu")) {
    d.spec.mu = number(src, e, "mu");
    if (d.spec.mu < 0) fail(src, e, "friction coefficient 'mu' must not be negative");
  }
  // Separate static and kinetic coefficients: both, instead of 'mu'.
  if (has(e, "mu_static") || has(e, "mu_kinetic")) {
    if (has(e, "mu")) fail(src, e, "give either 'mu' or 'mu_static' with 'mu_kinetic', not both");
    if (!has(e, "mu_static") || !has(e, "mu_kinetic"))
      fail(src, e, "'mu_static' and 'mu_kinetic' go together (one coefficient for both: 'mu')");
    d.spec.mu = number(src, e, "mu_static");
    d.spec.mu_kinetic = number(src, e, "mu_kinetic");
    if (!(d.spec.mu_kinetic >= 0))
      fail(src, e, "kinetic friction coefficient 'mu_kinetic' must not be negative");
    if (!(d.spec.mu_kinetic <= d.spec.mu))
      fail(src, e, "'mu_kinetic' must not exceed 'mu_static' (a contact that starts to slide "
                   "would hold harder than sticking could)");
  }
  if (has(e, "mu_spin")) {
    d.spec.mu_spin = number(src, e, "mu_spin");
    if (!(d.spec.mu_spin > 0))
      fail(src, e, "spin friction 'mu_spin' must be a positive length (m): the torque it holds per newton of load");
    if (d.spec.kind != ContactKind::RollingWithoutSpin)
      fail(src, e, "'mu_spin' needs kind=\"rolling_without_spin\" (a contact with a spin row)");
    if (!(d.spec.mu > 0 && std::isfinite(d.spec.mu)))
      fail(src, e, "'mu_spin' needs a finite 'mu' > 0 (the friction cone it shares)");
  }
  if (has(e, "creep_speed")) {
    d.spec.creep_speed = number(src, e, "creep_speed");
    if (!(d.spec.creep_speed > 0 && std::isfinite(d.spec.creep_speed)))
      fail(src, e, "'creep_speed' must be a positive slip speed (m/s): below it the friction "
                   "force grows linearly with the slip");
    if (!(d.spec.mu > 0 && std::isfinite(d.spec.mu)))
      fail(src, e, "'creep_speed' needs a finite 'mu' > 0 (the force it saturates at)");
    if (has(e, "mu_static"))
      fail(src, e, "'creep_speed' takes one coefficient 'mu', not 'mu_static' with "
                   "'mu_kinetic': a regularized contact never sticks");
  }
  if (has(e, "normal_stiffness") || has(e, "normal_damping")) {
    if (!has(e, "normal_stiffness"))
      fail(src, e, "'normal_damping' needs a 'normal_stiffness' (a damper alone does not hold "
                   "the contact)");
    d.spec.normal_stiffness = number(src, e, "normal_stiffness");
    if (!(d.spec.normal_stiffness > 0 && std::isfinite(d.spec.normal_stiffness)))
      fail(src, e, "'normal_stiffness' must be a positive stiffness (N/m)");
    if (has(e, "normal_damping")) {
      d.spec.normal_damping = number(src, e, "normal_damping");
      if (!(d.spec.normal_damping >= 0 && std::isfinite(d.spec.normal_damping)))
        fail(src, e, "'normal_damping' must be ≥ 0 (N·s/m)");
    }
    if (has(e, "restitution"))
      fail(src, e, "a compliant contact takes no 'restitution': its 'normal_damping' sets what "
                   "an impact keeps");
  }
  if (has(e, "restitution")) {
    d.spec.restitution = number(src, e, "restitution");
    if (!(d.spec.restitution >= 0 && d.spec.restitution <= 1))
      fail(src, e, "restitution must lie in [0, 1] (0: plastic, 1: elastic)");
  }
  if (has(e, "points")) {
    const double n = number(src, e, "points");
    if (!(n >= 1 && n <= 4 && n == std::floor(n)))
      fail(src, e, "'points' must be a whole number from 1 to 4 (places the body may touch a "
                   "terrain at once)");
    d.spec.points = static_cast<int>(n);
  }
  if (has(e, "unilateral")) {
    const std::string u = text(src, e, "unilateral");
    if (u != "true" && u != "false")
      fail(src, e, "'unilateral' must be \"true\" (the contact can lift off, the default) or "
                   "\"false\" (it always holds)");
    d.spec.unilateral = u == "true";
  }
  if (d.spec.kind == ContactKind::KnifeEdge && shape && shapeType(*shape).role == ShapeRole::Point &&
      !has_direction)
    fail(src, e, "a knife edge on a point needs a blade 'direction'");
  if (has_direction && d.spec.kind != ContactKind::KnifeEdge)
    fail(src, e, "'direction' is only meaningful for kind=\"" +
                     std::string(toString(ContactKind::KnifeEdge)) + "\"");
  return d;
}

JointStateDecl parseJointState(const XmlSource& src, const TiXmlElement* e) {
  allowOnly(src, e, {"name", "position", "velocity", "xyz", "rpy", "quat"});
  JointStateDecl d;
  d.element = e;
  d.joint = text(src, e, "name");
  if (has(e, "position")) d.position = numbers(src, e, "position");
  if (has(e, "velocity")) d.velocity = numbers(src, e, "velocity");
  if (has(e, "xyz")) d.xyz = vec3(src, e, "xyz");
  if (has(e, "rpy")) d.rpy = vec3(src, e, "rpy");
  if (has(e, "quat")) d.quat = numbers(src, e, "quat", 4);
  if (d.position && (d.xyz || d.rpy || d.quat))
    fail(src, e, "give either 'position' or 'xyz'/'rpy'/'quat', not both");
  if (d.rpy && d.quat) fail(src, e, "give either 'rpy' or 'quat', not both");
  return d;
}

// <actuator name="drive" joint="j" type="velocity" kv="2" setpoint="3"/>, or
// with <setpoint t="…" value="…"/> children for a schedule (docs/scene-format.md).
ActuatorDecl parseActuator(const XmlSource& src, const TiXmlElement* e) {
  allowOnly(src, e, {"name", "joint", "type", "kp", "kv", "effort_limit", "setpoint"});
  ActuatorDecl d;
  d.element = e;
  d.joint = text(src, e, "joint");
  Actuator& a = d.actuator;
  a.name = text(e, "name", d.joint);
  if (a.name.empty()) fail(src, e, "empty actuator name");
  const std::string type = text(src, e, "type");
  if (type == "position") a.type = ActuatorType::Position;
  else if (type == "velocity") a.type = ActuatorType::Velocity;
  else fail(src, e, "unknown actuator type '" + type + "' (known: position, velocity)");
  a.kp = number(src, e, "kp", 0.0);
  a.kv = number(src, e, "kv", 0.0);
  if (has(e, "effort_limit")) {
    a.effort_limit = positive(src, e, "effort_limit");
    d.own_limit = true;
  }
  const bool constant = has(e, "setpoint");
  if (constant) {
    a.setpoint.t = {0.0};
    a.setpoint.value = {number(src, e, "setpoint")};
  }
  for (const TiXmlElement* p = e->FirstChildElement(); p; p = p->NextSiblingElement()) {
    if (std::string(p->Value()) != "setpoint")
      fail(src, p, "unknown element in <actuator> (only <setpoint t value> is allowed)");
    if (constant) fail(src, p, "give the set-point either as the 'setpoint' attribute or as <setpoint> elements, not both");
    allowOnly(src, p, {"t", "value"});
    const double t = number(src, p, "t");
    if (!a.setpoint.t.empty() && !(t > a.setpoint.t.back()))
    {
      std::ostringstream m;
      m << "set-point time " << t << " does not come after the one before (" << a.setpoint.t.back()
        << "); times must increase";
      fail(src, p, m.str());
    }
    a.setpoint.t.push_back(t);
    a.setpoint.value.push_back(number(src, p, "value"));
  }
  if (a.setpoint.t.empty()) {  // hold position 0 / stand still
    a.setpoint.t = {0.0};
    a.setpoint.value = {0.0};
  }
  return d;
}

SimulationSettings parseSimulation(const XmlSource& src, const TiXmlElement* e) {
  allowOnly(src, e, {"integrator", "dt", "tol", "duration", "formulation", "snap_angles",
                     "balance_inertia", "bound_inertia", "bound_mass", "contacts"});
  SimulationSettings s;
  // The names are stored canonical ("multipliers" reads as "kkt").
  try {
    s.integrator = toString(integratorFromString(text(e, "integrator", s.integrator)));
    s.formulation = toString(formulationFromString(text(e, "formulation", s.formulation)));
    s.contacts = toString(contactSchemeFromString(text(e, "contacts", s.contacts)));
  } catch (const std::invalid_argument& err) {
    fail(src, e, err.what());
  }
  if (has(e, "dt")) s.dt = positive(src, e, "dt");
  if (has(e, "tol")) s.tol = positive(src, e, "tol");
  if (has(e, "duration")) s.duration = positive(src, e, "duration");
  if (has(e, "snap_angles")) {
    s.snap_angles = positive(src, e, "snap_angles");
    if (s.snap_angles > kMaxSnapAngle)
      fail(src, e, "snap_angles must be at most 0.05 rad: angles further from a multiple of "
                   "π/2 are design, not rounding");
  }
  return s;
}

// The inertia repairs of <simulation> (InertiaRepairs, model.hpp): a flag and
// two bounds ≥ 0 (kg m², kg).
InertiaRepairs parseInertiaRepairs(const XmlSource& src, const TiXmlElement* e) {
  InertiaRepairs r;
  const std::string balance = text(e, "balance_inertia", "false");
  if (balance != "true" && balance != "false") fail(src, e, "'balance_inertia' must be \"true\" or \"false\"");
  r.balance = balance == "true";
  for (auto [attr, bound] : {std::pair{"bound_inertia", &r.bound_inertia}, std::pair{"bound_mass", &r.bound_mass}}) {
    if (!has(e, attr)) continue;
    *bound = number(src, e, attr);
    if (*bound < 0) fail(src, e, std::string("'") + attr + "' must be ≥ 0 (a lower bound; 0: none)");
  }
  return r;
}

}  // namespace

AppellBlock parseAppellBlock(const XmlSource& src, const TiXmlElement* block, bool scene_file,
                             const std::string& base_dir, const LoadOptions& options) {
  AppellBlock b;
  b.element = block;
  if (!b.element) return b;
  if (scene_file) allowOnly(src, b.element, {"robot", "format"});
  else allowOnly(src, b.element, {"format"});
  if (has(b.element, "format")) {
    const std::string f = text(src, b.element, "format");
    if (f != "1" && f != "2")
      fail(src, b.element, "format \"" + f + "\" is not known: this loader reads format=\"1\" (scenes written "
                           "before the planar joint's axes changed) and format=\"2\" (the current one)");
    b.format = f == "1" ? 1 : 2;
  }
  std::set<std::string> supports, contacts;
  bool have_gravity = false, have_simulation = false;
  for (const TiXmlElement* e = b.element->FirstChildElement(); e; e = e->NextSiblingElement()) {
    const std::string tag = e->Value();
    if (tag == "gravity") {
      allowOnly(src, e, {"xyz"});
      if (have_gravity) fail(src, e, "gravity is given twice");
      have_gravity = true;
      b.gravity = vec3(src, e, "xyz");
    } else if (tag == "support") {
      SupportDecl d = parseSupport(src, e, base_dir, options, b.warnings);
      if (!supports.insert(d.name).second) fail(src, e, "support name '" + d.name + "' is used twice");
      b.supports.push_back(std::move(d));
    } else if (tag == "contact") {
      ContactDecl d = parseContact(src, e);
      if (!contacts.insert(d.spec.options.name).second)
        fail(src, e, "contact name '" + d.spec.options.name + "' is used twice");
      b.contacts.push_back(std::move(d));
    } else if (tag == "initial") {
      allowOnly(src, e, {});
      for (const TiXmlElement* j = e->FirstChildElement(); j; j = j->NextSiblingElement()) {
        if (std::string(j->Value()) != "joint")
          fail(src, j, "unknown element in <initial> (only <joint> is allowed)");
        b.initial.push_back(parseJointState(src, j));
      }
    } else if (tag == "effort") {
      allowOnly(src, e, {"joint", "value"});
      b.efforts.push_back({e, text(src, e, "joint"), numbers(src, e, "value")});
    } else if (tag == "actuator") {
      ActuatorDecl d = parseActuator(src, e);
      for (const ActuatorDecl& o : b.actuators)
        if (o.actuator.name == d.actuator.name)
          fail(src, e, "actuator name '" + d.actuator.name + "' is used twice");
      b.actuators.push_back(std::move(d));
    } else if (tag == "joint_limits") {
      allowOnly(src, e, {"enabled", "restitution"});
      if (b.limits_element) fail(src, e, "<joint_limits> is given twice");
      b.limits_element = e;
      const std::string en = text(e, "enabled", "true");
      if (en != "true" && en != "false") fail(src, e, "'enabled' must be \"true\" or \"false\"");
      b.limits_enabled = en == "true";
      if (has(e, "restitution")) {
        b.limits_restitution = number(src, e, "restitution");
        if (!(b.limits_restitution >= 0 && b.limits_restitution <= 1))
          fail(src, e, "restitution must lie in [0, 1] (0: plastic, 1: elastic)");
      }
    } else if (tag == "simulation") {
      if (have_simulation) fail(src, e, "<simulation> is given twice");
      have_simulation = true;
      b.settings = parseSimulation(src, e);
      b.repairs = parseInertiaRepairs(src, e);
    } else {
      fail(src, e, "unknown element <" + tag +
                       "> in <appell> (known: gravity, support, contact, initial, effort, actuator, joint_limits, simulation)");
    }
  }
  for (const ContactDecl& c : b.contacts)
    if (!supports.count(c.support))
      fail(src, c.element, "unknown support '" + c.support + "'");
  return b;
}

std::set<std::string> AppellBlock::collisionLinks() const {
  std::set<std::string> links;
  for (const ContactDecl& c : contacts)
    if (!c.explicit_shape) links.insert(c.link);
  return links;
}

}  // namespace appell::io
