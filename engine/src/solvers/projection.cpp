// Drift projection (projection.hpp): Newton on the holonomic gaps in the
// mass metric, then the solver's impulse solve. It lives with the solvers
// because its Newton steps are solves — the tree solver's O(n) one, or the
// dense row basis (row_basis.hpp) — so engine/src/constraints needs nothing
// from engine/src/solvers.
#include <appell/configuration.hpp>
#include <appell/dynamics.hpp>
#include <appell/projection.hpp>

#include <appell/tree_solver.hpp>

#include "solvers/row_basis.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace appell {

struct PositionProjector::Impl {
  Impl(const Model& model, const ConstraintList& constraints, const ProjectionOptions& o,
       TreeSolver* shared)
      : opt(o), mh(countHolonomic(constraints)), y(VecX::Zero(model.nv)),
        theta(VecX::Zero(model.nv)), v0(VecX::Zero(model.nv)), q_start(VecX::Zero(model.nq)),
        q_next(VecX::Zero(model.nq)) {
    if (!(o.gap_tol > 0) || o.max_iterations < 1)
      throw std::invalid_argument("ProjectionOptions: gap_tol must be > 0 and max_iterations >= 1");
    for (size_t k = 0; k < constraints.size(); ++k) {
      const Constraint& c = *constraints[k];
      bool any = false;
      for (int r = 0; r < c.rows(); ++r) {
        holonomic_flags.push_back(c.holonomic(r));
        any = any || c.holonomic(r);
      }
      has_gap.push_back(any ? 1 : 0);
      if (any) with_gaps.push_back(static_cast<int>(k));
    }
    for (int i = 0; i < static_cast<int>(holonomic_flags.size()); ++i)
      if (holonomic_flags[i]) row_map.push_back(i);
    g = VecX::Zero(mh);
    if (mh > 0) {
      rows = std::make_unique<ConstraintData>(model, constraints, DenseRows::None);
      if (!shared) own = std::make_unique<TreeSolver>(model, constraints, o.rank);
      tree = shared ? shared : own.get();
      impulse = VecX::Zero(rows->m);
    }
  }

  /// The holonomic rows of cdata as a constraint set of their own: rows
  /// that are not holonomic, and constraints that are open or have no gap,
  /// write zero rows; b of a holonomic row is its gap, so the velocity
  /// projection of v = 0 is the Newton step A_hol δ = −g.
  void holonomicRows(const ConstraintList& constraints, const ConstraintData& cdata) {
    ConstraintData& h = *rows;
    h.singular = false;
    for (size_t k = 0; k < constraints.size(); ++k) {
      const int c = static_cast<int>(k);
      const bool use = has_gap[c] && cdata.isActive(c);
      h.setActive(c, use);
      if (!use) continue;
      const Constraint& con = *constraints[c];
      const RowBlock& in = cdata.blocks[c];
      RowBlock& out = h.blocks[c];
      const int o = cdata.offset[c], m = con.rows();
      if (con.jointSpace()) {
        out.A_joint = in.A_joint;  // same size: no allocation
        for (int r = 0; r < m; ++r) {
          const bool hol = holonomic_flags[o + r];
          if (!hol) out.A_joint.row(r).setZero();
          out.b_joint[r] = hol ? cdata.gap[o + r] : 0.0;
        }
        continue;
      }
      out.Wa = in.Wa;
      out.Wb = in.Wb;
      for (int r = 0; r < m; ++r) {
        const bool hol = holonomic_flags[o + r];
        if (!hol) {
          out.Wa.row(r).setZero();
          out.Wb.row(r).setZero();
        }
        out.b[r] = hol ? cdata.gap[o + r] : 0.0;
      }
    }
  }

