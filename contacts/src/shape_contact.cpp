// ShapeContact: one body's smooth shape against a world support; validation
// at construction, rows at evaluation (no allocation there).
#include <appell/contacts.hpp>

#include "contact_kinds.hpp"
#include "geometry_internal.hpp"

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

bool isWheel(const Shape& s) {
  return std::holds_alternative<Disk>(s) || std::holds_alternative<Torus>(s);
}

}  // namespace

const char* toString(ContactKind kind) {
  switch (kind) {
    case ContactKind::Rolling: return "rolling";
    case ContactKind::RollingWithoutSpin: return "rolling_without_spin";
    case ContactKind::KnifeEdge: return "knife_edge";
    case ContactKind::Sliding: return "sliding";
  }
  return "?";
}

ContactKind contactKindFromString(const std::string& text) {
  if (text == "rolling") return ContactKind::Rolling;
  if (text == "rolling_without_spin" || text == "rolling-without-spin" || text == "rolling_no_spin" ||
      text == "rubber")
    return ContactKind::RollingWithoutSpin;
  if (text == "knife_edge" || text == "knife-edge" || text == "knife") return ContactKind::KnifeEdge;
  if (text == "sliding") return ContactKind::Sliding;
  throw std::invalid_argument("unknown contact kind '" + text +
                              "' (expected rolling, rolling_without_spin, knife_edge or sliding)");
}

ShapeContact::ShapeContact(ContactKind kind, int body, Shape shape, Support support,
                           const ContactOptions& options)
    : kind_(kind),
      body_(body),
      shape_(std::move(shape)),
      support_(std::move(support)),
      geometry_options_(options.geometry),
      rows_(rowCount(kind)) {
  if (options.name.empty()) {
    std::ostringstream s;
    s << toString(kind) << "(body " << body << ", " << shapeName(shape_) << " on "
      << support_.name << ")";
    name_ = s.str();
  } else {
    name_ = options.name;
  }
  auto fail = [&](const std::string& why) {
    throw std::invalid_argument("contact '" + name_ + "': " + why);
  };
  if (body < 0) fail("body index must be ≥ 0 (the world cannot carry a contact shape)");
  if (support_.body == body) fail("the support cannot be carried by the contact's own body");
  if (support_.body < -1) fail("support body index must be ≥ −1");
  if (support_.body >= 0 && !std::holds_alternative<StaticMotion>(support_.motion))
    fail("a support carried by a body moves with it: give a StaticMotion (its pose on the body)");
  try {
    validateShape(shape_);
    validateSupport(support_);
  } catch (const std::invalid_argument& e) {
    fail(e.what());
  }
  if (auto* p = std::get_if<Plane>(&support_.surface)) p->normal.normalize();
  // Face normals, adjacency and the box tree, once (evaluation must not allocate).
  if (auto* t = std::get_if<TerrainMesh>(&support_.surface); t && !t->index)
    *t = makeTerrain(t->vertices, t->triangles);
  std::string why;
  switch (kind) {
    case ContactKind::Rolling:
    case ContactKind::RollingWithoutSpin:
      if (!canRoll(shape_, &why)) fail(why);
      break;
    case ContactKind::KnifeEdge:
      if (std::holds_alternative<PointShape>(shape_)) {
        const Vec3& b = options.blade_direction;
        if (!b.allFinite() || b.norm() < 1e-12)
          fail("knife edge on a point needs a non-zero blade direction");
        blade_ = b.normalized();
      } else if (isWheel(shape_)) {
        if (options.blade_direction.norm() != 0)
          fail("a disk or torus knife edge uses its wheel plane as the blade; leave "
               "blade_direction unset");
        blade_ = std::holds_alternative<Disk>(shape_) ? std::get<Disk>(shape_).axis
                                                      : std::get<Torus>(shape_).axis;
      } else {
        fail(std::string("a knife edge needs a blade: a point with a blade direction, or a disk "
                         "or torus wheel (got a ") +
             shapeName(shape_) + ")");
      }
      break;
    case ContactKind::Sliding:
      if (!isSmoothContactShape(shape_))
        fail(std::string("a ") + shapeName(shape_) +
             " has no smooth contact point; sliding needs a point or a smooth convex shape");
      break;
  }
  if (const auto* sp = std::get_if<SphereSurface>(&support_.surface)) {
    if (sp->side == SphereSurface::Side::Inside && !fitsInBowl(shape_, sp->radius, &why))
      fail("does not fit the bowl '" + support_.name + "': " + why);
  }
}

