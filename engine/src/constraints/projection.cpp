#include <appell/configuration.hpp>
#include <appell/dynamics.hpp>
#include <appell/projection.hpp>

#include "solvers/row_basis.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace appell {

struct PositionProjector::Impl {
  Impl(const Model& model, const ConstraintList& constraints, const ProjectionOptions& o)
      : opt(o), mh(countHolonomic(constraints)), nd(mh > 0 ? model.nv : 0), llt(nd),
        basis(nd, mh), Ah(MatX::Zero(mh, nd)), B(MatX::Zero(nd, mh)), J(MatX::Zero(6, nd)),
        g(VecX::Zero(mh)),
        y(VecX::Zero(model.nv)), theta(VecX::Zero(model.nv)), v0(VecX::Zero(model.nv)),
        q_start(VecX::Zero(model.nq)), q_next(VecX::Zero(model.nq)) {
    if (!(o.gap_tol > 0) || o.max_iterations < 1)
      throw std::invalid_argument("ProjectionOptions: gap_tol must be > 0 and max_iterations >= 1");
    int rows_max = 0;
    for (size_t k = 0; k < constraints.size(); ++k) {
      const Constraint& c = *constraints[k];
      bool any = false;
      for (int r = 0; r < c.rows(); ++r) {
        holonomic_flags.push_back(c.holonomic(r));
        any = any || c.holonomic(r);
      }
      if (any) {
        with_gaps.push_back(static_cast<int>(k));
        rows_max = std::max(rows_max, c.rows());
      }
    }
    for (int i = 0; i < static_cast<int>(holonomic_flags.size()); ++i)
      if (holonomic_flags[i]) row_map.push_back(i);
    Ak = MatX::Zero(rows_max, nd);
    abias_k = VecX::Zero(rows_max);
  }

  /// A_hol: the holonomic rows of the dense form, assembled constraint by
  /// constraint from the rows (only the constraints that have a gap).
  void assembleHolonomicRows(const Model& model, const Data& data,
                             const ConstraintList& constraints, const ConstraintData& cdata) {
    int k = 0;
    for (int c : with_gaps) {
      const Constraint& con = *constraints[c];
      const int o = cdata.offset[c], m = con.rows();
      if (!cdata.isActive(c)) {  // an open contact: its gap is a clearance, not a constraint
        for (int r = 0; r < m; ++r)
          if (holonomic_flags[o + r]) Ah.row(k++).setZero();
        continue;
      }
      assembleConstraintRows(model, data, con, cdata.blocks[c], J, Ak.topRows(m),
                             abias_k.head(m));
      for (int r = 0; r < m; ++r)
        if (holonomic_flags[o + r]) Ah.row(k++) = Ak.row(r);
    }
  }

  static int countHolonomic(const ConstraintList& constraints) {
    int n = 0;
    for (const auto& c : constraints) {
      if (!c) throw std::invalid_argument("constraint list holds a null constraint");
      for (int r = 0; r < c->rows(); ++r) n += c->holonomic(r) ? 1 : 0;
    }
    return n;
  }

  ProjectionOptions opt;
  int mh;
  int nd;  // columns of the dense storage: nv, or 0 when there is nothing to project
           // (no nv × nv mass matrix for a model without holonomic rows)
  Eigen::LLT<MatX> llt;
  detail::RowBasis basis;
  MatX Ah, B, J, Ak;
  VecX g, y, theta, v0, q_start, q_next, abias_k;
  std::vector<char> holonomic_flags;
  std::vector<int> row_map;    // holonomic row → row of the system
  std::vector<int> with_gaps;  // constraints with at least one holonomic row
};

PositionProjector::PositionProjector(const Model& model, const ConstraintList& constraints,
                                     const ProjectionOptions& options)
    : impl_(std::make_unique<Impl>(model, constraints, options)) {}
