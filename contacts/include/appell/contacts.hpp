// Contact constraints between one body's shape and a world support.
//
// Every row is a material-point velocity row or an angular-velocity row
// (constraint.hpp): for a unit direction t(q, t) and the body point w(q, t)
// now in contact,
//      tᵀ (V_B(w) − V_S(w, t)) = 0          V_B(w) = v_O + ω × w
//   row      W = [w × t; t],   b = −tᵀ V_S(w, t)
//   accel    W·a + κ = 0,
//            κ = ṫᵀ(V_B(w) − V_S(w)) + tᵀ(ω × ẇ) − tᵀ(A_lin + A_ang × w + Ω × ẇ)
// where ẇ is the velocity of the geometric contact point (contact_geometry.hpp)
// and [A_ang; A_lin] the support's spatial acceleration. The spin row is
//      nᵀ(ω − Ω) = 0:  W = [n; 0], b = −nᵀΩ, κ = ṅᵀ(ω − Ω) − nᵀ A_ang.
// The normal row is the time derivative of the signed gap, so the position
// projection can drive the gap to zero.
//
// Rows per kind (in this order):
//   Rolling               tangent1, tangent2, normal
//   RollingWithoutSpin    tangent1, tangent2, normal, spin
//   KnifeEdge             lateral, normal
//   Sliding               normal
#pragma once

#include <appell/constraint.hpp>
#include <appell/contact_geometry.hpp>

#include <appell/name_table.hpp>

#include <cmath>
#include <limits>
#include <memory>
#include <vector>

namespace appell {

enum class ContactKind { Rolling, RollingWithoutSpin, KnifeEdge, Sliding };

/// Every contact kind with its names ("rolling", "rolling_without_spin" /
/// "rolling_no_spin" / "rubber", "knife_edge" / "knife", "sliding"): the one
/// list that parsing, error messages and the scene format read.
std::span<const NamedValue<ContactKind>> contactKindTable();
const char* toString(ContactKind kind);  ///< the canonical name
/// Parses any name or alias of contactKindTable() ('-' = '_'); throws
/// std::invalid_argument listing them all otherwise.
ContactKind contactKindFromString(const std::string& text);

/// The optional part of a contact's description.
struct ContactOptions {
  std::string name;                 ///< empty: "<kind>(body …, <shape> on <support>)"
  /// Knife edges on a PointShape: the blade direction, body frame (any length
  /// > 0). Disks and tori use their wheel plane instead (must stay zero).
  Vec3 blade_direction = Vec3::Zero();
  GeometryOptions geometry;
};

/// A contact, described once: the constraint keeps this description and
/// everything downstream (the scene loader, the CLI's reports, the CSV) reads
/// it back from the constraint.
struct ContactSpec {
  ContactKind kind = ContactKind::Rolling;
  int body = -1;                    ///< the body carrying the shape
  Shape shape;                      ///< in that body's frame
  Support support;
  /// Coulomb friction coefficient (∞: no limit, ideal rolling). With a
  /// finite μ a unilateral contact sticks while |λₜ| ≤ μ λₙ and slides
  /// beyond (docs/contacts.md §8); 0: frictionless sliding.
  double mu = std::numeric_limits<double>::infinity();
  /// Coulomb's kinetic coefficient, the force μₖλₙ of a sliding contact
  /// (≤ mu, which is then the static one: the cone that sticking must stay
  /// in). NaN: the same as mu.
  double mu_kinetic = std::numeric_limits<double>::quiet_NaN();
  /// Torsional friction of a rolling-without-spin contact, a length ℓ > 0
  /// (m): the spin torque a sticking contact holds alone is ℓ λₙ, and with
  /// the tangential force the pair stays in the ellipsoid |(fₜ, τₙ μ/ℓ)| ≤ μλₙ
  /// (docs/contacts.md §8). NaN: none (the spin row is ideal while the
  /// contact sticks and free while it slides). Needs a finite μ > 0.
  double mu_spin = std::numeric_limits<double>::quiet_NaN();
  /// Regularized friction (ContactLaw::creep_speed): the slip speed v_c > 0
  /// (m/s) below which the friction force grows linearly with the slip,
  /// μₖλₙ s/v_c, instead of sticking. 0: Coulomb, with sticking. Needs a
  /// finite μ > 0 and a unilateral contact.
  double creep_speed = 0;
  /// The contact can open: it lifts off when its normal force would pull and
  /// closes when its gap reaches zero (contact_events.hpp). false: a
  /// bilateral idealisation (a wheel on a rail that holds it down).
  bool unilateral = true;
  /// Newton's coefficient of restitution of its impacts, in [0, 1] (0: plastic).
  double restitution = 0;
  /// A compliant normal (ContactLaw::normal_stiffness, normal_damping): k > 0
  /// N/m and c ≥ 0 N·s/m; 0: rigid. Compliant contacts are time-stepped
  /// (docs/contacts.md §10); they take no restitution (c dissipates).
  double normal_stiffness = 0;
  double normal_damping = 0;
  /// How many places a smooth body may touch a terrain at once, 1 … 4 (a
  /// ball in a valley touches both slopes; a tyre in a pothole its rim): one
  /// unilateral contact per point (makeContactPoints), each on its own piece
  /// of the terrain. 1 on every other support.
  int points = 1;
  ContactOptions options;
};

/// One body's smooth shape against a world support. The kinds differ only in
/// which rows they write.
class ShapeContact : public Constraint {
 public:
  /// Checks the description (see makeContact) and keeps it, with its name
  /// filled in when it was empty.
  explicit ShapeContact(ContactSpec spec);
  ShapeContact(ContactKind kind, int body, Shape shape, Support support,
               const ContactOptions& options);

