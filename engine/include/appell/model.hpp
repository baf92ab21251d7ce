// The kinematic tree: bodies, joints, inertias. Immutable once built.
//
// Bodies are numbered 0 … nbodies−1 in topological order (parent < child);
// the world is −1. Body i's frame is the frame of the joint that connects it
// to its parent, after the joint's motion (the URDF convention):
//     pose of body i in its parent = placement[i] * jointTransform(q_i).
//
// Joint coordinates (nq) and velocities (nv), per joint type:
//   fixed       nq 0  nv 0
//   revolute,   nq 1  nv 1   angle / rate about `axis`
//   continuous  (revolute without position limits)
//   prismatic   nq 1  nv 1   displacement / rate along `axis`
//   planar      nq 3  nv 3   q = (a, b, φ): displacement along t₁, t₂ and the
//               angle about the normal `axis`;  v = (v₁, v₂, ω) in the BODY
//               frame, so q̇ ≠ v:  (ȧ, ḃ) = Rot(φ) (v₁, v₂),  φ̇ = ω.
//   floating    nq 7  nv 6   q = (p, quaternion x y z w);  v = (ω, v) in the BODY
//               frame (Featherstone order):  ṗ = R v,  quaternion: q̇ = ½ q ⊗ ω.
//   ball        nq 4  nv 3   q = quaternion x y z w;  v = ω in the BODY frame.
// Every motion subspace S is constant in the body frame, so Ṡ q̇ = 0 for all.
#pragma once

#include <appell/spatial.hpp>

#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace appell {

enum class JointType { Fixed, Revolute, Continuous, Prismatic, Planar, Floating, Ball };

const char* toString(JointType type);
int jointNq(JointType type);
int jointNv(JointType type);
/// Revolute, continuous and prismatic joints: one scalar coordinate (the joints
/// a mimic, a servo or a joint-space coupling can act on).
inline bool oneDofJoint(JointType type) { return jointNv(type) == 1; }

/// Position limits kept from the model description (not enforced by the
/// dynamics; reported and available to controllers and contact code).
struct JointLimits {
  double lower = -std::numeric_limits<double>::infinity();
  double upper = std::numeric_limits<double>::infinity();
  double velocity = std::numeric_limits<double>::infinity();
  double effort = std::numeric_limits<double>::infinity();
};

struct Joint {
  JointType type = JointType::Fixed;
  /// Unit axis in the joint frame: rotation axis (revolute), translation
  /// direction (prismatic), plane normal (planar). Unused otherwise.
  Vec3 axis = Vec3::UnitZ();
  int idx_q = 0, idx_v = 0, nq = 0, nv = 0;
  /// Motion subspace in the body frame (6 × nv), constant.
  Mat6X S;
  /// Planar joints: in-plane directions t₁, t₂ (with axis, right-handed).
  Vec3 t1 = Vec3::UnitX(), t2 = Vec3::UnitY();
  JointLimits limits;
};

struct Model {
  int nbodies = 0;
  int nq = 0;
  int nv = 0;
  std::vector<int> parent;          ///< parent body, −1 = world
  std::vector<SE3> placement;       ///< joint frame in the parent body's frame
  std::vector<Joint> joints;        ///< joint i connects body i to parent[i]
  std::vector<Inertia> inertias;    ///< body inertia in the body frame
  std::vector<Mat6> spatial_inertia;///< inertias[i].matrix(), cached
  /// The lower Cholesky factor of each spatial inertia (zero where it is not
  /// positive definite): a free body without children is its own
  /// articulated body, and ABA solves with this instead of factorising.
  std::vector<Mat6> spatial_inertia_factor;
  std::vector<std::string> body_names;
  std::vector<std::string> joint_names;
  std::vector<std::vector<int>> children;
  /// Body that velocity index k belongs to.
  std::vector<int> body_of_v;
  Vec3 gravity{0, 0, -9.81};

