// ShapeContact: one body's smooth shape against a world support; validation
// at construction, rows at evaluation (no allocation there).
#include <appell/contacts.hpp>

#include "contact_kinds.hpp"
#include "geometry_internal.hpp"

#include <appell/name_table.hpp>

#include <atomic>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace appell {

namespace {

int rowCount(ContactKind kind) {
  switch (kind) {
    case ContactKind::Rolling: return 3;
    case ContactKind::RollingWithoutSpin: return 4;
    case ContactKind::KnifeEdge: return 2;
    case ContactKind::Sliding: return 1;
  }
  return 0;
}

}  // namespace

std::span<const NamedValue<ContactKind>> contactKindTable() {
  static const NamedValue<ContactKind> table[] = {
      {ContactKind::Rolling, "rolling", {}, "no slip: rows tangent1, tangent2, normal"},
      {ContactKind::RollingWithoutSpin, "rolling_without_spin", {"rolling_no_spin", "rubber"},
       "no slip and no spin about the normal: rows tangent1, tangent2, normal, spin"},
      {ContactKind::KnifeEdge, "knife_edge", {"knife"},
       "no sideways slip of a blade (a point with a direction, or a wheel plane): rows lateral, "
       "normal"},
      {ContactKind::Sliding, "sliding", {}, "frictionless, stays on the support: row normal"},
  };
  return table;
}

const char* toString(ContactKind kind) { return entryOf(contactKindTable(), kind).name; }

ContactKind contactKindFromString(const std::string& text) {
  return parseName(contactKindTable(), text, "contact kind");
}

ShapeContact::ShapeContact(ContactKind kind, int body, Shape shape, Support support,
                           const ContactOptions& options)
    : ShapeContact([&] {
        ContactSpec spec;  // ideal rolling: infinite friction, unilateral, plastic
        spec.kind = kind;
        spec.body = body;
        spec.shape = std::move(shape);
        spec.support = std::move(support);
        spec.options = options;
        return spec;
      }()) {}

