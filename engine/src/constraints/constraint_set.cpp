#include <appell/constraint_set.hpp>
#include <appell/kinematics.hpp>

#include <algorithm>
#include <cmath>

namespace appell {

ConstraintData::ConstraintData(const Model& model, const ConstraintList& constraints)
    : blocks(constraints.size()), J(MatX::Zero(6, model.nv)) {
  for (size_t k = 0; k < constraints.size(); ++k) {
    offset.push_back(m);
    constraints[k]->reserve(model, blocks[k]);
    for (int r = 0; r < constraints[k]->rows(); ++r) {
      holonomic.push_back(constraints[k]->holonomic(r));
      row_constraint.push_back(static_cast<int>(k));
    }
    m += constraints[k]->rows();
  }
  A = MatX::Zero(m, model.nv);
  b = VecX::Zero(m);
  abias = VecX::Zero(m);
  gap = VecX::Zero(m);
}

void evaluateConstraints(const Model& model, Data& data, const ConstraintList& constraints,
                         ConstraintData& cd, double t, const VecX& q, const VecX& v) {
  data.ddq.setZero();
  forwardKinematics(model, data, q, v, data.ddq);
  cd.singular = false;
  for (size_t k = 0; k < constraints.size(); ++k) {
    const Constraint& c = *constraints[k];
    RowBlock& blk = cd.blocks[k];
    blk.singular = false;
    c.evaluate(model, data, t, q, v, blk);
    if (blk.singular && !cd.singular) {
      cd.singular = true;
      cd.singular_reason = c.name() + ": " + blk.singular_reason;
    }
    const int o = cd.offset[k], m = c.rows();
    if (c.jointSpace()) {
      cd.A.middleRows(o, m) = blk.A_joint;
      cd.b.segment(o, m) = blk.b_joint;
      cd.abias.segment(o, m) = blk.abias_joint;
      // Holonomic joint-space rows report their gaps in blk.gap (≤ 6 rows).
      if (blk.gap.size() == m) cd.gap.segment(o, m) = blk.gap;
      else cd.gap.segment(o, m).setZero();
      continue;
    }
    // Rows over body velocities: A = Wₐ Jₐ − W_b J_b, abias = κ + Wₐ J̇ₐv − W_b J̇_b v.
    cd.b.segment(o, m) = blk.b;
    cd.abias.segment(o, m) = blk.kappa;
    cd.gap.segment(o, m) = blk.gap;
    cd.A.middleRows(o, m).setZero();
    const int bodies[2] = {c.bodyA(), c.bodyB()};
    for (int s = 0; s < 2; ++s) {
      if (bodies[s] < 0) continue;
      const double sign = s == 0 ? 1.0 : -1.0;
      const RowMatrix6& W = s == 0 ? blk.Wa : blk.Wb;
      spatialJacobianWorld(model, data, bodies[s], cd.J);
      cd.A.middleRows(o, m).noalias() += sign * W * cd.J;
      cd.abias.segment(o, m).noalias() += sign * W * spatialAccelerationWorld(data, bodies[s]);
    }
  }
}

double velocityResidual(const ConstraintData& cd, const VecX& v) {
  double r = 0;  // row by row: no temporary vector
  for (int i = 0; i < cd.m; ++i) r = std::max(r, std::abs(cd.A.row(i).dot(v) + cd.b[i]));
  return r;
}

double gapResidual(const ConstraintData& cd) {
  return cd.m == 0 ? 0.0 : cd.gap.lpNorm<Eigen::Infinity>();
}

}  // namespace appell