PositionProjector::~PositionProjector() = default;
PositionProjector::PositionProjector(PositionProjector&&) noexcept = default;
PositionProjector& PositionProjector::operator=(PositionProjector&&) noexcept = default;
int PositionProjector::holonomicRows() const { return impl_->mh; }
const ProjectionOptions& PositionProjector::options() const { return impl_->opt; }

PositionProjectionResult PositionProjector::project(const Model& model, Data& data,
                                                    const ConstraintList& constraints,
                                                    ConstraintData& cdata, double t, VecX& q) {
  Impl& w = *impl_;
  PositionProjectionResult res;
  if (q.size() != model.nq)
    throw std::invalid_argument("projectPositions: q has size " + std::to_string(q.size()) +
                                ", expected nq = " + std::to_string(model.nq));
  if (cdata.m != static_cast<int>(w.holonomic_flags.size()))
    throw std::invalid_argument("projectPositions: constraint data does not match the constraints");
  w.q_start = q;
  auto fail = [&](std::string why) {
    q = w.q_start;
    evaluateConstraintRows(model, data, constraints, cdata, t, q, w.v0);
    res.ok = false;
    res.error = std::move(why);
    return res;
  };
  double prev = std::numeric_limits<double>::infinity();
  for (int it = 0;; ++it) {
    evaluateConstraintRows(model, data, constraints, cdata, t, q, w.v0);
    if (cdata.singular) return fail("singular contact geometry: " + cdata.singular_reason);
    for (int k = 0; k < w.mh; ++k) {
      const int row = w.row_map[k];
      w.g[k] = cdata.isActive(cdata.row_constraint[row]) ? cdata.gap[row] : 0.0;
    }
    const double gmax = w.mh ? w.g.lpNorm<Eigen::Infinity>() : 0.0;
    if (!std::isfinite(gmax)) return fail("non-finite holonomic gap");
    if (it == 0) res.initial_residual = gmax;
    res.residual = gmax;
    res.iterations = it;
    if (gmax <= w.opt.gap_tol) return res;
    // Stagnation at round-off: accept when small, the last step did not halve it.
    if (gmax > 0.5 * prev && gmax <= w.opt.stall_tol) return res;
    if (it == w.opt.max_iterations) {
      std::ostringstream os;
      os << "position projection did not converge: max |gap| = " << gmax << " after " << it
         << " Newton iterations (tolerance " << w.opt.gap_tol << ")";
      // Newton stalls where the rows it solves are close to dependent: say
      // so, naming the weakest row — the root cause (a wheel nearly flat, a
      // linkage near a dead point), not the symptom.
      const double ratio = w.basis.weakestPivotRatio();
      if (it > 0 && ratio < 1e-4) {
        const int row = w.row_map[w.basis.pivot(w.basis.rank() - 1)];
        const int c = cdata.row_constraint[row];
        os << ": the constraint geometry is close to singular there — the holonomic rows are "
              "nearly dependent (pivot ratio "
           << ratio << ", weakest row '" << constraints[c]->name() << "'/"
           << constraints[c]->rowLabel(row - cdata.offset[c])
           << "), e.g. a wheel nearly lying flat or a linkage near a dead point";
      }
      // A contact whose geometry is near its singular limit (a wheel almost
      // flat: the rim's curvature radius R/|P m| blows up, and so does
      // Newton's second-order error) is the cause wherever the rows are.
      int worst = -1;
      for (int c : w.with_gaps)
        if (cdata.isActive(c) && cdata.blocks[c].frame.margin < 1e-3 &&
            (worst < 0 || cdata.blocks[c].frame.margin < cdata.blocks[worst].frame.margin))
          worst = c;
      if (worst >= 0)
        os << ": contact '" << constraints[worst]->name()
           << "' is at the edge of its singular geometry (margin "
           << cdata.blocks[worst].frame.margin
           << ": a wheel almost lying flat, its normal within that sine of its axis)";
      return fail(os.str());
    }
    prev = gmax;
    // Least-M-norm Newton step: A_hol δ = −g,  δ = L⁻ᵀ y,  (A_hol L⁻ᵀ) y = −g.
    w.assembleHolonomicRows(model, data, constraints, cdata);  // before crba reuses data
    w.llt.compute(crba(model, data, q));
    if (w.llt.info() != Eigen::Success) return fail("mass matrix is not positive definite");
    w.B = w.Ah.transpose();
    w.llt.matrixL().solveInPlace(w.B);
    w.basis.factor(w.B, w.opt.rank, /*form_q=*/false);
    res.rank = w.basis.rank();
    w.g = -w.g;
    if (!w.basis.solveRows(w.g, w.y))
      return fail("holonomic gaps cannot be closed: " +
                  w.basis.describeInconsistency(constraints, cdata, &w.row_map));
    w.llt.matrixU().solveInPlace(w.y);
    localRate(model, q, w.v0, w.y, w.theta);  // θ = T(q, 0) δ
    retract(model, q, w.theta, w.q_next);
    q = w.q_next;
  }
}

