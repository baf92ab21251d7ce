// Contact shapes, described in the BODY frame of the body that carries them.
//
// Rolling shapes are smooth and convex where they touch, so the contact point
// is a function of the contact normal: a body point y with outward unit normal
// m is y = σ(m), the inverse Gauss map. Its derivative Σ(m) = dσ/dm (3×3,
// symmetric, Σ m = 0) holds the principal radii of curvature on the tangent
// plane; the exact acceleration terms of every contact need it.
//
//   Point         σ = c                      Σ = 0            (knife edges, sliding feet)
//   Sphere        σ = c + ρ m                Σ = ρ (1 − m mᵀ)
//   SphericalCap  the sphere, valid where the angle between m and the cap axis
//                 is ≤ the half-angle (a hemisphere: π/2); elsewhere the body
//                 would touch on its rim or flat face — reported as singular.
//   Ellipsoid     σ = c + Q m / √(mᵀQm),     Q = E diag(a², b², c²) Eᵀ
//   Torus         σ = c + R u + r m,  u = P m/|P m|,  P = 1 − a aᵀ (outer, convex part)
//   Disk          a torus with tube radius 0: its rim.
// Box, Cylinder and Mesh are collision-only: they have edges or facets, no
// unique smooth contact point, so they cannot carry a rolling contact.
//
// Every alternative of `Shape` has one entry in shapeTable() (its names, role
// and scene-file parameters) and one handler in each visit of shapes.cpp —
// the visits have no catch-all, so a new alternative makes the compiler name
// each place to handle (docs/contacts.md, "Adding a rolling shape").
#pragma once

#include <appell/spatial.hpp>

#include <array>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace appell {

/// A single body point (radius-0 sphere): blade points, sleigh feet.
struct PointShape {
  Vec3 position = Vec3::Zero();
};

struct Sphere {
  double radius = 0;
  Vec3 centre = Vec3::Zero();
};

/// Semi-axes (a, b, c) along the columns of `orientation` (body ← ellipsoid axes).
struct Ellipsoid {
  Vec3 semi_axes = Vec3::Ones();
  Vec3 centre = Vec3::Zero();
  Mat3 orientation = Mat3::Identity();
};

/// Thin disk rolling on its rim: rim radius, centre, unit axis (normal of the disk).
struct Disk {
  double radius = 0;
  Vec3 centre = Vec3::Zero();
  Vec3 axis = Vec3::UnitZ();
};

/// Torus (a wheel with a tyre): `major` is the radius of the tube's centre
/// circle, `minor` the tube (tyre) radius; `axis` is the wheel axle.
struct Torus {
  double major = 0;
  double minor = 0;
  Vec3 centre = Vec3::Zero();
  Vec3 axis = Vec3::UnitZ();
};

/// The part of a sphere within `half_angle` of `axis` (from the sphere centre
/// toward the cap's pole). A hemisphere has half_angle = π/2.
struct SphericalCap {
  double radius = 0;
  Vec3 centre = Vec3::Zero();
  Vec3 axis = -Vec3::UnitZ();
  double half_angle = 1.5707963267948966;
};

/// Collision-only shapes (FCL handles them; they cannot roll).
struct Box {
  Vec3 half_extents = Vec3::Ones();
  SE3 pose;
};
struct Cylinder {
  double radius = 0;
  double length = 0;
  SE3 pose;  ///< cylinder axis = pose.R z-axis
};
struct Mesh {
  std::string file;
  Vec3 scale = Vec3::Ones();
  SE3 pose;
  /// The triangles in the mesh frame, scaled (filled by the loader; empty
  /// when the file was not read). FCL's geometry and the vertex contacts of
  /// a non-smooth contact (vertex_contacts.hpp) need them.
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;
};

using Shape = std::variant<PointShape, Sphere, Ellipsoid, Disk, Torus, SphericalCap, Box, Cylinder,
                           Mesh>;

/// What a shape can carry.
enum class ShapeRole {
  Rolling,        ///< smooth and convex where it touches: every contact kind it has a blade for
  Point,          ///< a body point: knife edges (with a blade direction) and sliding feet
  CollisionOnly,  ///< edges or facets, no unique smooth contact point: no contact at all
};

