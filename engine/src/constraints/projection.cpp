#include <appell/appell_maggi.hpp>
#include <appell/configuration.hpp>
#include <appell/dynamics.hpp>
#include <appell/kkt.hpp>
#include <appell/projection.hpp>

#include "solvers/row_basis.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace appell {

struct PositionProjector::Impl {
  Impl(const Model& model, const ConstraintList& constraints, const ProjectionOptions& o)
      : opt(o), mh(countHolonomic(constraints)), llt(model.nv), basis(model.nv, mh),
        Ah(MatX::Zero(mh, model.nv)), B(MatX::Zero(model.nv, mh)), g(VecX::Zero(mh)),
        y(VecX::Zero(model.nv)), theta(VecX::Zero(model.nv)), v0(VecX::Zero(model.nv)),
        q_start(VecX::Zero(model.nq)), q_next(VecX::Zero(model.nq)) {
    if (!(o.gap_tol > 0) || o.max_iterations < 1)
      throw std::invalid_argument("ProjectionOptions: gap_tol must be > 0 and max_iterations >= 1");
    for (const auto& c : constraints)
      for (int r = 0; r < c->rows(); ++r) holonomic_flags.push_back(c->holonomic(r));
    for (int i = 0; i < static_cast<int>(holonomic_flags.size()); ++i)
      if (holonomic_flags[i]) row_map.push_back(i);
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
  Eigen::LLT<MatX> llt;
  detail::RowBasis basis;
  MatX Ah, B;
  VecX g, y, theta, v0, q_start, q_next;
  std::vector<char> holonomic_flags;
  std::vector<int> row_map;  // holonomic row → dense row
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
    evaluateConstraints(model, data, constraints, cdata, t, q, w.v0);
    res.ok = false;
    res.error = std::move(why);
    return res;
  };
  double prev = std::numeric_limits<double>::infinity();
  for (int it = 0;; ++it) {
    evaluateConstraints(model, data, constraints, cdata, t, q, w.v0);
    if (cdata.singular) return fail("singular contact geometry: " + cdata.singular_reason);
    for (int k = 0; k < w.mh; ++k) w.g[k] = cdata.gap[w.row_map[k]];
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
      return fail(os.str());
    }
    prev = gmax;
    // Least-M-norm Newton step: A_hol δ = −g,  δ = L⁻ᵀ y,  (A_hol L⁻ᵀ) y = −g.
    w.llt.compute(crba(model, data, q));
    if (w.llt.info() != Eigen::Success) return fail("mass matrix is not positive definite");
    for (int k = 0; k < w.mh; ++k) w.Ah.row(k) = cdata.A.row(w.row_map[k]);
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

namespace {

std::string solverError(const ConstrainedSolver& solver) {
  if (auto* k = dynamic_cast<const KktSolver*>(&solver)) return k->lastError();
  if (auto* a = dynamic_cast<const AppellSolver*>(&solver)) return a->lastError();
  return "the constraint rows are inconsistent";
}

}  // namespace

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
  // cdata now holds A(q, t), b(q, t) at the projected q.
  if (!solver.projectVelocity(model, data, constraints, cdata, q, v, impulse)) {
    res.ok = false;
    res.error = "velocity projection failed: " + solverError(solver);
    return res;
  }
  res.velocity_residual = velocityResidual(cdata, v);
  res.gap_residual = gapResidual(cdata);
  return res;
}

void applyBaumgarte(ConstraintData& cdata, const VecX& v, double alpha, double beta) {
  if (cdata.m == 0) return;
  cdata.abias.noalias() += (2.0 * alpha) * (cdata.A * v);
  cdata.abias += (2.0 * alpha) * cdata.b + (beta * beta) * cdata.gap;
}

}  // namespace appell
