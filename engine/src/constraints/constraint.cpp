#include <appell/constraint.hpp>

#include <stdexcept>

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

std::vector<int> Constraint::jointColumns(const Model& model) const {
  std::vector<int> all(model.nv);
  for (int k = 0; k < model.nv; ++k) all[k] = k;
  return all;
}

void Constraint::reserve(const Model& model, RowBlock& block) const {
  const int m = rows();
  block.m = m;
  if (jointSpace()) {
    block.joint_cols = jointColumns(model);
    for (int k : block.joint_cols)
      if (k < 0 || k >= model.nv)
        throw std::invalid_argument("constraint '" + name() + "': joint column " +
                                    std::to_string(k) + " outside v (nv = " +
                                    std::to_string(model.nv) + ")");
    block.A_joint = MatX::Zero(m, static_cast<int>(block.joint_cols.size()));
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
