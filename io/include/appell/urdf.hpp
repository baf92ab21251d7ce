// Loading robots and scenes from URDF (+ meshes, + the `<appell>` block, in
// the URDF or in a scene file around it).
//
// The URDF conventions kept here (docs/scene-format.md has the details):
//  - Bodies are the URDF links in depth-first order from the root (parent
//    before child, children in document order). Every link becomes a body,
//    including massless links attached by fixed joints (the Model accepts
//    massless fixed attachments); no inertia is merged.
//  - A link named `world` is the world, not a body. A joint whose parent is
//    `world` attaches its child at the root: a fixed joint welds it, any other
//    joint type is that joint at the root. Without a `world` link, the root
//    link gets a floating joint named "root_joint".
//  - The inertial origin may rotate the inertia frame: the tensor is rotated
//    into the link frame, I_link = R I Rᵀ, and the centre of mass is its xyz.
//  - Joint limits are kept in Model::joints[i].limits (continuous joints keep
//    only effort and velocity limits).
//  - Mesh files are resolved relative to the URDF's folder, as absolute paths,
//    `file://` URIs, or `package://NAME/…` through the package search path
//    (`package:///NAME/…` is read as `package://NAME/…`, with a warning).
#pragma once

#include <appell/scene.hpp>

#include <optional>
#include <string>
#include <vector>

namespace appell {

struct LoadOptions {
  /// Folders searched for `package://NAME/…`, before ROS_PACKAGE_PATH.
  std::vector<std::string> package_paths;
  /// Also search the environment (after `package_paths`): ROS 1's
  /// ROS_PACKAGE_PATH (colon-separated folders holding packages, searched for
  /// a folder named as the package or a package.xml naming it) and ROS 2's
  /// AMENT_PREFIX_PATH (colon-separated install prefixes: <prefix>/share/<package>).
  bool use_ros_package_path = true;
  /// Read mesh files (visual and collision). When false, mesh geometry keeps
  /// its resolved path but no triangles, and a missing file a contact takes
  /// its shape from is still an error (other missing meshes are warnings).
  bool load_meshes = true;
  /// loadScene: check the initial state against the constraints (see
  /// checkInitialState) with this tolerance; project it instead of failing
  /// when `project_initial_state` is set.
  bool check_initial_state = true;
  bool project_initial_state = false;
  /// Enforce the URDF position limits of revolute and prismatic joints as
  /// unilateral constraints (Scene::joint_limits); false ignores them.
  bool joint_limits = true;
  double initial_state_tolerance = 1e-8;
  /// Opt-in snap of CAD rounding (rad; 0: the scene's <simulation
  /// snap_angles>, itself 0 by default: none): every roll, pitch and yaw of a
  /// joint's or a link's visual/collision <origin rpy> within this of a
  /// multiple of π/2 becomes that multiple exactly, each change reported in
  /// Scene::warnings (rpy="-1.57" is a wheel 7.96e-4 rad off its axle: a
  /// rigid model takes it literally). At most 0.05 rad.
  double snap_angles = 0;
  /// Repairs of inertias as published (InertiaRepairs, model.hpp; MuJoCo's
  /// balanceinertia, boundinertia, boundmass): each one set here overrides
  /// the scene's <simulation balance_inertia bound_inertia bound_mass>; left
  /// unset, the scene's applies (none by default). Every repaired body gets a
  /// line in Scene::warnings.
  std::optional<bool> balance_inertia;
  std::optional<double> bound_inertia, bound_mass;
};

/// Model only (links, joints, inertias, limits, gravity from the `<appell>`
/// block if present). `path` may be a scene file: the model of the
/// description it names, under its gravity. Throws SceneError.
Model loadUrdfModel(const std::string& path, const LoadOptions& options = {});

/// The whole scene, from a URDF (with its `<appell>` block, if any) or from a
/// scene file: a top-level `<appell robot="URI">` naming a description it
/// leaves as published (resolved as a mesh URI, relative paths from the
/// scene file's folder; docs/scene-format.md §3). Throws SceneError; never
/// returns a partial scene.
Scene loadScene(const std::string& path, const LoadOptions& options = {});

/// The same from a string; `base_dir` resolves relative mesh paths and
/// `name` is used in messages (e.g. "<string>").
Scene loadSceneFromString(const std::string& xml, const std::string& base_dir,
                          const std::string& name = "<string>",
                          const LoadOptions& options = {});

/// Resolves a mesh URI as the loader does: `package://NAME/rest` (also with
/// three slashes, `package:///NAME/rest`), `file://path`,
/// an absolute path, or a path relative to `base_dir`. Returns the absolute
/// path; throws SceneError (naming `uri` and every folder searched) when the
/// file does not exist.
std::string resolveMeshPath(const std::string& uri, const std::string& base_dir,
                            const LoadOptions& options = {});

/// Folder of package NAME: the first search-path entry E with E/NAME a folder,
/// else the first AMENT_PREFIX_PATH prefix P with P/share/NAME a folder, else
/// a folder under a search-path entry (E itself included, breadth-first up to
/// 6 levels, following symbolic links but entering each folder once, at most
/// 10⁵ folders in all) holding a package.xml whose <name> is NAME. Empty if none.
std::string findPackage(const std::string& name, const LoadOptions& options = {});

/// Reads a triangle mesh — STL (binary or ASCII), OBJ, PLY or Collada,
/// recognised by content, whatever the file's name — applies node transforms
/// and `scale`. Collada files keep their own up axis (the file's coordinates
/// are taken as they are, as ROS tools do) and their unit. Throws SceneError
/// naming the file for: a missing file, a directory or device, more than
/// 256 MiB, any other format, declared sizes the file cannot hold, a Collada
/// node graph too deep, cyclic or too large once expanded, polygons of more
/// than 1024 corners, a non-finite vertex (named), no triangles
/// (docs/hardening.md lists every bound).
TriangleMesh loadMesh(const std::string& path, const Vec3& scale = Vec3::Ones());

/// Result of checkInitialState.
struct InitialStateReport {
  double velocity_residual = 0;   ///< max |A v + b| over all rows
  double gap_residual = 0;        ///< max |g| over holonomic rows
  bool projected = false;         ///< q0/v0 were changed
  int iterations = 0;             ///< Newton steps of the position projection
  /// Closed contacts with finite μ that slip at (q0, v0) by more than CAD
  /// level (1e-6 of the largest velocity component, and more than `tol`): they
  /// start sliding (a ball thrown with backspin), so only their normal rows
  /// are checked. Slips below that are inconsistencies, checked as before.
  /// Empty when projecting: then every row is made to hold (the contact rolls).
  std::vector<std::string> sliding;
};

/// Checks that (q0, v0) satisfies every constraint: |A v + b| and the
/// holonomic gaps within `tol`. If not: with `project` false, throws
/// SceneError naming the worst contact, its row and the residual; with
/// `project` true, puts the state on the constraints with the engine's
/// projection (projectState, projection.hpp: Newton on the gaps with the
/// least-M-norm steps, then the impulse solve of the scene's formulation,
/// v ← v − M⁻¹Aᵀμ with A v + b = 0), then checks again and throws, naming
/// the worst contact and row, if that did not succeed.
InitialStateReport checkInitialState(Scene& scene, bool project, double tol = 1e-8);

}  // namespace appell
