// What readUrdf read → Model and link geometry: bodies in depth-first order,
// each link's parent joint (or the floating root joint), meshes resolved and
// read once per (path, scale).
#include "urdf/urdf_internal.hpp"

#include <map>
#include <set>

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

// One line for a tolerance met many times in a file (a package's every mesh
// URI written alike): the first place it was met, and how many more.
class WarningTally {
 public:
  explicit WarningTally(std::string more) : more_(std::move(more)) {}
  void add(std::string warning) {
    if (count_++ == 0) first_ = std::move(warning);
  }
  void appendTo(std::vector<std::string>& out) const {
    if (count_ == 0) return;
    out.push_back(count_ == 1 ? first_
                              : first_ + " (and " + std::to_string(count_ - 1) + " more " + more_ + ")");
  }

 private:
  std::string more_, first_;
  int count_ = 0;
};

// The geometry as read, with its mesh resolved (and loaded if asked);
// resolution errors name the <mesh> element, a URI form the loader
// tolerates is noted in `uri_notes`.
Geometry resolve(const XmlSource& src, const UrdfGeometry& in, const std::string& base_dir,
                 const LoadOptions& options, MeshCache& cache, WarningTally& uri_notes) {
  Geometry out = in.geometry;
  if (out.type != GeometryType::Mesh) return out;
  if (const std::string note = packageUriNote(out.mesh_uri); !note.empty())
    uri_notes.add(located(src, in.shape, note));
  try {
    out.mesh_path = resolveMeshPath(out.mesh_uri, base_dir, options);
    if (options.load_meshes) out.mesh = cache.get(out.mesh_path, out.mesh_scale);
  } catch (const SceneError& e) {
    fail(src, in.shape, e.what());
  }
  return out;
}

// A link's visual and collision geometry, resolved. A visual mesh only
// draws the link: one that cannot be found or read is left out with a
// warning (as RViz does). So is a collision mesh of a link no contact takes
// its shape from (`strict_collision` false): the dynamics never read it —
// urdfdom does not open mesh files at all, and a published package often
// ships without some of them. A collision mesh a contact uses stays an error.
LinkGeometry resolveLinkGeometry(const XmlSource& src, const UrdfLink& link, const std::string& base_dir,
                                 const LoadOptions& options, bool strict_collision, MeshCache& cache,
                                 WarningTally& uri_notes, std::vector<std::string>& warnings,
                                 WarningTally& unused_missing) {
  LinkGeometry geo;
  geo.link = link.name;
  for (const UrdfGeometry& v : link.visual) {
    try {
      geo.visual.push_back(resolve(src, v, base_dir, options, cache, uri_notes));
    } catch (const SceneError& e) {
      warnings.push_back(std::string(e.what()) + " — visual only: the link is not drawn with it");
    }
  }
  for (const UrdfGeometry& c : link.collision) {
    try {
      geo.collision.push_back(resolve(src, c, base_dir, options, cache, uri_notes));
    } catch (const SceneError& e) {
      if (strict_collision) throw;
      unused_missing.add(std::string(e.what()) + " — collision of link '" + link.name +
                         "', which no contact takes its shape from: left out");
    }
  }
  return geo;
}

}  // namespace

InertiaRepairs inertiaRepairs(const LoadOptions& options, const InertiaRepairs& scene) {
  InertiaRepairs r = scene;
  if (options.balance_inertia) r.balance = *options.balance_inertia;
  if (options.bound_inertia) r.bound_inertia = *options.bound_inertia;
  if (options.bound_mass) r.bound_mass = *options.bound_mass;
  return r;
}

Robot buildRobot(const XmlSource& src, const UrdfRobot& urdf, const std::string& base_dir,
                 const LoadOptions& options, const Vec3& gravity, const InertiaRepairs& repairs,
                 const std::set<std::string>& contact_links) {
  ModelBuilder builder;
  builder.setGravity(gravity);
  builder.setInertiaRepairs(repairs);
  std::map<std::string, int> body_of_link;
  Robot robot;
  robot.warnings = urdf.warnings;
  MeshCache cache;
  WarningTally uri_notes("mesh URIs like it"), unused_missing("collision meshes no contact uses");
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
    LinkGeometry geo = resolveLinkGeometry(src, link, base_dir, options, contact_links.count(name) > 0,
                                           cache, uri_notes, robot.warnings, unused_missing);
    geo.body = body_of_link[name];
    robot.geometry.push_back(std::move(geo));
  }
  uri_notes.appendTo(robot.warnings);
  unused_missing.appendTo(robot.warnings);
  std::vector<std::string> notes;
  try {
    robot.model = builder.build(&notes);
  } catch (const ModelError& e) {
    std::string msg = e.what();
    // ModelError names the body; the body is the link of the same name. A
    // link's own inertia is pointed at in its <inertia>; a group's combined
    // one (with fixed links merged) at the moving link.
    const bool own_inertia = msg.find("combined inertia") == std::string::npos &&
                             (msg.find("inertia tensor") != std::string::npos ||
                              msg.find("principal moments") != std::string::npos);
    for (const auto& [name, link] : urdf.links)
      if (msg.rfind("body '" + name + "'", 0) == 0)
        fail(src, own_inertia && link.inertia_element ? link.inertia_element : link.element, msg);
    fail(src, msg);
  }
  // Each note names its body ("body 'NAME': …"), the link of that name: the
  // warning points at the link, as the errors do.
  for (const std::string& note : notes) {
    std::string where = src.file;
    for (const auto& [name, link] : urdf.links)
      if (note.rfind("body '" + name + "'", 0) == 0 && link.element) {
        where += ":" + std::to_string(link.element->Row()) + ": " + describe(link.element);
        break;
      }
    robot.warnings.push_back(where + ": " + note);
  }
  return robot;
}

}  // namespace appell::io