  int bodyIndex(const std::string& name) const;   ///< −1 if absent
  int jointIndex(const std::string& name) const;  ///< −1 if absent
  /// True when body `ancestor` lies on the path from `body` to the root (or is it).
  bool isAncestor(int ancestor, int body) const;
  double totalMass() const;
};

/// A body on a moving joint (or a root) with the bodies fixed to it: one
/// rigid body for the dynamics. URDF tools merge fixed-joint children into
/// their parent the same way (Pinocchio, KDL); here they stay bodies of the
/// tree (frames for geometry and contacts) and the validity of the mass
/// distribution is decided on the group.
struct RigidGroup {
  int body = -1;             ///< the moving body (its joint is not fixed)
  std::vector<int> fixed;    ///< bodies fixed to it (directly or through fixed joints), tree order
  Inertia inertia;           ///< combined inertia, in `body`'s frame
};
/// The groups of bodies that move together, one per body whose joint is not
/// fixed, in body order. Bodies fixed to the world belong to none. O(n).
std::vector<RigidGroup> rigidGroups(const Model& model);

/// Error in a model description: which element, and why.
struct ModelError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Opt-in repairs of inertias as CAD tools and robot vendors publish them,
/// with the semantics of MuJoCo's compiler options of the same names, applied
/// to each rigid group (a moving body with the bodies fixed to it, as MuJoCo
/// applies them after fusing static bodies) in this order:
///   bound_mass     a group's mass is raised to at least this (kg); the added
///                  mass sits at the group's centre of mass (at the body's
///                  origin when it had none);
///   bound_inertia  each principal moment about the group's centre of mass is
///                  raised to at least this (kg m²);
///   balance        when the principal moments I₁ ≤ I₂ ≤ I₃ break the triangle
///                  inequality, I₁ is raised to I₃ − I₂, keeping the axes and
///                  the two larger moments (MuJoCo's balanceinertia replaces
///                  all three by their mean instead: a larger change).
/// The correction is added to the moving body's own inertia; each repaired
/// group gets one note naming the body and what changed.
struct InertiaRepairs {
  bool balance = false;
  double bound_inertia = 0;
  double bound_mass = 0;
  bool any() const { return balance || bound_inertia > 0 || bound_mass > 0; }
};

/// Builds a Model body by body. `build()` validates everything and throws
/// ModelError naming the body and the reason for what the dynamics cannot
/// run: non-finite numbers, a negative mass, a zero axis, a rotational
/// inertia that is not symmetric or has a negative principal moment beyond
/// round-off, and a joint whose articulated inertia along its motion
/// (D = Sᵀ Iᴬ S, Featherstone 2008, §7.3) is singular — the mass matrix would
/// be. Inertias the dynamics can run although no mass distribution has them —
/// principal moments that break the triangle inequality (CAD rounding), a
/// massless or singular group carried by bodies that give its joint full
/// rank (a near-massless floating base) — load, with one note per group in
/// `notes`. A body on a fixed joint may be massless or degenerate (a point
/// mass, a sensor frame): only its rigid group (rigidGroups) is judged.
class ModelBuilder {
 public:
  /// Adds a body attached to `parent` (−1 = world) by `joint`, whose frame sits
  /// at `placement` in the parent's frame. Returns the new body's index.
  int addBody(const std::string& name, int parent, const SE3& placement, JointType type,
              const Vec3& axis, const Inertia& inertia, const std::string& joint_name = "",
              const JointLimits& limits = {});
  void setGravity(const Vec3& g) { gravity_ = g; }
  void setInertiaRepairs(const InertiaRepairs& r) { repairs_ = r; }
  /// The model; when `notes` is given, one line per rigid group loaded with a
  /// defect or repaired, "body 'NAME': …" (appended).
  Model build(std::vector<std::string>* notes = nullptr) const;

 private:
  struct Entry {
    std::string name, joint_name;
    int parent;
    SE3 placement;
    JointType type;
    Vec3 axis;
    Inertia inertia;
    JointLimits limits;
  };
  std::vector<Entry> entries_;
  Vec3 gravity_{0, 0, -9.81};
  InertiaRepairs repairs_;
};

}  // namespace appell
