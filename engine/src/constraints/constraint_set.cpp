#include <appell/constraint_set.hpp>
#include <appell/kinematics.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace appell {

ConstraintData::ConstraintData(const Model& model, const ConstraintList& constraints,
                               DenseRows dense)
    : blocks(constraints.size()) {
  for (size_t k = 0; k < constraints.size(); ++k) {
    if (!constraints[k]) throw std::invalid_argument("constraint list holds a null constraint");
    offset.push_back(m);
    constraints[k]->reserve(model, blocks[k]);
    for (int r = 0; r < constraints[k]->rows(); ++r) {
      holonomic.push_back(constraints[k]->holonomic(r));
      row_constraint.push_back(static_cast<int>(k));
    }
    m += constraints[k]->rows();
  }
  active.assign(constraints.size(), 1);
  sliding.assign(constraints.size(), 0);
  regularized.assign(constraints.size(), 0);
  slide.resize(constraints.size());
  for (size_t k = 0; k < constraints.size(); ++k) {
    const Constraint& c = *constraints[k];
    if (c.jointSpace() || !c.unilateral()) continue;
    for (int r = 0; r < c.rows() && slide[k].n < 3; ++r)
      if (isTangential(c.rowKind(r))) slide[k].row[slide[k].n++] = r;
    // Spin friction: the spin row joins the friction rows, in the unit that
    // makes the friction set the ball of radius μλₙ (Leine & Glocker 2003).
    const double ell = c.spinFriction(), mu = c.friction();
    if (std::isfinite(ell) && std::isfinite(mu) && mu > 0 && slide[k].n < 3)
      for (int r = 0; r < c.rows(); ++r)
        if (c.rowKind(r) == RowKind::Spin) {
          slide[k].scale[slide[k].n] = ell / mu;
          slide[k].row[slide[k].n++] = r;
          break;
        }
    regularized[k] = slide[k].n > 0 && std::isfinite(mu) && c.creepSpeed() > 0;
  }
  m_active = m;
  b = VecX::Zero(m);
  gap = VecX::Zero(m);
  if (dense == DenseRows::Sized) {
    has_dense = true;
    A = MatX::Zero(m, model.nv);
    abias = VecX::Zero(m);
    J = MatX::Zero(6, model.nv);
  }
}

namespace {
int rowsOf(const ConstraintData& cd, int c) {
  return c + 1 < static_cast<int>(cd.offset.size()) ? cd.offset[c + 1] - cd.offset[c] : cd.m - cd.offset[c];
}
}  // namespace

void ConstraintData::setActive(int constraint, bool closed) {
  if (isActive(constraint) == closed) return;
  active[constraint] = closed ? 1 : 0;
  const int rows = isSliding(constraint) ? 1 : rowsOf(*this, constraint);
  m_active += closed ? rows : -rows;
  // An open contact neither sticks nor slides; it closes sticking, or
  // sliding when its friction is regularized (it has no sticking mode).
  sliding[constraint] = 0;
  if (closed && regularized[constraint]) setSliding(constraint, true);
}

void ConstraintData::setSliding(int constraint, bool slides) {
  if (isSliding(constraint) == slides) return;
  sliding[constraint] = slides ? 1 : 0;
  if (isActive(constraint)) m_active += (slides ? -1 : 1) * (rowsOf(*this, constraint) - 1);
}