ShapeContact::ShapeContact(ContactSpec spec) : spec_(std::move(spec)), rows_(rowCount(spec_.kind)) {
  const ContactKind kind = spec_.kind;
  const int body = spec_.body;
  const Shape& shape = spec_.shape;
  Support& support = spec_.support;
  std::string& name = spec_.options.name;
  if (name.empty()) {
    std::ostringstream s;
    s << toString(kind) << "(body " << body << ", " << shapeName(shape) << " on " << support.name
      << ")";
    name = s.str();
  }
  auto fail = [&](const std::string& why) {
    throw std::invalid_argument("contact '" + name + "': " + why);
  };
  if (body < 0) fail("body index must be ≥ 0 (the world cannot carry a contact shape)");
  if (support.body == body) fail("the support cannot be carried by the contact's own body");
  if (support.body < -1) fail("support body index must be ≥ −1");
  if (support.body >= 0 && !std::holds_alternative<StaticMotion>(support.motion))
    fail("a support carried by a body moves with it: give a StaticMotion (its pose on the body)");
  if (!(spec_.mu >= 0))
    fail("the friction coefficient μ must be ≥ 0 (∞: no limit)");
  if (!(spec_.points >= 1 && spec_.points <= 4))
    fail("'points' must be 1 … 4 (places the body may touch a terrain at once), got " +
         std::to_string(spec_.points));
  if (spec_.points > 1 && !std::holds_alternative<TerrainMesh>(support.surface))
    fail("more than one point needs a terrain support: a smooth body touches a plane or a "
         "sphere at one point");
  if (spec_.points > 1 && !spec_.unilateral)
    fail("more than one point needs a unilateral contact (the points make and break)");
  if (!(spec_.restitution >= 0 && spec_.restitution <= 1))
    fail("the restitution must lie in [0, 1] (0: plastic, 1: elastic), got " +
         std::to_string(spec_.restitution));
  if (!std::isnan(spec_.mu_spin)) {
    if (!(spec_.mu_spin > 0 && std::isfinite(spec_.mu_spin)))
      fail("the spin friction length must be positive and finite (m), got " +
           std::to_string(spec_.mu_spin));
    if (spec_.kind != ContactKind::RollingWithoutSpin)
      fail("spin friction needs a contact with a spin row (kind rolling_without_spin)");
    if (!(spec_.mu > 0 && std::isfinite(spec_.mu)))
      fail("spin friction needs a finite friction coefficient μ > 0 (the cone it shares)");
  }
  if (!(spec_.creep_speed >= 0 && std::isfinite(spec_.creep_speed)))
    fail("the creep speed must be ≥ 0 and finite (m/s; 0: Coulomb with sticking), got " +
         std::to_string(spec_.creep_speed));
  if (spec_.creep_speed > 0 && !(spec_.mu > 0 && std::isfinite(spec_.mu)))
    fail("a creep speed needs a finite friction coefficient μ > 0 (the force it saturates at)");
  if (spec_.creep_speed > 0 && !spec_.unilateral)
    fail("a creep speed needs a unilateral contact (friction acts on unilateral contacts)");
  if (!(spec_.normal_stiffness >= 0 && std::isfinite(spec_.normal_stiffness)) ||
      !(spec_.normal_damping >= 0 && std::isfinite(spec_.normal_damping)))
    fail("the normal stiffness and damping must be ≥ 0 and finite (N/m, N·s/m; 0: rigid)");
  if (spec_.normal_damping > 0 && !(spec_.normal_stiffness > 0))
    fail("a normal damping needs a normal stiffness > 0 (a damper alone does not hold the contact)");
  if (spec_.normal_stiffness > 0 && !spec_.unilateral)
    fail("a compliant normal needs a unilateral contact");
  if (spec_.normal_stiffness > 0 && spec_.restitution > 0)
    fail("a compliant contact takes no restitution: its normal damping sets what an impact keeps");
  try {
    validateShape(shape);
    validateSupport(support);
  } catch (const std::invalid_argument& e) {
    fail(e.what());
  }
  law_.mu = spec_.mu;
  law_.mu_kinetic = std::isnan(spec_.mu_kinetic) ? spec_.mu : spec_.mu_kinetic;
  law_.spin = spec_.mu_spin;
  law_.creep_speed = spec_.creep_speed;
  law_.restitution = spec_.restitution;
  law_.normal_stiffness = spec_.normal_stiffness;
  law_.normal_damping = spec_.normal_damping;
  if (auto* p = std::get_if<Plane>(&support.surface)) p->normal.normalize();
  // Face normals, adjacency and FCL's hierarchy, once (evaluation must not allocate).
  if (auto* t = std::get_if<TerrainMesh>(&support.surface); t && !t->index)
    *t = makeTerrain(t->vertices, t->triangles);
  std::string why;
  switch (kind) {
    case ContactKind::Rolling:
      // On a point, "rolling" is a sticking point: the body point does not
      // slip (the vertex contacts of a box or mesh foot, vertex_contacts.hpp).
      if (shapeType(shape).role != ShapeRole::Point && !canRoll(shape, &why)) fail(why);
      break;
    case ContactKind::RollingWithoutSpin:
      if (!canRoll(shape, &why)) fail(why);
      break;
    case ContactKind::KnifeEdge: {
      const Vec3& b = spec_.options.blade_direction;
      if (shapeType(shape).role == ShapeRole::Point) {
        if (!b.allFinite() || b.norm() < 1e-12)
          fail("knife edge on a point needs a non-zero blade direction");
        blade_ = b.normalized();
      } else if (const Vec3* axle = wheelAxis(shape)) {
        if (b.norm() != 0)
          fail("a disk or torus knife edge uses its wheel plane as the blade; leave "
               "blade_direction unset");
        blade_ = *axle;
      } else {
        fail(std::string("a knife edge needs a blade: a point with a blade direction, or a disk "
                         "or torus wheel (got a ") +
             shapeName(shape) + ")");
      }
      break;
    }
    case ContactKind::Sliding:
      if (!isSmoothContactShape(shape))
        fail(std::string("a ") + shapeName(shape) +
             " has no smooth contact point; sliding needs a point or a smooth convex shape");
      break;
  }
  if (const auto* sp = std::get_if<SphereSurface>(&support.surface)) {
    if (sp->side == SphereSurface::Side::Inside && !fitsInBowl(shape, sp->radius, &why))
      fail("does not fit the bowl '" + support.name + "': " + why);
  }
}

