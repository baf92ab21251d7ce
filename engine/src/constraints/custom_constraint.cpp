// User-supplied Pfaffian rows over the generalized velocities.
#include <appell/custom_constraint.hpp>

#include <stdexcept>

namespace appell {

CustomConstraint::CustomConstraint(CustomRows spec) : spec_(std::move(spec)) {
  auto fail = [&](const std::string& why) {
    throw std::invalid_argument("custom constraint '" + spec_.name + "': " + why);
  };
  if (spec_.rows <= 0 || spec_.rows > 6)
    fail("rows must be between 1 and 6 (got " + std::to_string(spec_.rows) +
         "); split larger sets into several constraints");
  if (!spec_.A_b) fail("the A(q, t), b(q, t) callback is empty");
  if (!spec_.bias) fail("the acceleration-term callback (Ȧv + ḃ) is empty");
  if (!spec_.labels.empty() && static_cast<int>(spec_.labels.size()) != spec_.rows)
    fail("labels must be empty or one per row");
  if (!spec_.holonomic.empty() && static_cast<int>(spec_.holonomic.size()) != spec_.rows)
    fail("holonomic flags must be empty or one per row");
  for (bool h : spec_.holonomic)
    if (h && !spec_.gap) fail("a holonomic row needs the gap callback g(q, t)");
  if (spec_.body < -1) fail("body must be ≥ −1");
}

std::string CustomConstraint::rowLabel(int k) const {
  return spec_.labels.empty() ? Constraint::rowLabel(k) : spec_.labels[k];
}

bool CustomConstraint::holonomic(int k) const {
  return !spec_.holonomic.empty() && spec_.holonomic[k];
}

void CustomConstraint::reserve(const Model& model, RowBlock& block) const {
  if (spec_.body >= model.nbodies)
    throw std::invalid_argument("custom constraint '" + spec_.name + "': body index out of range");
  Constraint::reserve(model, block);
  const int m = spec_.rows;
  block.m = m;
  block.Wa.setZero(m, 6);
  block.Wb.setZero(m, 6);
  block.b.setZero(m);
  block.kappa.setZero(m);
  block.gap.setZero(m);
  block.A_joint.setZero(m, model.nv);
  block.b_joint.setZero(m);
  block.abias_joint.setZero(m);
  block.singular_reason.reserve(256);
}

void CustomConstraint::evaluate(const Model& model, const Data&, double t, const VecX& q,
                                const VecX& v, RowBlock& out) const {
  const int m = spec_.rows;
  out.m = m;
  spec_.A_b(model, q, t, out.A_joint, out.b_joint);
  spec_.bias(model, q, v, t, out.abias_joint);
  if (spec_.gap) {
    spec_.gap(model, q, t, out.gap);
    for (int k = 0; k < m; ++k)
      if (!holonomic(k)) out.gap[k] = 0;
  } else {
    out.gap.setZero();
  }
  const bool finite =
      out.A_joint.allFinite() && out.b_joint.allFinite() && out.abias_joint.allFinite() &&
      out.gap.allFinite();
  out.singular = !finite;
  if (!finite) out.singular_reason.assign("custom constraint callback returned a non-finite value");
  else out.singular_reason.clear();
}

}  // namespace appell
