// From the <appell> declarations to supports, contact constraints, the
// initial state and the efforts, against the built model.
#include "scene/block.hpp"

#include <appell/configuration.hpp>
#include <appell/vertex_contacts.hpp>
#include <appell/wheel_fit.hpp>

#include <cmath>
#include <sstream>

namespace appell::io {

namespace {

std::string geometryLabel(int k, const Geometry& g) {
  return "collision[" + std::to_string(k) + "] (" + toString(g.type) +
         (g.name.empty() ? "" : " '" + g.name + "'") + ")";
}

// A cylinder collision on a wheel is its rim: a thin disk in the cylinder's
// mid-plane (or a torus whose outer radius is the cylinder's when the contact
// gives a tyre radius); with `rim_points` it is a cylinder standing on a face,
// touching with its rim polygons. A sphere is itself. Boxes and meshes touch
// with their vertices (vertex_contacts.hpp).
// A rolling (or knife-edge) contact on a mesh wheel: the smooth shape fitted
// about the wheel joint's axle (wheel_fit.hpp), said in `label` — if the mesh
// is round enough to be a wheel (isWheel); a foot's mesh about its ankle is
// not, and the error says to declare it as a sole.
Shape fittedWheel(const XmlSource& src, const ContactDecl& c, const Geometry& g, const Joint& joint,
                  std::string& label) {
  std::vector<Vec3> link_frame(g.mesh->vertices.size());
  for (std::size_t k = 0; k < link_frame.size(); ++k) link_frame[k] = g.origin.R * g.mesh->vertices[k] + g.origin.p;
  WheelFit f;
  try {
    f = fitWheel(link_frame, Vec3::Zero(), joint.axis);
  } catch (const std::invalid_argument& e) {
    fail(src, c.element, label + ": " + e.what());
  }
  std::ostringstream s;
  s << label << ", fitted " << (f.torus ? "torus" : "disk") << " about the joint axle: radius "
    << f.outer_radius;
  if (f.torus) s << ", tyre radius " << f.tube_radius;
  s << ", largest deviation " << f.max_deviation << " over " << f.tread_vertices
    << " tread vertices, runout " << f.runout;
  if (!isWheel(f)) {
    std::ostringstream why;
    why << s.str() << ": not a wheel — the runout of a wheel";
    if (f.torus) why << " and tread deviation";
    why << " stay within " << 100 * kWheelTolerance << " % of its radius (" << kWheelTolerance * f.outer_radius
        << "). A foot or a sole: write shape=\"" << kSoleShape
        << "\" (it touches with its hull vertices); a wheel: give its shape, e.g. shape=\"disk\" radius=\"…\" "
           "axis=\"…\"";
    fail(src, c.element, why.str());
  }
  label = s.str();
  return f.shape;
}

// shape="collision": the geometry as a sole — a box's corners, a mesh's hull
// vertices, a cylinder standing on an end (its rims as polygons), a sphere
// as itself; never a fitted wheel.
Shape soleShape(const XmlSource& src, const ContactDecl& c, const Geometry& g, const std::string& label) {
  if (c.rim_points > 0 && g.type != GeometryType::Cylinder)
    fail(src, c.element, "'rim_points' applies to a cylinder collision, not " + label);
  switch (g.type) {
    case GeometryType::Sphere: return Sphere{g.radius, g.origin.p};
    case GeometryType::Cylinder: return Cylinder{g.radius, g.length, g.origin};
    case GeometryType::Box: return Box{0.5 * g.box_size, g.origin};
    case GeometryType::Mesh:
      if (!g.mesh) fail(src, c.element, label + ": the mesh '" + g.mesh_path + "' was not loaded");
      return Mesh{g.mesh_path, g.mesh_scale, g.origin, g.mesh->vertices, g.mesh->triangles};
  }
  fail(src, c.element, label + ": unknown geometry type");
}

bool rollsOnAWheel(ContactKind kind) { return kind != ContactKind::Sliding; }

Shape shapeOfGeometry(const XmlSource& src, const ContactDecl& c, const Geometry& g,
                      const Joint& joint, std::string& label) {
  const Vec3 axis = g.origin.R.col(2);
  if (c.rim_points > 0 && g.type != GeometryType::Cylinder)
    fail(src, c.element, "'rim_points' applies to a cylinder collision, not " + label);
  switch (g.type) {
    case GeometryType::Sphere:
      if (c.tyre_radius > 0) fail(src, c.element, "'tyre_radius' needs a cylinder, not " + label);
      return Sphere{g.radius, g.origin.p};
    case GeometryType::Cylinder:
      if (c.rim_points > 0) return Cylinder{g.radius, g.length, g.origin};
      if (c.tyre_radius > 0) {
        if (c.tyre_radius >= g.radius)
          fail(src, c.element, "'tyre_radius' must be smaller than the cylinder radius " +
                                   std::to_string(g.radius) + " of " + label);
        return Torus{g.radius - c.tyre_radius, c.tyre_radius, g.origin.p, axis};
      }
      return Disk{g.radius, g.origin.p, axis};
    case GeometryType::Box:
      if (c.tyre_radius > 0) fail(src, c.element, "'tyre_radius' needs a cylinder, not " + label);
      return Box{0.5 * g.box_size, g.origin};
    case GeometryType::Mesh: {
      if (c.tyre_radius > 0) fail(src, c.element, "'tyre_radius' needs a cylinder, not " + label);
      if (!g.mesh) fail(src, c.element, label + ": the mesh '" + g.mesh_path + "' was not loaded");
      if (rollsOnAWheel(c.spec.kind) && c.rim_points == 0 &&
          (joint.type == JointType::Revolute || joint.type == JointType::Continuous))
        return fittedWheel(src, c, g, joint, label);
      Mesh m{g.mesh_path, g.mesh_scale, g.origin, g.mesh->vertices, g.mesh->triangles};
      return m;
    }
  }
  fail(src, c.element, label + ": unknown geometry type");
}

// Which of the link's collision geometries a contact takes: `collision=`
// (a name or an index); else, for a wheel, the first that can roll (or the
// first, whose error says why it cannot); for a sole, the only one.
int pickCollision(const XmlSource& src, const ContactDecl& c, const std::vector<Geometry>& col) {
  if (col.empty())
    fail(src, c.element, "link '" + c.link + "' has no collision geometry to take the contact "
                         "shape from; give 'shape' or 'point'");
  int pick = -1;
  if (!c.collision.empty()) {
    for (int k = 0; k < static_cast<int>(col.size()); ++k)
      if (col[k].name == c.collision) pick = k;
    if (pick < 0) {
      bool finite = false;
      const auto idx = parseNumber(c.collision, &finite);
      if (idx && finite && *idx >= 0 && *idx < static_cast<double>(col.size()) &&
          *idx == static_cast<int>(*idx))
        pick = static_cast<int>(*idx);
    }
    if (pick < 0)
      fail(src, c.element, "link '" + c.link + "' has no collision geometry named or numbered '" +
                               c.collision + "'");
  } else if (c.sole && col.size() > 1) {
    std::string list;
    for (int k = 0; k < static_cast<int>(col.size()); ++k)
      list += (k ? ", " : "") + geometryLabel(k, col[k]);
    fail(src, c.element, "link '" + c.link + "' has " + std::to_string(col.size()) +
                             " collision geometries: say which one is the sole with collision=\"NAME\" "
                             "or collision=\"INDEX\" (" + list + ")");
  } else {
    // The first geometry that can roll; if none can, the first one (whose
    // error says why it cannot).
    for (int k = 0; k < static_cast<int>(col.size()) && pick < 0; ++k)
      if (col[k].type == GeometryType::Sphere || col[k].type == GeometryType::Cylinder) pick = k;
    if (pick < 0) pick = 0;
  }
  return pick;
}

Shape contactShape(const XmlSource& src, const ContactDecl& c, const LinkGeometry& geo,
                   const Joint& joint, std::string& source) {
  if (c.explicit_shape) {
    if (!c.collision.empty()) fail(src, c.element, "give either 'collision' or an explicit shape, not both");
    source = "explicit";
    return c.spec.shape;
  }
  const int pick = pickCollision(src, c, geo.collision);
  const Geometry& g = geo.collision[pick];
  source = geometryLabel(pick, g);
  if (!c.sole) return shapeOfGeometry(src, c, g, joint, source);
  const Shape sole = soleShape(src, c, g, source);
  source += ", as a sole";
  return sole;
}

void setJointState(const XmlSource& src, const Model& model, const JointStateDecl& d, VecX& q,
                   VecX& v) {
  const int j = model.jointIndex(d.joint);
  if (j < 0) failUnknownName(src, d.element, "joint", d.joint, model.joint_names);
  const Joint& joint = model.joints[j];
  auto qs = q.segment(joint.idx_q, joint.nq);
  if (d.position) {
    if (static_cast<int>(d.position->size()) != joint.nq)
      fail(src, d.element, std::string("'position' needs ") + std::to_string(joint.nq) +
                               " numbers for a " + toString(joint.type) + " joint, got " +
                               std::to_string(d.position->size()));
    for (int k = 0; k < joint.nq; ++k) qs(k) = (*d.position)[k];
  }
  const bool floating = joint.type == JointType::Floating, ball = joint.type == JointType::Ball;
  if (d.xyz) {
    if (!floating) fail(src, d.element, "'xyz' applies to a floating joint only");
    qs.head<3>() = *d.xyz;
  }
  if (d.rpy || d.quat) {
    if (!floating && !ball) fail(src, d.element, "'rpy'/'quat' apply to floating and ball joints only");
    Quat qu;
    if (d.rpy) {
      qu = Quat(rpyToMatrix(*d.rpy));
    } else {
      const auto& c = *d.quat;
      qu = Quat(c[3], c[0], c[1], c[2]);
    }
    qs.tail<4>() << qu.x(), qu.y(), qu.z(), qu.w();
  }
  if (floating || ball) {
    auto quat = qs.tail<4>();
    if (quat.norm() < 1e-9) fail(src, d.element, "the orientation quaternion is zero");
    quat.normalize();
  }
  if (d.velocity) {
    if (static_cast<int>(d.velocity->size()) != joint.nv)
      fail(src, d.element, std::string("'velocity' needs ") + std::to_string(joint.nv) +
                               " numbers for a " + toString(joint.type) + " joint, got " +
                               std::to_string(d.velocity->size()));
    for (int k = 0; k < joint.nv; ++k) v(joint.idx_v + k) = (*d.velocity)[k];
  }
}

// A follower whose <initial> does not set it starts where its leader puts it,
// q_f = m q_l + o and v_f = m v_l, as ROS's joint_state_publisher places mimic
// joints. Leaders first: a chain settles in as many passes as it is long. A
// follower the block does set is left alone — if it contradicts its leader,
// the initial-state check names the coupling.
void followLeaders(const AppellBlock& block, Scene& scene) {
  const Model& model = scene.model;
  std::vector<bool> q_given(model.nbodies, false), v_given(model.nbodies, false);
  for (const JointStateDecl& d : block.initial) {
    const int j = model.jointIndex(d.joint);
    q_given[j] = q_given[j] || d.position.has_value();
    v_given[j] = v_given[j] || d.velocity.has_value();
  }
  for (std::size_t pass = 0; pass < scene.couplings.size(); ++pass) {
    for (const auto& c : scene.couplings) {
      const Joint& f = model.joints[c->follower()];
      const Joint& l = model.joints[c->leader()];
      if (!q_given[c->follower()])
        scene.q0[f.idx_q] = c->multiplier() * scene.q0[l.idx_q] + c->offset();
      if (!v_given[c->follower()]) scene.v0[f.idx_v] = c->multiplier() * scene.v0[l.idx_v];
    }
  }
}

}  // namespace

void buildSceneContents(const XmlSource& src, const UrdfRobot& urdf, const AppellBlock& block,
                        const LoadOptions& options, Scene& scene) {
  const Model& model = scene.model;
  for (const SupportDecl& d : block.supports) {
    Support support = d.support;
    try {
      // Checks the triangles (degenerate ones name their index) and builds the index.
      if (d.terrain)
        support.surface = makeTerrain(d.terrain_mesh->vertices, d.terrain_mesh->triangles);
      validateSupport(support);
    } catch (const std::invalid_argument& e) {
      fail(src, d.element,
           d.terrain ? std::string(e.what()) + " (in " + d.terrain_path + ")" : e.what());
    }
    scene.supports.push_back(std::move(support));
  }
  for (const ContactDecl& c : block.contacts) {
    ContactSpec spec = c.spec;
    spec.body = model.bodyIndex(c.link);
    if (spec.body < 0) failUnknownName(src, c.element, "link", c.link, model.body_names);
    for (const Support& s : scene.supports)
      if (s.name == c.support) spec.support = s;
    ContactOrigin origin;
    origin.line = c.element->Row();
    spec.shape = contactShape(src, c, scene.geometry[spec.body], model.joints[spec.body],
                              origin.shape_source);
    std::vector<std::shared_ptr<ShapeContact>> made;
    try {
      if (isSmoothContactShape(spec.shape))
        made = makeContactPoints(spec);
      else if (spec.points > 1)
        throw std::invalid_argument("contact '" + spec.options.name +
                                    "': 'points' applies to a smooth shape on a terrain; a " +
                                    shapeName(spec.shape) + " touches with its vertices");
      else {
        std::string reduced;
        made = makeVertexContacts(spec, c.rim_points > 0 ? c.rim_points : 16, &reduced);
        if (!reduced.empty())
          scene.warnings.push_back(where(src, c.element) + ": " + reduced);
      }
    } catch (const std::invalid_argument& e) {
      fail(src, c.element, std::string(e.what()) + " (shape: " + shapeName(spec.shape) + " from " +
                               origin.shape_source + ")");
    }
    if (!isSmoothContactShape(spec.shape)) {
      VertexGroup g;
      g.name = spec.options.name;
      g.body = spec.body;
      g.shape = spec.shape;
      for (int k = 0; k < static_cast<int>(scene.supports.size()); ++k)
        if (scene.supports[k].name == c.support) g.support = k;
      g.first = static_cast<int>(scene.contacts.size());
      g.count = static_cast<int>(made.size());
      scene.vertex_groups.push_back(std::move(g));
    }
    for (int k = 0; k < static_cast<int>(made.size()); ++k) {
      ContactOrigin o = origin;
      if (made.size() > 1)
        o.shape_source += (spec.points > 1 ? ", point " : ", vertex ") + std::to_string(k);
      scene.constraints.push_back(made[k]);
      scene.contacts.push_back(std::move(made[k]));
      scene.contact_origins.push_back(std::move(o));
    }
  }
  if (block.limits_enabled && options.joint_limits) {
    for (int j = 0; j < model.nbodies; ++j) {
      const Joint& joint = model.joints[j];
      if (joint.type != JointType::Revolute && joint.type != JointType::Prismatic) continue;
      for (LimitSide side : {LimitSide::Lower, LimitSide::Upper}) {
        const double bound = side == LimitSide::Lower ? joint.limits.lower : joint.limits.upper;
        if (!std::isfinite(bound)) continue;
        auto limit = std::make_shared<const JointLimit>(model, j, side, block.limits_restitution);
        scene.constraints.push_back(limit);
        scene.joint_limits.push_back(std::move(limit));
      }
    }
  }
  for (const std::string& name : urdf.joint_order) {
    const UrdfJoint& j = urdf.joints.at(name);
    if (!j.mimic) continue;
    try {
      auto coupling = std::make_shared<const JointCoupling>(
          model, model.jointIndex(name), model.jointIndex(j.mimic->joint), j.mimic->multiplier,
          j.mimic->offset);
      scene.constraints.push_back(coupling);
      scene.couplings.push_back(std::move(coupling));
    } catch (const std::invalid_argument& e) {
      fail(src, j.mimic->element, e.what());
    }
  }
  scene.q0 = neutralConfiguration(model);
  scene.v0 = VecX::Zero(model.nv);
  for (const JointStateDecl& d : block.initial) setJointState(src, model, d, scene.q0, scene.v0);
  followLeaders(block, scene);
  scene.tau = VecX::Zero(model.nv);
  for (const EffortDecl& e : block.efforts) {
    const int j = model.jointIndex(e.joint);
    if (j < 0) failUnknownName(src, e.element, "joint", e.joint, model.joint_names);
    const Joint& joint = model.joints[j];
    if (static_cast<int>(e.value.size()) != joint.nv)
      fail(src, e.element, std::string("'value' needs ") + std::to_string(joint.nv) +
                               " numbers for a " + toString(joint.type) + " joint, got " +
                               std::to_string(e.value.size()));
    for (int k = 0; k < joint.nv; ++k) scene.tau(joint.idx_v + k) += e.value[k];
  }
  for (const ActuatorDecl& d : block.actuators) {
    Actuator a = d.actuator;
    a.joint = model.jointIndex(d.joint);
    if (a.joint < 0) failUnknownName(src, d.element, "joint", d.joint, model.joint_names);
    // The URDF's <limit effort> bounds the servo unless it names its own.
    if (!d.own_limit && std::isfinite(model.joints[a.joint].limits.effort) &&
        model.joints[a.joint].limits.effort > 0)
      a.effort_limit = model.joints[a.joint].limits.effort;
    try {
      a.validate(model);
    } catch (const std::invalid_argument& e) {
      fail(src, d.element, e.what());
    }
    scene.actuators.push_back(std::move(a));
  }
  scene.settings = block.settings;
  applySceneFormat(src, block, scene);
}

}  // namespace appell::io
