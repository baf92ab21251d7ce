#include <appell/constraint.hpp>

namespace appell {

const char* toString(RowKind kind) {
  switch (kind) {
    case RowKind::Normal: return "normal";
    case RowKind::Tangent1: return "tangent1";
    case RowKind::Tangent2: return "tangent2";
    case RowKind::Lateral: return "lateral";
    case RowKind::Spin: return "spin";
    case RowKind::Custom: return "custom";
  }
  return "?";
}

std::string Constraint::rowLabel(int k) const {
  const RowKind kind = rowKind(k);
  if (kind == RowKind::Custom) return toString(kind) + std::to_string(k);
  return toString(kind);
}

void Constraint::reserve(const Model& model, RowBlock& block) const {
  const int m = rows();
  block.m = m;
  if (jointSpace()) {
    block.A_joint = MatX::Zero(m, model.nv);
    block.b_joint = VecX::Zero(m);
    block.abias_joint = VecX::Zero(m);
  } else {
    block.Wa = RowMatrix6::Zero(m, 6);
    block.Wb = RowMatrix6::Zero(m, 6);
    block.b = RowVector6::Zero(m);
    block.kappa = RowVector6::Zero(m);
    block.gap = RowVector6::Zero(m);
  }
}

}  // namespace appell
