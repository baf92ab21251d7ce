// URDF → Model through urdfdom, after checkUrdf has validated the text.
#include "urdf/urdf_internal.hpp"

#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include <filesystem>
#include <map>
#include <mutex>

namespace appell::io {

namespace {

// urdfdom reports errors only through console_bridge; collect them so the
// SceneError can say what went wrong. console_bridge's handler is global,
// hence the lock.
class CollectErrors : public console_bridge::OutputHandler {
 public:
  std::string messages;
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR)
      messages += (messages.empty() ? "" : "; ") + text;
  }
};

urdf::ModelInterfaceSharedPtr parseWithUrdfdom(const XmlSource& src, const std::string& xml) {
  static std::mutex mutex;
  std::lock_guard<std::mutex> lock(mutex);
  CollectErrors errors;
  console_bridge::useOutputHandler(&errors);
  urdf::ModelInterfaceSharedPtr model;
  try {
    model = urdf::parseURDF(xml);
  } catch (const std::exception& e) {
    errors.messages += (errors.messages.empty() ? "" : "; ") + std::string(e.what());
  }
  console_bridge::restorePreviousOutputHandler();
  if (!model)
    fail(src, "urdfdom rejected the file: " +
                  (errors.messages.empty() ? std::string("no reason given") : errors.messages));
  return model;
}

SE3 toSE3(const urdf::Pose& pose) {
  const Quat q(pose.rotation.w, pose.rotation.x, pose.rotation.y, pose.rotation.z);
  SE3 X;
  X.R = q.normalized().toRotationMatrix();
  X.p = Vec3(pose.position.x, pose.position.y, pose.position.z);
  return X;
}

Inertia toInertia(const urdf::InertialSharedPtr& in) {
  Inertia I;
  if (!in) return I;  // a massless link (no <inertial>)
  const SE3 X = toSE3(in->origin);
  Mat3 J;
  J << in->ixx, in->ixy, in->ixz, in->ixy, in->iyy, in->iyz, in->ixz, in->iyz, in->izz;
  I.mass = in->mass;
  I.com = X.p;
  // The inertial frame may be rotated with respect to the link frame: the
  // tensor given in it is R J Rᵀ in the link frame (about the same point).
  I.inertia_com = X.R * J * X.R.transpose();
  I.inertia_com = 0.5 * (I.inertia_com + I.inertia_com.transpose());
  return I;
}

JointType toJointType(int urdf_type) {
  switch (urdf_type) {
    case urdf::Joint::REVOLUTE: return JointType::Revolute;
    case urdf::Joint::CONTINUOUS: return JointType::Continuous;
    case urdf::Joint::PRISMATIC: return JointType::Prismatic;
    case urdf::Joint::FLOATING: return JointType::Floating;
    case urdf::Joint::PLANAR: return JointType::Planar;
    case urdf::Joint::FIXED: return JointType::Fixed;
    default: break;
  }
  throw SceneError("unknown joint type");  // checkUrdf rejects these first
}

JointLimits toLimits(const urdf::Joint& j) {
  JointLimits L;
  if (!j.limits) return L;
  if (j.type != urdf::Joint::CONTINUOUS) {
    L.lower = j.limits->lower;
    L.upper = j.limits->upper;
  }
  L.effort = j.limits->effort;
  L.velocity = j.limits->velocity;
  return L;
}

// Meshes are read once per (path, scale) within a load.
class MeshCache {
 public:
  std::shared_ptr<const TriangleMesh> get(const std::string& path, const Vec3& scale) {
    const std::string key = path + "|" + std::to_string(scale.x()) + "," +
                            std::to_string(scale.y()) + "," + std::to_string(scale.z());
    auto it = cache_.find(key);
    if (it != cache_.end()) return it->second;
    auto mesh = std::make_shared<const TriangleMesh>(loadMesh(path, scale));
    cache_[key] = mesh;
    return mesh;
  }

 private:
  std::map<std::string, std::shared_ptr<const TriangleMesh>> cache_;
};