/// The attributes a scene file gives for a shape, by name (io reads them from
/// the XML element and names file, line and attribute in its errors).
class ShapeParameters {
 public:
  virtual ~ShapeParameters() = default;
  virtual bool has(const char* name) const = 0;
  virtual double number(const char* name) const = 0;  ///< required
  virtual Vec3 vector(const char* name) const = 0;    ///< required, three numbers
  /// Required roll-pitch-yaw angles (URDF convention) as a rotation matrix.
  virtual Mat3 rotation(const char* name) const = 0;
};

/// One alternative of `Shape`: its names, what it is, what it can carry and
/// how a scene file declares it (`<contact shape="name" …/>`).
struct ShapeType {
  const char* name;                   ///< canonical, as in a scene file: "sphere", "cap", …
  std::vector<const char*> aliases;   ///< other scene-file spellings ("hemisphere")
  const char* description;
  ShapeRole role;
  /// Not rolling: why, and what to use instead.
  const char* cannot_roll;
  /// Attributes of `shape="name"`; empty when a scene file cannot declare it.
  std::vector<const char*> parameters;
  /// Those attributes with example values, as written in a scene file (docs, tests).
  const char* example;
  /// Builds the shape from those attributes (null when not declarable). Throws
  /// std::invalid_argument naming the attribute; validateShape() still applies.
  Shape (*make)(const ShapeParameters&);
};

/// One entry per alternative, in the variant's order (entry k describes
/// alternative k): the one list of shape names.
std::span<const ShapeType> shapeTable();
/// The entry of the alternative held.
const ShapeType& shapeType(const Shape& shape);
/// The entry `text` names (canonical name or alias, '-' = '_'), or nullptr.
const ShapeType* findShapeType(std::string_view text);
/// "sphere, ellipsoid, …": the canonical names of the rolling shapes.
std::string rollingShapeNames();
/// Every name and alias `shape="…"` accepts in a scene file (the entries with
/// a `make`), for error messages: "sphere, …, cap (hemisphere, spherical_cap), …".
std::string declarableShapeNames();

/// Canonical name of the alternative held ("sphere", "box", …).
const char* shapeName(const Shape& shape);

/// True when the shape can carry a rolling contact; otherwise `why` (when not
/// null) says why and what to use instead.
bool canRoll(const Shape& shape, std::string* why = nullptr);

/// True for shapes the exact contact geometry handles (rolling shapes and points).
bool isSmoothContactShape(const Shape& shape);

/// The wheel axle of a disk or torus (its wheel plane is a knife edge's
/// blade), nullptr for every other shape.
const Vec3* wheelAxis(const Shape& shape);

/// Throws std::invalid_argument naming the shape and the bad parameter
/// (non-positive or non-finite radius, zero axis, non-orthonormal orientation,
/// half-angle outside (0, π], …).
void validateShape(const Shape& shape);

/// Inverse Gauss map of a smooth contact shape at the unit outward normal m
/// (body frame): the surface point y = σ(m) and Σ = dσ/dm.
struct GaussPoint {
  Vec3 y = Vec3::Zero();
  Mat3 Sigma = Mat3::Zero();
  bool singular = false;
  const char* reason = nullptr;  ///< static text, set when singular
  /// How far from singular (1: no singular limit near): for a disk or torus
  /// |P m| — the sine of the angle between the normal and the wheel axis,
  /// → 0 as the wheel lies flat and the rim's curvature radius R/|P m| blows up.
  double margin = 1;
};
/// `tol` bounds |P m| for disks and tori (below it the wheel lies flat:
/// every rim point has normal m) and the slack on a cap's edge.
GaussPoint inverseGaussMap(const Shape& shape, const Vec3& m, double tol = 1e-9);

/// True when the shape can roll inside a spherical bowl of radius R with a
/// unique contact point; otherwise `why` says which size condition fails.
/// Sphere and cap: ρ < R. Ellipsoid: its largest radius of curvature
/// a_max²/a_min < R (Blaschke's rolling theorem: a convex body whose radii of
/// curvature are all below R touches an enclosing sphere of radius R in one
/// point). Disk: rim radius < R. Torus: tube r < R and major + minor < R
/// (the farthest point of the tube's centre circle from the bowl centre is
/// unique, so only the sizes matter).
bool fitsInBowl(const Shape& shape, double bowl_radius, std::string* why = nullptr);

}  // namespace appell