PositionProjectionResult projectPositions(const Model& model, Data& data,
                                          const ConstraintList& constraints,
                                          ConstraintData& cdata, double t, VecX& q,
                                          const ProjectionOptions& options) {
  PositionProjector projector(model, constraints, options);
  return projector.project(model, data, constraints, cdata, t, q);
}

StateProjectionResult projectState(const Model& model, Data& data,
                                   const ConstraintList& constraints, ConstraintData& cdata,
                                   ConstrainedSolver& solver, PositionProjector& projector,
                                   double t, VecX& q, VecX& v, VecX& impulse) {
  StateProjectionResult res;
  res.position = projector.project(model, data, constraints, cdata, t, q);
  if (!res.position.ok) {
    res.ok = false;
    res.error = res.position.error;
    return res;
  }
  // cdata now holds the rows at the projected q.
  if (!solver.projectVelocity(model, data, constraints, cdata, q, v, impulse)) {
    res.ok = false;
    res.error = "velocity projection failed: " + solver.lastError();
    return res;
  }
  res.velocity_residual = velocityResidual(model, data, constraints, cdata, q, v);
  res.gap_residual = gapResidual(cdata);
  return res;
}

void applyBaumgarte(const Data& data, const ConstraintList& constraints, ConstraintData& cdata,
                    const VecX& v, double alpha, double beta) {
  // On the rows: κ (or Ȧv + ḃ of a joint-space row) gains 2α·(row value) + β²·gap;
  // the dense abias = κ + W J̇v, assembled from κ, inherits it.
  for (size_t k = 0; k < constraints.size(); ++k) {
    const Constraint& c = *constraints[k];
    RowBlock& blk = cdata.blocks[k];
    const int o = cdata.offset[k], m = c.rows();
    if (!cdata.isActive(static_cast<int>(k))) continue;
    const int a = c.bodyA(), bb = c.bodyB();
    Vec6 Va = Vec6::Zero(), Vb = Vec6::Zero();
    if (!c.jointSpace()) {
      if (a >= 0) Va = data.oMi[a].act(data.v[a]);
      if (bb >= 0) Vb = data.oMi[bb].act(data.v[bb]);
    }
    for (int r = 0; r < m; ++r) {
      double value = cdata.b[o + r];
      if (c.jointSpace()) value += jointRowDot(blk, r, v);
      else value += blk.Wa.row(r).dot(Va) - (bb >= 0 ? blk.Wb.row(r).dot(Vb) : 0.0);
      const double add = 2.0 * alpha * value + beta * beta * cdata.gap[o + r];
      if (c.jointSpace()) blk.abias_joint[r] += add;
      else blk.kappa[r] += add;
      if (cdata.has_dense) cdata.abias[o + r] += add;
    }
  }
}

}  // namespace appell