RowKind ShapeContact::rowKind(int k) const {
  static constexpr RowKind rolling[] = {RowKind::Tangent1, RowKind::Tangent2, RowKind::Normal,
                                        RowKind::Spin};
  switch (spec_.kind) {
    case ContactKind::Rolling:
    case ContactKind::RollingWithoutSpin: return rolling[k];
    case ContactKind::KnifeEdge: return k == 0 ? RowKind::Lateral : RowKind::Normal;
    case ContactKind::Sliding: return RowKind::Normal;
  }
  return RowKind::Custom;
}

// The normal row is ġ for the signed gap g; the others are velocity rows.
bool ShapeContact::holonomic(int k) const { return rowKind(k) == RowKind::Normal; }

int ShapeContact::unilateralRow() const {
  if (!spec_.unilateral) return -1;
  for (int k = 0; k < rows_; ++k)
    if (rowKind(k) == RowKind::Normal) return k;
  return -1;
}

void ShapeContact::reserve(const Model& model, RowBlock& block) const {
  if (spec_.support.body >= model.nbodies)
    throw std::invalid_argument("contact '" + name() + "': support body index " +
                                std::to_string(spec_.support.body) + " is out of range (the model has " +
                                std::to_string(model.nbodies) + " bodies)");
  if (spec_.body >= model.nbodies)
    throw std::invalid_argument("contact '" + name() + "': body index " + std::to_string(spec_.body) +
                                " is out of range (the model has " +
                                std::to_string(model.nbodies) + " bodies)");
  Constraint::reserve(model, block);
  block.m = rows_;
  block.Wa.setZero(rows_, 6);
  block.Wb.setZero(rows_, 6);
  block.b.setZero(rows_);
  block.kappa.setZero(rows_);
  block.gap.setZero(rows_);
  // Singular reasons are static texts shorter than this: assigning one later
  // does not allocate.
  block.singular_reason.reserve(256);
}

SupportState ShapeContact::supportStateAt(double t, const SE3& support_body_pose,
                                          const Vec6& support_body_velocity) const {
  if (spec_.support.body < 0) return supportState(spec_.support.motion, t);
  SupportState S;
  S.pose = support_body_pose * std::get<StaticMotion>(spec_.support.motion).pose;
  S.V = support_body_velocity;
  return S;  // A = 0: the carrying body's acceleration enters through Wb
}

void ShapeContact::geometry(const SE3& body_pose, const Vec6& body_velocity, double t,
                            ContactGeometry& out) const {
  contactGeometry(spec_.shape, spec_.support.surface, supportStateAt(t), body_pose, body_velocity, out,
                  spec_.options.geometry);
}