void evaluateConstraintRows(const Model& model, Data& data, const ConstraintList& constraints,
                            ConstraintData& cd, double t, const VecX& q, const VecX& v) {
  data.ddq.setZero();
  forwardKinematics(model, data, q, v, data.ddq);
  cd.singular = false;
  for (size_t k = 0; k < constraints.size(); ++k) {
    const Constraint& c = *constraints[k];
    RowBlock& blk = cd.blocks[k];
    if (cd.closed_only && !cd.isActive(static_cast<int>(k))) continue;  // (its rows are zero)
    blk.singular = false;
    c.evaluate(model, data, t, q, v, blk);
    // An open contact's rows are not used: its singular geometry (a flat disk
    // far above the ground) stops nothing.
    if (blk.singular && cd.isActive(static_cast<int>(k)) && !cd.singular) {
      cd.singular = true;
      cd.singular_reason = c.name() + ": " + blk.singular_reason;
    }
    const int o = cd.offset[k], m = c.rows();
    if (!cd.isActive(static_cast<int>(k))) {
      // Open: zero rows (no constraint on v, λ = 0 in every formulation); the
      // gap and the frame stay — the clearance touchdown is detected on.
      if (c.jointSpace()) {
        blk.A_joint.setZero();
        blk.b_joint.setZero();
        blk.abias_joint.setZero();
      } else {
        blk.Wa.setZero();
        blk.Wb.setZero();
        blk.b.setZero();
        blk.kappa.setZero();
      }
      cd.b.segment(o, m).setZero();
      if (c.jointSpace()) {
        if (blk.gap.size() == m) cd.gap.segment(o, m) = blk.gap;
        else cd.gap.segment(o, m).setZero();
      } else {
        cd.gap.segment(o, m) = blk.gap;
      }
      continue;
    }
    if (cd.isSliding(static_cast<int>(k))) {
      // Sliding: keep the friction rows' directions and slip velocities, then
      // leave only the normal row.
      ConstraintData::SlidingRows& sr = cd.slide[k];
      const int a = c.bodyA(), bb = c.bodyB();
      const Vec6 Va = a >= 0 ? Vec6(data.oMi[a].act(data.v[a])) : Vec6::Zero();
      const Vec6 Vb = bb >= 0 ? Vec6(data.oMi[bb].act(data.v[bb])) : Vec6::Zero();
      for (int i = 0; i < sr.n; ++i) {
        const int r = sr.row[i];
        const double s = sr.scale[i];
        sr.Wa.row(i) = s * blk.Wa.row(r);
        sr.Wb.row(i) = s * blk.Wb.row(r);
        sr.kappa[i] = s * blk.kappa[r];
        sr.slip[i] = s * (blk.b[r] + (a >= 0 ? blk.Wa.row(r).dot(Va) : 0.0) -
                          (bb >= 0 ? blk.Wb.row(r).dot(Vb) : 0.0));
      }
      const int keep = c.unilateralRow();
      for (int r = 0; r < m; ++r) {
        if (r == keep) continue;
        blk.Wa.row(r).setZero();
        blk.Wb.row(r).setZero();
        blk.b[r] = blk.kappa[r] = 0;
      }
    }
    if (c.jointSpace()) {
      cd.b.segment(o, m) = blk.b_joint;
      // Holonomic joint-space rows report their gaps in blk.gap (≤ 6 rows).
      if (blk.gap.size() == m) cd.gap.segment(o, m) = blk.gap;
      else cd.gap.segment(o, m).setZero();
    } else {
      cd.b.segment(o, m) = blk.b;
      cd.gap.segment(o, m) = blk.gap;
    }
  }
}

void assembleConstraintRows(const Model& model, const Data& data, const Constraint& c,
                            const RowBlock& blk, MatX& J, Eigen::Ref<MatX> A,
                            Eigen::Ref<VecX> abias) {
  if (c.jointSpace()) {  // scatter the sparse columns
    A.setZero();
    for (size_t k = 0; k < blk.joint_cols.size(); ++k)
      A.col(blk.joint_cols[k]) = blk.A_joint.col(static_cast<int>(k));
    abias = blk.abias_joint;
    return;
  }
  // A = Wₐ Jₐ − W_b J_b,  abias = κ + Wₐ J̇ₐv − W_b J̇_b v.
  const int m = c.rows();
  A.setZero();
  abias = blk.kappa.head(m);
  const int bodies[2] = {c.bodyA(), c.bodyB()};
  for (int s = 0; s < 2; ++s) {
    if (bodies[s] < 0) continue;
    const double sign = s == 0 ? 1.0 : -1.0;
    const RowMatrix6& W = s == 0 ? blk.Wa : blk.Wb;
    spatialJacobianWorld(model, data, bodies[s], J);
    A.noalias() += sign * W * J;
    abias.noalias() += sign * W * spatialAccelerationWorld(data, bodies[s]);
  }
}

