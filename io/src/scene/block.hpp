// The `<appell>` block of a URDF, read into declarations that do not yet
// know the model (gravity must be known before the model is built).
#pragma once

#include "urdf/urdf_internal.hpp"

#include <optional>

namespace appell::io {

struct SupportDecl {
  const TiXmlElement* element = nullptr;
  std::string name;
  bool terrain = false;            ///< a terrain mesh (buildSceneContents turns it into a TerrainMesh surface)
  Support support;                 ///< when !terrain
  std::shared_ptr<const TriangleMesh> terrain_mesh;
  std::string terrain_path;
};

struct ContactDecl {
  const TiXmlElement* element = nullptr;
  std::string link, support;       ///< names, resolved when the model is built
  /// kind, shape (when explicit) and options (name, blade direction, μ); the
  /// body and the support are filled in by buildSceneContents.
  ContactSpec spec;
  bool explicit_shape = false;     ///< `shape=` or `point=` given
  double tyre_radius = 0;          ///< > 0: a cylinder collision is a torus rim
  /// > 0: a cylinder collision touches with its two rims as polygons of this
  /// many vertices (standing on a face); 0: it is a wheel rim (disk or torus).
  int rim_points = 0;
  std::string collision;           ///< `collision=`: name or index of the geometry to use
  /// shape="collision": the collision geometry as it is — a box's corners, a
  /// mesh's hull vertices, a cylinder's rim polygons (standing on an end),
  /// never a fitted wheel (a foot's sole).
  bool sole = false;
};

/// The `shape` value that takes a contact's vertices from the link's collision geometry.
inline constexpr const char* kSoleShape = "collision";

struct JointStateDecl {
  const TiXmlElement* element = nullptr;
  std::string joint;
  std::optional<std::vector<double>> position, velocity;
  std::optional<Vec3> xyz, rpy;
  std::optional<std::vector<double>> quat;  ///< x y z w
};

struct EffortDecl {
  const TiXmlElement* element = nullptr;
  std::string joint;
  std::vector<double> value;
};

/// <actuator name joint type kp kv effort_limit setpoint> with optional
/// <setpoint t value> children (actuators.hpp); the joint is resolved and the
/// effort limit completed from the URDF when the scene is built.
struct ActuatorDecl {
  const TiXmlElement* element = nullptr;
  std::string joint;
  Actuator actuator;                ///< joint index and URDF limit not yet set
  bool own_limit = false;           ///< effort_limit given
};

/// The scene format this loader writes and reads by default (<appell format>).
/// 1: before the planar joint's in-plane axes became the joint frame's x, y
/// (commit 44be170; docs/scene-format.md, "Format versions"); 2: since.
inline constexpr int kSceneFormat = 2;

struct AppellBlock {
  const TiXmlElement* element = nullptr;  ///< null when the URDF has no <appell>
  int format = 0;                         ///< <appell format="N">; 0 when not given
  Vec3 gravity{0, 0, -9.81};
  std::vector<SupportDecl> supports;
  std::vector<ContactDecl> contacts;
  std::vector<JointStateDecl> initial;
  std::vector<EffortDecl> efforts;
  std::vector<ActuatorDecl> actuators;
  SimulationSettings settings;
  /// <simulation balance_inertia bound_inertia bound_mass>: the scene's
  /// inertia repairs (LoadOptions may override each).
  InertiaRepairs repairs;
  /// <joint_limits enabled="true|false" restitution="e"/>
  const TiXmlElement* limits_element = nullptr;
  bool limits_enabled = true;
  double limits_restitution = 0;
  /// What the block tolerated and how ("file:line: <element>: …").
  std::vector<std::string> warnings;

  /// The links whose collision geometry a contact takes its shape from
  /// (their collision meshes must load).
  std::set<std::string> collisionLinks() const;
};

/// Reads an <appell> element (null: an empty block): the block embedded in a
/// URDF, or the root of a scene file (`scene_file`: it also carries `robot`,
/// read by loadSceneFromString). `base_dir` resolves the block's own files
/// (terrain meshes). Throws SceneError.
AppellBlock parseAppellBlock(const XmlSource& src, const TiXmlElement* block, bool scene_file,
                             const std::string& base_dir, const LoadOptions& options);

/// Throws "unknown KIND 'NAME'" at `e`, saying which description was
/// searched when the block is a scene file's, and the closest of `names`
/// when it is a likely typo (unknown_name.cpp).
[[noreturn]] void failUnknownName(const XmlSource& src, const TiXmlElement* e, const std::string& kind,
                                  const std::string& name, const std::vector<std::string>& names);

/// Reads the scene in the format its block declares (format.cpp): format 1's
/// planar in-plane coordinates turned into the current axes; without a
/// format, a warning for each planar joint whose axes changed.
void applySceneFormat(const XmlSource& src, const AppellBlock& block, Scene& scene);

/// Turns the declarations into the scene's supports, contacts, constraints,
/// initial state and efforts, against the built model and link geometry.
void buildSceneContents(const XmlSource& src, const UrdfRobot& urdf, const AppellBlock& block,
                        const LoadOptions& options,
                        Scene& scene);

}  // namespace appell::io