void ShapeContact::writeRows(const SE3& body_pose, const Vec6& body_velocity,
                             const SupportState& S, RowBlock& out) const {
  ContactGeometry g;
  contactGeometry(spec_.shape, spec_.support.surface, S, body_pose, body_velocity, g,
                  spec_.options.geometry, out.piece.latched,
                  std::span<const int>(out.piece.excluded.data(), out.piece.excluded_count));
  out.piece.feature = g.feature;
  out.m = rows_;
  out.Wa.resize(rows_, 6);
  out.Wb.resize(rows_, 6);
  out.b.resize(rows_);
  out.kappa.resize(rows_);
  out.gap.resize(rows_);
  const char* reason = g.singular ? g.reason : nullptr;
  switch (spec_.kind) {
    case ContactKind::Rolling:
    case ContactKind::RollingWithoutSpin:
      detail::writeRollingRows(g, body_velocity, S, spec_.kind == ContactKind::RollingWithoutSpin, out);
      break;
    case ContactKind::KnifeEdge: {
      const char* r =
          detail::writeKnifeEdgeRows(g, body_pose, body_velocity, S, blade_, wheelAxis(spec_.shape) != nullptr,
                                     spec_.options.geometry.singular_tol, out);
      if (!reason) reason = r;
      break;
    }
    case ContactKind::Sliding:
      detail::writeSlidingRows(g, body_velocity, S, out);
      break;
  }
  out.frame.point = g.point;
  out.frame.normal = g.normal;
  out.frame.t1 = g.t1;
  out.frame.t2 = g.t2;
  out.frame.gap = g.gap;
  out.frame.margin = g.margin;
  out.singular = reason != nullptr;
  if (reason) out.singular_reason.assign(reason);
  else out.singular_reason.clear();
}

void ShapeContact::evaluateAt(const SE3& body_pose, const Vec6& body_velocity, double t,
                              RowBlock& out) const {
  if (spec_.support.body >= 0)
    throw std::logic_error("contact '" + name() +
                           "': the support is carried by a body; use evaluateOnBody");
  writeRows(body_pose, body_velocity, supportState(spec_.support.motion, t), out);
}

void ShapeContact::evaluateOnBody(const SE3& body_pose, const Vec6& body_velocity,
                                  const SE3& support_body_pose,
                                  const Vec6& support_body_velocity, RowBlock& out) const {
  writeRows(body_pose, body_velocity, supportStateAt(0.0, support_body_pose, support_body_velocity),
            out);
  // Every row has b = −W·V_S with V_S the carrying body's velocity: the
  // two-body form wₐ·Vₐ − w_b·V_b with w_b = wₐ and no offset.
  out.Wb = out.Wa;
  out.b.setZero();
}

void ShapeContact::evaluate(const Model&, const Data& data, double t, const VecX&, const VecX&,
                            RowBlock& out) const {
  const SE3& pose = data.oMi[spec_.body];
  const Vec6 V = pose.act(data.v[spec_.body]);
  if (spec_.support.body < 0) {
    writeRows(pose, V, supportState(spec_.support.motion, t), out);
  } else {
    const SE3& pb = data.oMi[spec_.support.body];
    evaluateOnBody(pose, V, pb, pb.act(data.v[spec_.support.body]), out);
  }
}

std::shared_ptr<ShapeContact> makeContact(const ContactSpec& spec) {
  auto c = std::make_shared<ShapeContact>(spec);
  if (spec.points > 1)
    throw std::invalid_argument("contact '" + c->name() + "': " + std::to_string(spec.points) +
                                " points make " + std::to_string(spec.points) +
                                " contacts (makeContactPoints)");
  return c;
}

std::vector<std::shared_ptr<ShapeContact>> makeContactPoints(const ContactSpec& spec) {
  auto first = std::make_shared<ShapeContact>(spec);  // validates, names, builds the index
  if (spec.points == 1) return {first};
  const ContactSpec pair = first->spec();
  // The pair's id: distinct for every pair made in this process (only
  // equality is read: Constraint::pointGroup).
  static std::atomic<int> next_pair{0};
  const int group = next_pair.fetch_add(1, std::memory_order_relaxed);
  std::vector<std::shared_ptr<ShapeContact>> points;
  for (int k = 0; k < pair.points; ++k) {
    ContactSpec one = pair;
    one.options.name = pair.options.name + "/p" + std::to_string(k);
    auto c = std::make_shared<ShapeContact>(std::move(one));
    c->point_group_ = group;
    c->point_slot_ = k;
    points.push_back(std::move(c));
  }
  return points;
}

std::shared_ptr<ShapeContact> makeContact(ContactKind kind, int body, const Shape& shape,
                                          const Support& support, const ContactOptions& options) {
  return std::make_shared<ShapeContact>(kind, body, shape, support, options);
}

}  // namespace appell