  const std::string& name() const override { return spec_.options.name; }
  int rows() const override { return rows_; }
  int bodyA() const override { return spec_.body; }
  /// The body carrying the support, or −1 (world).
  int bodyB() const override { return spec_.support.body; }
  RowKind rowKind(int k) const override;
  bool holonomic(int k) const override;
  /// The normal row, when the contact is unilateral (spec().unilateral).
  int unilateralRow() const override;
  // Its ContactLaw (Constraint::contactLaw) is the spec's μ, μₖ (μ when
  // unset), spin length, creep speed and restitution; makeContactPoints
  // gives the points of one pair a common group id and their slots.
  void reserve(const Model& model, RowBlock& block) const override;
  void evaluate(const Model& model, const Data& data, double t, const VecX& q, const VecX& v,
                RowBlock& out) const override;

  /// The same rows from the body's world pose and world spatial velocity
  /// directly (what evaluate() does after reading data.oMi and data.v), for a
  /// support that belongs to the world.
  void evaluateAt(const SE3& body_pose, const Vec6& body_velocity, double t,
                  RowBlock& out) const;
  /// Rows against a support carried by body B (support.body ≥ 0), given B's
  /// world pose and spatial velocity: Wb = Wa, b = 0, and κ without B's
  /// acceleration (the engine adds −Wb·a_B).
  void evaluateOnBody(const SE3& body_pose, const Vec6& body_velocity, const SE3& support_body_pose,
                      const Vec6& support_body_velocity, RowBlock& out) const;
  /// The geometry alone at the given state.
  void geometry(const SE3& body_pose, const Vec6& body_velocity, double t,
                ContactGeometry& out) const;
  /// State of the support frame: from its motion (world supports), or from the
  /// carrying body's pose and velocity (then A = 0: the body's acceleration
  /// enters through Wb, not κ).
  SupportState supportStateAt(double t, const SE3& support_body_pose = {},
                              const Vec6& support_body_velocity = Vec6::Zero()) const;

  /// The contact's description, as given (name filled in).
  const ContactSpec& spec() const { return spec_; }
  ContactKind kind() const { return spec_.kind; }
  const Shape& shape() const { return spec_.shape; }
  const Support& support() const { return spec_.support; }
  /// Coulomb friction coefficient (∞: no limit).
  double mu() const { return spec_.mu; }
  /// Knife edge: the unit blade direction (body frame; a wheel's axle for a
  /// disk or torus); zero otherwise.
  const Vec3& bladeDirection() const { return blade_; }

 private:
  void writeRows(const SE3& body_pose, const Vec6& body_velocity, const SupportState& S,
                 RowBlock& out) const;

  friend std::vector<std::shared_ptr<ShapeContact>> makeContactPoints(const ContactSpec& spec);

  ContactSpec spec_;
  Vec3 blade_ = Vec3::Zero();
  int rows_ = 0;
};

/// Builds a contact from a declarative description. Throws std::invalid_argument
/// with the contact's name and the reason: a shape that cannot roll (box,
/// cylinder, mesh, point) for rolling kinds, a knife edge without a blade (zero
/// direction on a point; a sphere or ellipsoid has no blade), a shape that does
/// not fit its bowl, a negative body index, bad shape or support parameters, a
/// support carried by the contact's own body or given a prescribed motion, a
/// negative or NaN μ.
std::shared_ptr<ShapeContact> makeContact(const ContactSpec& spec);
std::shared_ptr<ShapeContact> makeContact(ContactKind kind, int body, const Shape& shape,
                                          const Support& support,
                                          const ContactOptions& options = {});

/// The spec.points contacts of a smooth body on a terrain, named
/// "<name>/p0", "<name>/p1", … (one contact, named as given, for points = 1).
/// Each is a unilateral contact with spec's kind, μ and restitution; the
/// simulator keeps them on separate pieces of the terrain (docs/contacts.md
/// §4). Throws std::invalid_argument naming the contact: points outside
/// 1 … 4, more than one point on a support other than a terrain, or on a
/// bilateral contact.
std::vector<std::shared_ptr<ShapeContact>> makeContactPoints(const ContactSpec& spec);

}  // namespace appell