void assembleDenseRows(const Model& model, const Data& data, const ConstraintList& constraints,
                       ConstraintData& cd) {
  if (!cd.has_dense)
    throw std::logic_error(
        "assembleDenseRows: this ConstraintData was built without dense storage "
        "(DenseRows::None)");
  for (size_t k = 0; k < constraints.size(); ++k) {
    const int o = cd.offset[k], m = constraints[k]->rows();
    if (!cd.isActive(static_cast<int>(k))) {  // an open contact: zero rows, λ = 0
      cd.A.middleRows(o, m).setZero();
      cd.abias.segment(o, m).setZero();
      continue;
    }
    assembleConstraintRows(model, data, *constraints[k], cd.blocks[k], cd.J, cd.A.middleRows(o, m),
                           cd.abias.segment(o, m));
  }
}

void evaluateConstraints(const Model& model, Data& data, const ConstraintList& constraints,
                         ConstraintData& cd, double t, const VecX& q, const VecX& v) {
  evaluateConstraintRows(model, data, constraints, cd, t, q, v);
  assembleDenseRows(model, data, constraints, cd);
}

namespace {

/// Calls row(global index, A v + b) for each row of the closed constraints.
template <typename F>
void forEachRowResidual(const Data& data, const ConstraintList& constraints,
                        const ConstraintData& cd, const VecX& v, F&& row) {
  for (size_t k = 0; k < constraints.size(); ++k) {
    const Constraint& c = *constraints[k];
    const RowBlock& blk = cd.blocks[k];
    const int o = cd.offset[k], m = c.rows();
    if (!cd.isActive(static_cast<int>(k))) continue;
    if (c.jointSpace()) {
      for (int i = 0; i < m; ++i) row(o + i, jointRowDot(blk, i, v) + cd.b[o + i]);
      continue;
    }
    // wₐ·Vₐ − w_b·V_b + b with world-frame body velocities V = ᵒX V^body.
    const int a = c.bodyA(), bb = c.bodyB();
    const Vec6 Va = a >= 0 ? Vec6(data.oMi[a].act(data.v[a])) : Vec6::Zero();
    const Vec6 Vb = bb >= 0 ? Vec6(data.oMi[bb].act(data.v[bb])) : Vec6::Zero();
    for (int i = 0; i < m; ++i) {
      double value = cd.b[o + i];
      if (a >= 0) value += blk.Wa.row(i).dot(Va);
      if (bb >= 0) value -= blk.Wb.row(i).dot(Vb);
      row(o + i, value);
    }
  }
}

}  // namespace

double velocityResidual(const Data& data, const ConstraintList& constraints,
                        const ConstraintData& cd, const VecX& v) {
  double r = 0;  // row by row: no temporary vector
  forEachRowResidual(data, constraints, cd, v,
                     [&](int, double value) { r = std::max(r, std::abs(value)); });
  return r;
}

void velocityResiduals(const Data& data, const ConstraintList& constraints,
                       const ConstraintData& cd, const VecX& v, VecX& residual) {
  residual = cd.b;  // open constraints: zero rows
  forEachRowResidual(data, constraints, cd, v, [&](int i, double value) { residual[i] = value; });
}

double velocityResidual(const Model& model, Data& data, const ConstraintList& constraints,
                        const ConstraintData& cd, const VecX& q, const VecX& v) {
  forwardKinematics(model, data, q, v);
  return velocityResidual(data, constraints, cd, v);
}

void shiftRowOffsets(const ConstraintList& constraints, ConstraintData& cd, const VecX& delta) {
  for (size_t k = 0; k < constraints.size(); ++k) {
    if (!cd.isActive(static_cast<int>(k))) continue;  // zero rows stay zero
    const Constraint& c = *constraints[k];
    RowBlock& blk = cd.blocks[k];
    const int o = cd.offset[k], m = c.rows();
    for (int r = 0; r < m; ++r) {
      if (c.jointSpace()) blk.b_joint[r] += delta[o + r];
      else blk.b[r] += delta[o + r];
      cd.b[o + r] += delta[o + r];
    }
  }
}

double gapResidual(const ConstraintData& cd) {
  double r = 0;  // closed constraints only: an open contact's gap is its clearance
  for (int i = 0; i < cd.m; ++i)
    if (cd.isActive(cd.row_constraint[i])) r = std::max(r, std::abs(cd.gap[i]));
  return r;
}

}  // namespace appell
