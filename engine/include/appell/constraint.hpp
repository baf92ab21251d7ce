// Pfaffian constraints  A(q, t) v + b(q, t) = 0  and how solvers see them.
//
// A contact (or any constraint) produces up to 6 rows acting on one body, or
// on the relative motion of two bodies. Each row is a world-frame spatial
// covector w on the body's world-frame spatial velocity V = [ω; v_O] (v_O: the
// velocity of the body point now at the world origin, Featherstone's convention):
//      row value      wₐ·Vₐ − w_b·V_b + b = 0
//      acceleration   wₐ·aₐ − w_b·a_b + κ = 0,   a = dV/dt (spatial acceleration)
// κ carries every velocity-product term of the geometry (ẇ·V, ḃ): the contact
// layer knows the curvatures, the engine knows the tree. A point-velocity row
// tᵀ ṗ for a point x on the body is w = [x × t; t].
//
// Rows that are not naturally body-local (user-supplied rows over v, joint
// limits, mimic couplings) say jointSpace() and give A, b and Ȧv + ḃ over the
// generalized velocities — sparse: only over the columns jointColumns()
// names (a joint limit: one; a coupling: two), so a model with a limit on
// every joint stores O(n), not O(n²).
//
// Each row says what it means (RowKind): λ of a row with direction t is the
// force along t on the body, so the normal row carries the normal load and
// tangent and lateral rows the friction force; reports find rows by kind,
// never by their label.
#pragma once

#include <appell/data.hpp>

#include <array>
#include <limits>
#include <string>
#include <vector>