RowKind ShapeContact::rowKind(int k) const {
  static constexpr RowKind rolling[] = {RowKind::Tangent1, RowKind::Tangent2, RowKind::Normal,
                                        RowKind::Spin};
  switch (kind_) {
    case ContactKind::Rolling:
    case ContactKind::RollingWithoutSpin: return rolling[k];
    case ContactKind::KnifeEdge: return k == 0 ? RowKind::Lateral : RowKind::Normal;
    case ContactKind::Sliding: return RowKind::Normal;
  }
  return RowKind::Custom;
}

// The normal row is ġ for the signed gap g; the others are velocity rows.
bool ShapeContact::holonomic(int k) const { return rowKind(k) == RowKind::Normal; }

void ShapeContact::reserve(const Model& model, RowBlock& block) const {
  if (support_.body >= model.nbodies)
    throw std::invalid_argument("contact '" + name_ + "': support body index " +
                                std::to_string(support_.body) + " is out of range (the model has " +
                                std::to_string(model.nbodies) + " bodies)");
  if (body_ >= model.nbodies)
    throw std::invalid_argument("contact '" + name_ + "': body index " + std::to_string(body_) +
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
  if (support_.body < 0) return supportState(support_.motion, t);
  SupportState S;
  S.pose = support_body_pose * std::get<StaticMotion>(support_.motion).pose;
  S.V = support_body_velocity;
  return S;  // A = 0: the carrying body's acceleration enters through Wb
}

void ShapeContact::geometry(const SE3& body_pose, const Vec6& body_velocity, double t,
                            ContactGeometry& out) const {
  contactGeometry(shape_, support_.surface, supportStateAt(t), body_pose, body_velocity, out,
                  geometry_options_);
}

void ShapeContact::writeRows(const SE3& body_pose, const Vec6& body_velocity,
                             const SupportState& S, RowBlock& out) const {
  ContactGeometry g;
  contactGeometry(shape_, support_.surface, S, body_pose, body_velocity, g, geometry_options_);
  out.m = rows_;
  out.Wa.resize(rows_, 6);
  out.Wb.resize(rows_, 6);
  out.b.resize(rows_);
  out.kappa.resize(rows_);
  out.gap.resize(rows_);
  const char* reason = g.singular ? g.reason : nullptr;
  switch (kind_) {
    case ContactKind::Rolling:
    case ContactKind::RollingWithoutSpin:
      detail::writeRollingRows(g, body_velocity, S, kind_ == ContactKind::RollingWithoutSpin, out);
      break;
    case ContactKind::KnifeEdge: {
      const char* r =
          detail::writeKnifeEdgeRows(g, body_pose, body_velocity, S, blade_, isWheel(shape_),
                                     geometry_options_.singular_tol, out);
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
  out.singular = reason != nullptr;
  if (reason) out.singular_reason.assign(reason);
  else out.singular_reason.clear();
}

void ShapeContact::evaluateAt(const SE3& body_pose, const Vec6& body_velocity, double t,
                              RowBlock& out) const {
  if (support_.body >= 0)
    throw std::logic_error("contact '" + name_ +
                           "': the support is carried by a body; use evaluateOnBody");
  writeRows(body_pose, body_velocity, supportState(support_.motion, t), out);
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
  const SE3& pose = data.oMi[body_];
  const Vec6 V = pose.act(data.v[body_]);
  if (support_.body < 0) {
    writeRows(pose, V, supportState(support_.motion, t), out);
  } else {
    const SE3& pb = data.oMi[support_.body];
    evaluateOnBody(pose, V, pb, pb.act(data.v[support_.body]), out);
  }
}

std::shared_ptr<ShapeContact> makeContact(ContactKind kind, int body, const Shape& shape,
                                          const Support& support, const ContactOptions& options) {
  return std::make_shared<ShapeContact>(kind, body, shape, support, options);
}

}  // namespace appell