  /// Of the holonomic rows at q, how close the kept ones are to dependent
  /// (the weakest pivot of their mass-metric QR) and which row that is — the
  /// root cause to name when Newton stalls. Dense (O(m n²)), so only on that
  /// failure and only for models small enough to afford it; −1 otherwise.
  double weakestRow(const Model& model, Data& data, const ConstraintList& constraints,
                    const ConstraintData& cdata, const VecX& q, int& row) const {
    row = -1;
    if (model.nv > kDenseDiagnosisMaxNv) return -1;
    MatX Ah = MatX::Zero(mh, model.nv), J = MatX::Zero(6, model.nv);
    int k = 0;
    for (int c : with_gaps) {
      const Constraint& con = *constraints[c];
      const int o = cdata.offset[c], m = con.rows();
      MatX Ak = MatX::Zero(m, model.nv);
      VecX ab = VecX::Zero(m);
      if (cdata.isActive(c)) assembleConstraintRows(model, data, con, cdata.blocks[c], J, Ak, ab);
      for (int r = 0; r < m; ++r)
        if (holonomic_flags[o + r]) Ah.row(k++) = Ak.row(r);
    }
    const Eigen::LLT<MatX> llt(crba(model, data, q));
    if (llt.info() != Eigen::Success) return -1;
    MatX B = Ah.transpose();
    llt.matrixL().solveInPlace(B);
    detail::RowBasis basis(model.nv, mh);
    basis.factor(B, opt.rank, /*form_q=*/false);
    if (basis.rank() == 0) return -1;
    row = row_map[basis.pivot(basis.rank() - 1)];
    return basis.weakestPivotRatio();
  }

  static int countHolonomic(const ConstraintList& constraints) {
    int n = 0;
    for (const auto& c : constraints) {
      if (!c) throw std::invalid_argument("constraint list holds a null constraint");
      for (int r = 0; r < c->rows(); ++r) n += c->holonomic(r) ? 1 : 0;
    }
    return n;
  }

  /// Largest model the stall diagnosis factors densely.
  static constexpr int kDenseDiagnosisMaxNv = 2000;

  ProjectionOptions opt;
  int mh;
  std::unique_ptr<ConstraintData> rows;  // the holonomic rows alone (holonomicRows)
  std::unique_ptr<TreeSolver> own;       // the O(n) mass-metric projection of each step,
  TreeSolver* tree = nullptr;            // own or shared
  VecX g, y, theta, v0, q_start, q_next, impulse;
  std::vector<char> holonomic_flags, has_gap;
  std::vector<int> row_map;    // holonomic row → row of the system
  std::vector<int> with_gaps;  // constraints with at least one holonomic row
};

PositionProjector::PositionProjector(const Model& model, const ConstraintList& constraints,
                                     const ProjectionOptions& options, TreeSolver* shared)
    : impl_(std::make_unique<Impl>(model, constraints, options, shared)) {}
PositionProjector::~PositionProjector() = default;
PositionProjector::PositionProjector(PositionProjector&&) noexcept = default;
PositionProjector& PositionProjector::operator=(PositionProjector&&) noexcept = default;
int PositionProjector::holonomicRows() const { return impl_->mh; }
const ProjectionOptions& PositionProjector::options() const { return impl_->opt; }

PositionProjectionResult PositionProjector::project(const Model& model, Data& data,
                                                    const ConstraintList& constraints,
                                                    ConstraintData& cdata, double t, VecX& q,
                                                    bool rows_current) {
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
    if (it > 0 || !rows_current) evaluateConstraintRows(model, data, constraints, cdata, t, q, w.v0);
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
      int row = -1;
      const double ratio = it > 0 ? w.weakestRow(model, data, constraints, cdata, q, row) : -1;
      if (row >= 0 && ratio < 1e-4) {
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
    // Least-M-norm Newton step A_hol δ = −g: the velocity projection of
    // v = 0 onto the holonomic rows with their gaps as b — the tree solver's,
    // O(n) and rank-aware (redundant gap rows are fine, contradictory ones
    // an error naming them).
    w.holonomicRows(constraints, cdata);
    w.y.setZero();
    if (!w.tree->projectVelocity(model, data, constraints, *w.rows, q, w.y, w.impulse))
      return fail("holonomic gaps cannot be closed: " + w.tree->lastError());
    res.rank = w.rows->m_active - w.tree->redundantRows();
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
