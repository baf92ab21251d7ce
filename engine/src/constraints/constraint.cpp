#include <appell/constraint.hpp>

namespace appell {

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
