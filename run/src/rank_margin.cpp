// The near-dependency watch (rank_margin.hpp): the closed rows' smallest
// kept singular value, equilibrated as the solvers equilibrate them.
//
// With M = LLᵀ and A the closed rows (open contacts' and sliding contacts'
// friction rows are zero rows, as the solvers see them), B = L⁻¹Aᵀ D holds
// the rows in the mass metric, each column scaled to unit norm (D; a column
// at or below rank_rel_tol of the largest is a zero row, as in
// docs/solvers.md). Its SVD B = U Σ Vᵀ gives the rank test the solvers apply
// to pivots — σ > rank_abs_tol + rank_rel_tol — and for the smallest kept
// σᵣ the rows' combination Vᵣ that nearly cancels and the motion
// v = L⁻ᵀUᵣ (unit kinetic energy ½) that violates the equilibrated rows only
// by σᵣ Vᵣ: the freedom that an exact dependency would leave and the margin
// locks (Golub & Van Loan, Matrix Computations, 4th ed. 2013, §5.4.1: the
// SVD as the reliable rank revealer, σᵣ the distance to the nearest matrix
// of lower rank).
#include "rank_margin.hpp"

#include <appell/constrained_dynamics.hpp>
#include <appell/constraint_set.hpp>
#include <appell/dynamics.hpp>
#include <appell/kinematics.hpp>
#include <appell/output.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace appell::run_detail {

namespace {

constexpr int kChecksPerRun = 256;  ///< checks spread over the duration (plus events)
constexpr double kShare = 0.2;      ///< entries named: ≥ this of the largest
/// Larger models are not watched: the dense check (O(nv³), nv² memory)
/// would outweigh the run (a 10⁵-body chain has no nv × nv matrix anywhere).
constexpr int kMaxVelocities = 300, kMaxRows = 1200;
/// Event steps check at most this often (of the regular spacing): a run
/// with thousands of events does not pay a dense check for each.
constexpr double kEventSpacing = 1.0 / 16;

int totalRows(const Scene& scene) {
  int m = 0;
  for (const auto& c : scene.constraints) m += c->rows();
  return m;
}

/// Indices of x's entries of at least kShare·max|x|, largest first.
std::vector<int> largest(const VecX& x) {
  std::vector<int> idx;
  const double top = x.cwiseAbs().maxCoeff();
  for (int i = 0; i < x.size(); ++i)
    if (std::abs(x[i]) >= kShare * top && top > 0) idx.push_back(i);
  std::sort(idx.begin(), idx.end(), [&](int a, int b) { return std::abs(x[a]) > std::abs(x[b]); });
  return idx;
}

}  // namespace

RankMarginWatch::RankMarginWatch(const Scene& scene, const RunOptions& options)
    : scene_(scene),
      threshold_(SolverOptions{}.rank_abs_tol + SolverOptions{}.rank_rel_tol),
      rel_tol_(SolverOptions{}.rank_rel_tol),
      every_(options.duration / kChecksPerRun) {
  const int nv = scene.model.nv, m = totalRows(scene);
  if (!(options.near_dependency_level > 0) || m == 0 || nv > kMaxVelocities || m > kMaxRows)
    return;  // inactive: nothing allocated
  level_ = options.near_dependency_level;
  coordinates_ = coordinateNames(scene.model, true);
  data_ = std::make_unique<Data>(scene.model);
  A_.setZero(m, nv);
  J_.setZero(6, nv);
  B_.setZero(nv, m);
  abias_.setZero(m);
  scale_.setZero(m);
  llt_ = Eigen::LLT<MatX>(nv);
  svd_ = std::make_unique<Eigen::JacobiSVD<MatX>>(nv, m,
                                                  Eigen::ComputeThinU | Eigen::ComputeThinV);
}

void RankMarginWatch::sample(const Simulator& sim, bool event, NearDependency& out) {
  if (!active()) return;
  const bool regular = sim.time() >= next_;
  if (!regular && !(event && sim.time() >= last_ + kEventSpacing * every_)) return;
  while (next_ <= sim.time()) next_ += every_;
  last_ = sim.time();
  check(sim, out);
}

void RankMarginWatch::check(const Simulator& sim, NearDependency& out) {
  const Model& model = scene_.model;
  const ConstraintData& cd = sim.constraintData();
  Data& data = *data_;
  forwardKinematics(model, data, sim.q(), sim.v(), VecX::Zero(model.nv));
  A_.setZero();
  for (std::size_t c = 0; c < scene_.constraints.size(); ++c) {
    if (!cd.isActive(static_cast<int>(c))) continue;
    const Constraint& con = *scene_.constraints[c];
    const int r0 = cd.offset[c], r = con.rows();
    assembleConstraintRows(model, data, con, cd.blocks[c], J_, A_.middleRows(r0, r),
                           abias_.segment(r0, r));
  }
  llt_.compute(crba(model, data, sim.q()));
  B_ = A_.transpose();
  llt_.matrixL().solveInPlace(B_);
  scale_ = B_.colwise().norm().transpose();
  const double top = scale_.maxCoeff();
  if (!(top > 0)) return;
  for (int i = 0; i < B_.cols(); ++i) {
    if (scale_[i] <= rel_tol_ * top) scale_[i] = 0;  // a zero row (or no row)
    B_.col(i) *= scale_[i] > 0 ? 1 / scale_[i] : 0.0;
  }
  svd_->compute(B_);
  ++out.checks;
  const VecX& s = svd_->singularValues();
  int rank = 0;
  while (rank < s.size() && s[rank] > threshold_) ++rank;
  if (rank == 0 || !(s[rank - 1] < level_)) return;
  ++out.samples;
  if (!out.found) out.t_first = sim.time();
  if (out.found && !(s[rank - 1] < out.sigma)) return;
  out.found = true;
  out.t = sim.time();
  out.sigma = s[rank - 1];
  out.threshold = threshold_;
  describe(sim, rank - 1, out);
}

void RankMarginWatch::describe(const Simulator& sim, int k, NearDependency& out) {
  const ConstraintData& cd = sim.constraintData();
  out.rows.clear();
  for (int i : largest(svd_->matrixV().col(k))) {
    const int c = cd.row_constraint[i];
    out.rows.push_back(scene_.constraints[c]->name() + "." +
                       scene_.constraints[c]->rowLabel(i - cd.offset[c]));
  }
  VecX motion = svd_->matrixU().col(k);
  llt_.matrixU().solveInPlace(motion);  // L⁻ᵀ u
  const std::vector<int> idx = largest(motion);
  out.freedom.clear();
  for (int i : idx) out.freedom.emplace_back(coordinates_[i], motion[i] / motion[idx.front()]);
}

}  // namespace appell::run_detail
