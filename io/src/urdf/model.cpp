// What readUrdf read → Model and link geometry: bodies in depth-first order,
// each link's parent joint (or the floating root joint), meshes resolved and
// read once per (path, scale).
#include "urdf/urdf_internal.hpp"

#include <map>

namespace appell::io {

namespace {

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

// The geometry as read, with its mesh resolved (and loaded if asked);
// resolution errors name the <mesh> element.
Geometry resolve(const XmlSource& src, const UrdfGeometry& in, const std::string& base_dir,
                 const LoadOptions& options, MeshCache& cache) {
  Geometry out = in.geometry;
  if (out.type != GeometryType::Mesh) return out;
  try {
    out.mesh_path = resolveMeshPath(out.mesh_uri, base_dir, options);
    if (options.load_meshes) out.mesh = cache.get(out.mesh_path, out.mesh_scale);
  } catch (const SceneError& e) {
    fail(src, in.shape, e.what());
  }
  return out;
}

}  // namespace

Robot buildRobot(const XmlSource& src, const UrdfRobot& urdf, const std::string& base_dir,
                 const LoadOptions& options, const Vec3& gravity) {
  ModelBuilder builder;
  builder.setGravity(gravity);
  std::map<std::string, int> body_of_link;
  Robot robot;
  robot.warnings = urdf.warnings;
  MeshCache cache;
  for (const std::string& name : urdf.body_order) {
    const UrdfLink& link = urdf.links.at(name);
    int parent = -1;
    SE3 placement;
    JointType type = JointType::Floating;
    Vec3 axis = Vec3::UnitZ();
    JointLimits limits;
    std::string joint_name = "root_joint";
    if (auto pj = urdf.parent_joint.find(name); pj != urdf.parent_joint.end()) {
      const UrdfJoint& joint = urdf.joints.at(pj->second);
      parent = joint.parent == "world" ? -1 : body_of_link.at(joint.parent);
      placement = joint.origin;
      type = joint.type;
      axis = joint.axis;
      limits = joint.limits;
      joint_name = joint.name;
    } else if (urdf.joints.count(joint_name)) {
      fail(src, urdf.joints.at(joint_name).element,
           "the floating base joint of root link '" + name +
               "' is named 'root_joint', and this joint already has that name");
    }
    try {
      body_of_link[name] =
          builder.addBody(name, parent, placement, type, axis, link.inertia, joint_name, limits);
    } catch (const ModelError& e) {
      fail(src, link.element, e.what());
    }
    LinkGeometry geo;
    geo.link = name;
    geo.body = body_of_link[name];
    // A visual mesh only draws the link: one that cannot be found or read
    // is left out with a warning (as RViz does), not an error; collision
    // meshes carry contacts and stay errors.
    for (const UrdfGeometry& v : link.visual) {
      try {
        geo.visual.push_back(resolve(src, v, base_dir, options, cache));
      } catch (const SceneError& e) {
        robot.warnings.push_back(std::string(e.what()) + " — visual only: the link is not drawn with it");
      }
    }
    for (const UrdfGeometry& c : link.collision)
      geo.collision.push_back(resolve(src, c, base_dir, options, cache));
    robot.geometry.push_back(std::move(geo));
  }
  try {
    robot.model = builder.build();
  } catch (const ModelError& e) {
    std::string msg = e.what();
    // ModelError names the body; the body is the link of the same name. A
    // link's own inertia is pointed at in its <inertia>; a group's combined
    // one (with fixed links merged) at the moving link.
    const bool own_inertia = msg.find("combined inertia") == std::string::npos &&
                             (msg.find("inertia") != std::string::npos ||
                              msg.find("principal moments") != std::string::npos);
    for (const auto& [name, link] : urdf.links)
      if (msg.rfind("body '" + name + "'", 0) == 0)
        fail(src, own_inertia && link.inertia_element ? link.inertia_element : link.element, msg);
    fail(src, msg);
  }
  return robot;
}

}  // namespace appell::io
