// A loaded scene: the model, its contacts as constraints, the initial state,
// the geometry of every link and the default simulation settings.
//
// A Scene is what `loadScene` (urdf.hpp) returns from a URDF with an
// `<appell>` block (docs/scene-format.md). Everything in it is plain data: the
// engine, the solvers and the writers read it; nothing in it refers back to
// the file, except `source` for messages.
#pragma once

#include <appell/actuators.hpp>
#include <appell/constraint.hpp>
#include <appell/constraint_set.hpp>
#include <appell/contacts.hpp>
#include <appell/joint_coupling.hpp>
#include <appell/joint_limit.hpp>
#include <appell/model.hpp>
#include <appell/simulator.hpp>

#include <array>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace appell {

/// Error in a scene description. The message names the file, the element
/// (with its line when the XML parser gives one) and the reason, as
///   "robot.urdf:12: <joint name=\"j1\">: axis is zero".
struct SceneError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Triangles of a mesh, already scaled, in the mesh file's own frame.
struct TriangleMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;  ///< indices into `vertices`
  std::string source;                         ///< resolved file path
};

enum class GeometryType { Box, Cylinder, Sphere, Mesh };
const char* toString(GeometryType type);

/// One `<visual>` or `<collision>` element of a link.
struct Geometry {
  GeometryType type = GeometryType::Sphere;
  std::string name;               ///< the element's name attribute (may be empty)
  SE3 origin;                     ///< pose of the geometry in the link frame
  Vec3 box_size = Vec3::Zero();   ///< box: full edge lengths along x, y, z
  double radius = 0;              ///< sphere, cylinder
  double length = 0;              ///< cylinder: along its local z
  std::string mesh_uri;           ///< mesh: the filename as written
  std::string mesh_path;          ///< mesh: resolved absolute path
  Vec3 mesh_scale = Vec3::Ones(); ///< mesh: the scale applied to `mesh`
  std::shared_ptr<const TriangleMesh> mesh;  ///< mesh: triangles (scaled); null if not loaded
  /// Visual: the URDF `<material>` colour (r, g, b, a in [0, 1]) — the
  /// visual's own `<color rgba>`, else that of the robot-level material it
  /// names; none when the visual has no material or only a texture.
  std::optional<std::array<double, 4>> rgba;
};

/// Geometry of one link. Links map one-to-one to model bodies.
struct LinkGeometry {
  std::string link;
  int body = -1;
  std::vector<Geometry> visual;
  std::vector<Geometry> collision;
};

/// A link's collision geometry as contacts-module shapes in the body frame
/// (Box, Cylinder, Sphere, Mesh; collision detection, not rolling), in
/// document order.
std::vector<Shape> collisionShapes(const LinkGeometry& link);

/// Where a declared contact came from in the file. The contact itself —
/// kind, body, shape, support, blade, μ — is described once, by its
/// constraint (Scene::contacts[k]->spec()).
struct ContactOrigin {
  /// Where the shape came from: "explicit" or "collision[k] (<type>)".
  std::string shape_source;
  int line = 0;                   ///< line of the <contact> element
};

/// Defaults for running the scene; the command line may override them.
struct SimulationSettings {
  std::string integrator = "rk4";  ///< a canonical name of integratorTable()
  double dt = 1e-3;                ///< fixed step (and first step of adaptive methods)
  double tol = 1e-8;               ///< adaptive methods: relative tolerance
  double duration = 1.0;
  std::string formulation = "tree";  ///< a canonical name of formulationTable()
  /// Snap origin angles within this of a multiple of π/2 (rad; 0: no snap):
  /// LoadOptions::snap_angles, which overrides it when set.
  double snap_angles = 0;
  std::string contacts = "auto";     ///< a canonical name of contactSchemeTable()
};

/// The vertex contacts one <contact> on a box, mesh or standing cylinder
/// became (vertex_contacts.hpp): contacts[first, first + count).
struct VertexGroup {
  std::string name;   ///< the <contact>'s name
  int body = -1;
  Shape shape;        ///< the non-smooth shape, body frame
  int support = -1;   ///< index into Scene::supports
  int first = 0, count = 0;
};

struct Scene {
  Model model;
  /// One constraint per contact, in the order of `contacts`, then the joint
  /// limits, in the order of `joint_limits`, then the mimic couplings.
  ConstraintList constraints;
  /// The declared contacts in document order: the same objects as `constraints`
  /// (a contact's description is its spec(); the link is
  /// model.body_names[contact->bodyA()]).
  std::vector<std::shared_ptr<const ShapeContact>> contacts;
  std::vector<ContactOrigin> contact_origins;  ///< index-aligned with `contacts`
  std::vector<VertexGroup> vertex_groups;      ///< contacts that are a shape's vertices
  /// URDF <limit lower upper> of revolute and prismatic joints, one per finite
  /// side (joint_limit.hpp; off with LoadOptions::joint_limits = false): the
  /// same objects as constraints[contacts.size() …].
  std::vector<std::shared_ptr<const JointLimit>> joint_limits;
  /// URDF <mimic> couplings (joint_coupling.hpp), in document order of the
  /// following joints: the same objects as the constraints after the limits.
  std::vector<std::shared_ptr<const JointCoupling>> couplings;
  std::vector<Support> supports;
  VecX q0, v0;                     ///< initial state (nq, nv)
  VecX tau;                        ///< constant generalized forces (nv), from <effort>
  /// Servos from <actuator> (actuators.hpp), adding to `tau`; each one's
  /// effort limit is its own or its joint's URDF <limit effort>.
  std::vector<Actuator> actuators;
  SimulationSettings settings;
  std::vector<LinkGeometry> geometry;  ///< one per body, index = body
  std::string source;              ///< the file the scene was loaded from
  /// The robot description: `source` itself for a URDF; for a scene file (a
  /// top-level <appell robot="…">), the URDF its `robot` names, resolved.
  std::string robot_source;
  /// What the loader left out and why, "file:line: <element>: reason" (a
  /// visual mesh that is missing or unreadable); `appell` prints them.
  std::vector<std::string> warnings;

  /// The joint forces the scene declares — the constant efforts plus the
  /// actuators — as Simulator::setJointForces takes them (empty when the
  /// scene declares none). The function reads this scene's model: the scene
  /// must outlive it, as it must outlive a Simulator made on it.
  Simulator::JointForces jointForces() const;
  /// The constant efforts alone (empty when none): with
  /// Simulator::setActuators(actuators), what makeSimulator gives a simulator,
  /// so that its time-stepping takes the servos implicitly.
  Simulator::JointForces constantJointForces() const;
  /// Whether any joint force is declared (a driven scene: energy is not conserved).
  bool driven() const;

  /// Index of the contact with this name, −1 if absent.
  int contactIndex(const std::string& name) const;
  /// Total number of constraint rows.
  int constraintRows() const;
};

}  // namespace appell