namespace appell {

using RowMatrix6 = Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor, 6, 6>;
using RowVector6 = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1>;

/// What a row constrains. Contact rows (contacts.hpp): the relative velocity
/// of the contact points along the normal, the two tangents or the knife
/// edge's lateral direction, or the relative spin about the normal. Custom:
/// anything else (user rows, joint-space rows).
enum class RowKind { Normal, Tangent1, Tangent2, Lateral, Spin, Custom };

/// "normal", "tangent1", "tangent2", "lateral", "spin", "custom": the row
/// labels of messages and of the CSV columns lambda:<constraint>.<label>.
const char* toString(RowKind kind);
/// Rows whose force lies in the contact's tangent plane (friction).
inline bool isTangential(RowKind kind) {
  return kind == RowKind::Tangent1 || kind == RowKind::Tangent2 || kind == RowKind::Lateral;
}

/// Geometric description of a contact at the current state, for reports.
struct ContactFrame {
  Vec3 point = Vec3::Zero();        ///< contact point, world
  Vec3 normal = Vec3::UnitZ();      ///< unit normal, world, from the support toward the body
  Vec3 t1 = Vec3::UnitX(), t2 = Vec3::UnitY();
  double gap = 0;                   ///< signed distance (negative: penetration)
  /// How far the geometry is from a singular configuration (1: none near;
  /// → 0 as e.g. a wheel lies flat): failures read it to name the cause.
  double margin = 1;
};

/// A contact on a piecewise support (a terrain's flat regions, edges and
/// vertices): the piece a block's rows are for, and the simulator's choice
/// of the pieces its search may take (docs/contacts.md §4).
struct TerrainPiece {
  /// The piece these rows are for (−1: a smooth support), written by the
  /// constraint's evaluation.
  int feature = -1;
  /// ≥ 0: the contact is evaluated on that piece, extended past its bounds,
  /// instead of the nearest one — the simulator keeps a closed contact on
  /// one piece between events.
  int latched = -1;
  /// A search's pieces to skip (the first `excluded_count`): the ones the
  /// other points of the same pair hold (Constraint::pointGroup). The search
  /// then takes only a separate piece — a second place the body touches.
  std::array<int, 3> excluded{-1, -1, -1};
  int excluded_count = 0;
};

/// What one constraint writes when evaluated. Capacity is fixed (≤ 6 body rows),
/// except the joint-space block, which is sized once by the constraint's setup.
struct RowBlock {
  int m = 0;                        ///< rows written
  RowMatrix6 Wa, Wb;                ///< m × 6, world-frame spatial covectors
  RowVector6 b, kappa;              ///< velocity and acceleration offsets
  RowVector6 gap;                   ///< holonomic gap per row (0 where not holonomic)
  /// jointSpace(): the velocity indices the rows act on (jointColumns(),
  /// set once by reserve) and the rows over them,
  ///     row r · v = Σₖ A_joint(r, k) v[joint_cols[k]].
  std::vector<int> joint_cols;
  MatX A_joint;                     ///< jointSpace(): m × joint_cols.size()
  VecX b_joint, abias_joint;        ///< jointSpace(): b and Ȧv + ḃ (size m)
  ContactFrame frame;
  /// A contact on a piecewise support: which piece its rows are for, and
  /// which pieces the search may take (TerrainPiece).
  TerrainPiece piece;
  bool singular = false;            ///< the geometry is singular here (rows unusable)
  std::string singular_reason;      ///< why, when singular (set only then)
};

/// The law of a unilateral contact, as data (docs/contacts.md §7–8): what
/// the simulator's impact and friction stages read, one struct for every
/// kind of contact (shape contacts, joint limits). A new field is one member
/// here, its check in the simulator's setup (simulator/unilateral_setup.cpp)
/// and the stage that reads it (docs/architecture.md).
struct ContactLaw {
  /// Coulomb's coefficient μ of the friction rows (tangent and lateral rows,
  /// isTangential()): while |λₜ| ≤ μ λₙ the contact sticks (all rows hold);
  /// beyond it slides — its friction rows are replaced by the force
  /// −μₖ λₙ ŝ against the slip direction (docs/contacts.md §8). ∞: never
  /// slides (ideal rolling).
  double mu = std::numeric_limits<double>::infinity();
  /// Coulomb's kinetic coefficient μₖ ≤ μ: a sliding contact's force is
  /// μₖ λₙ; μ is then the static one, the cone sticking stays in and a
  /// stopped slip must fit to stick again. Set it with mu (the same: one
  /// coefficient).
  double mu_kinetic = std::numeric_limits<double>::infinity();
  /// Torsional (spin) friction, a length ℓ: a sticking contact's spin row
  /// holds while its friction (λₜ, τₙ/(ℓ/μ)) stays in the cone μ λₙ — the
  /// torque alone up to ℓ λₙ — and a sliding one takes the maximally
  /// dissipating force and torque of that ellipsoid (docs/contacts.md §8).
  /// NaN: none (the spin row is ideal while sticking, free while sliding).
  double spin = std::numeric_limits<double>::quiet_NaN();
  /// Regularized Coulomb friction: a creep speed v_c > 0 (m/s). The contact
  /// then never sticks: while closed it always carries the friction force
  ///     f = −μₖ λₙ s / max(|s|, v_c)
  /// of its slip velocity s — viscous creep μₖλₙ/v_c below v_c, Coulomb's
  /// μₖλₙ above (Drake's "stiction tolerance"; a tyre's linear range before
  /// saturation) — so rows that ideal rolling would make nearly dependent
  /// (four tyres on uneven ground) are never constraints. 0: Coulomb with
  /// sticking (docs/contacts.md §8). Only read when mu is finite.
  double creep_speed = 0;
  /// Newton's coefficient of restitution on the unilateral row at an impact
  /// (0: plastic).
  double restitution = 0;
  /// A compliant normal (a tyre's or a sole's): stiffness k > 0 (N/m) and
  /// damping c ≥ 0 (N·s/m) of a Kelvin–Voigt element, λₙ = max(0, −k g − c ġ)
  /// at the gap g — taken at the end of each time-stepping step
  /// (timestepping/moreau_jean.cpp). 0: rigid (g ≥ 0 exactly).
  double normal_stiffness = 0;
  double normal_damping = 0;
  bool compliant() const { return normal_stiffness > 0; }
};

class Constraint {
 public:
  virtual ~Constraint() = default;
  virtual const std::string& name() const = 0;
  /// Number of rows (fixed for the constraint's lifetime).
  virtual int rows() const = 0;
  /// Body the rows act on, and the second body (−1: the world / none).
  virtual int bodyA() const = 0;
  virtual int bodyB() const { return -1; }
  /// What row k constrains.
  virtual RowKind rowKind(int k) const = 0;
  /// Label of row k for messages and CSV columns: toString(rowKind(k)), and
  /// "custom<k>" for Custom rows unless the constraint names them.
  virtual std::string rowLabel(int k) const;
  /// Row k is ġ for a gap g(q, t) — the position projection drives g to 0.
  virtual bool holonomic(int k) const = 0;
  /// Rows given over v (A_joint …) rather than as body covectors.
  virtual bool jointSpace() const { return false; }
  /// jointSpace(): the velocity indices its rows may involve (the columns
  /// of RowBlock::A_joint), fixed for the constraint's lifetime. Default:
  /// all of v (a dense row).
  virtual std::vector<int> jointColumns(const Model& model) const;
  /// A unilateral constraint (a contact, a joint limit) can open. Its row
  /// unilateralRow() is ġ of a gap g(q) ≥ 0 whose multiplier may only push
  /// (λ ≥ 0, the force along the row's direction): while closed all its rows
  /// hold; it opens when that λ would pull (lift-off) and closes when g
  /// reaches 0 (touchdown) — docs/contacts.md §7. −1: bilateral, always closed.
  virtual int unilateralRow() const { return -1; }
  bool unilateral() const { return unilateralRow() >= 0; }
  /// The law of its unilateral row's contact (ContactLaw): data the
  /// constraint sets at construction, read only when unilateral().
  const ContactLaw& contactLaw() const { return law_; }
  // The law's fields one by one (reports, the scene's checks).
  double restitution() const { return law_.restitution; }
  double friction() const { return law_.mu; }
  double kineticFriction() const { return law_.mu_kinetic; }
  double creepSpeed() const { return law_.creep_speed; }
  double spinFriction() const { return law_.spin; }
  /// Several points of one pair (a ball that may touch a terrain in a valley
  /// on both slopes): constraints with the same group id ≥ 0 are the points
  /// of one pair, numbered by pointSlot(). The simulator gives each point the
  /// pieces its closed siblings hold to skip (TerrainPiece::excluded) and
  /// lets only the first open point watch for a touchdown. −1: a single point.
  int pointGroup() const { return point_group_; }
  int pointSlot() const { return point_slot_; }
  /// Constant-size storage the block needs (called once, outside the step).
  virtual void reserve(const Model& model, RowBlock& block) const;
  /// Writes the rows at (q, v, t). `data` holds forwardKinematics(q, v).
  virtual void evaluate(const Model& model, const Data& data, double t, const VecX& q,
                        const VecX& v, RowBlock& out) const = 0;

 protected:
  ContactLaw law_;        ///< default: ideal rolling (μ = ∞), plastic, no spin friction
  int point_group_ = -1;  ///< pointGroup()
  int point_slot_ = 0;    ///< pointSlot()
};

/// Joint-space row r of `blk` applied to x (size nv): Σₖ A_joint(r, k) x[cols[k]].
inline double jointRowDot(const RowBlock& blk, int r, const VecX& x) {
  double s = 0;
  for (size_t k = 0; k < blk.joint_cols.size(); ++k) s += blk.A_joint(r, k) * x[blk.joint_cols[k]];
  return s;
}

/// out += scale · (joint-space row r of `blk`)ᵀ, out of size nv.
inline void addJointRow(const RowBlock& blk, int r, double scale, Eigen::Ref<VecX> out) {
  for (size_t k = 0; k < blk.joint_cols.size(); ++k)
    out[blk.joint_cols[k]] += scale * blk.A_joint(r, k);
}

}  // namespace appell