Geometry toGeometry(const XmlSource& src, const TiXmlElement* element, const std::string& name,
                    const urdf::Pose& pose, const urdf::GeometrySharedPtr& g,
                    const std::string& base_dir, const LoadOptions& options, MeshCache& cache) {
  Geometry out;
  out.name = name;
  out.origin = toSE3(pose);
  switch (g->type) {
    case urdf::Geometry::BOX: {
      const auto& b = static_cast<const urdf::Box&>(*g);
      out.type = GeometryType::Box;
      out.box_size = Vec3(b.dim.x, b.dim.y, b.dim.z);
      break;
    }
    case urdf::Geometry::CYLINDER: {
      const auto& c = static_cast<const urdf::Cylinder&>(*g);
      out.type = GeometryType::Cylinder;
      out.radius = c.radius;
      out.length = c.length;
      break;
    }
    case urdf::Geometry::SPHERE:
      out.type = GeometryType::Sphere;
      out.radius = static_cast<const urdf::Sphere&>(*g).radius;
      break;
    case urdf::Geometry::MESH: {
      const auto& m = static_cast<const urdf::Mesh&>(*g);
      out.type = GeometryType::Mesh;
      out.mesh_uri = m.filename;
      out.mesh_scale = Vec3(m.scale.x, m.scale.y, m.scale.z);
      const TiXmlElement* me = element->FirstChildElement("geometry")->FirstChildElement("mesh");
      try {
        out.mesh_path = resolveMeshPath(m.filename, base_dir, options);
        if (options.load_meshes) out.mesh = cache.get(out.mesh_path, out.mesh_scale);
      } catch (const SceneError& e) {
        fail(src, me, e.what());
      }
      break;
    }
  }
  return out;
}

}  // namespace

Robot buildRobot(const XmlSource& src, const UrdfIndex& ix, const std::string& xml,
                 const std::string& base_dir, const LoadOptions& options, const Vec3& gravity) {
  const urdf::ModelInterfaceSharedPtr urdf = parseWithUrdfdom(src, xml);
  ModelBuilder builder;
  builder.setGravity(gravity);
  std::map<std::string, int> body_of_link;
  Robot robot;
  MeshCache cache;
  for (const std::string& name : ix.body_order) {
    const urdf::LinkConstSharedPtr link = urdf->getLink(name);
    const TiXmlElement* le = ix.links.at(name);
    if (!link) fail(src, le, "urdfdom lost this link");
    int parent = -1;
    SE3 placement;
    JointType type = JointType::Floating;
    Vec3 axis = Vec3::UnitZ();
    JointLimits limits;
    std::string joint_name = "root_joint";
    if (auto pj = ix.parent_joint.find(name); pj != ix.parent_joint.end()) {
      const urdf::JointConstSharedPtr joint = urdf->getJoint(pj->second);
      if (!joint) fail(src, ix.joints.at(pj->second), "urdfdom lost this joint");
      parent = joint->parent_link_name == "world" ? -1 : body_of_link.at(joint->parent_link_name);
      placement = toSE3(joint->parent_to_joint_origin_transform);
      type = toJointType(joint->type);
      axis = Vec3(joint->axis.x, joint->axis.y, joint->axis.z);
      limits = toLimits(*joint);
      joint_name = joint->name;
    } else if (ix.joints.count(joint_name)) {
      fail(src, ix.joints.at(joint_name),
           "the floating base joint of root link '" + name +
               "' is named 'root_joint', and this joint already has that name");
    }
    try {
      body_of_link[name] = builder.addBody(name, parent, placement, type, axis,
                                           toInertia(link->inertial), joint_name, limits);
    } catch (const ModelError& e) {
      fail(src, le, e.what());
    }
    LinkGeometry geo;
    geo.link = name;
    geo.body = body_of_link[name];
    // urdfdom keeps the elements in document order, so the k-th array entry
    // is the k-th XML element (used for line numbers in messages).
    const TiXmlElement* ve = le->FirstChildElement("visual");
    for (const auto& v : link->visual_array) {
      geo.visual.push_back(
          toGeometry(src, ve, v->name, v->origin, v->geometry, base_dir, options, cache));
      ve = ve->NextSiblingElement("visual");
    }
    const TiXmlElement* ce = le->FirstChildElement("collision");
    for (const auto& c : link->collision_array) {
      geo.collision.push_back(
          toGeometry(src, ce, c->name, c->origin, c->geometry, base_dir, options, cache));
      ce = ce->NextSiblingElement("collision");
    }
    robot.geometry.push_back(std::move(geo));
  }
  try {
    robot.model = builder.build();
  } catch (const ModelError& e) {
    std::string msg = e.what();
    // ModelError names the body; the body is the link of the same name.
    for (const auto& [name, el] : ix.links)
      if (msg.rfind("body '" + name + "'", 0) == 0) fail(src, el, msg);
    fail(src, msg);
  }
  return robot;
}

}  // namespace appell::io
