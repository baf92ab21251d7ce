#include <appell/appell_maggi.hpp>
#include <appell/dynamics.hpp>

#include "solvers/row_basis.hpp"

#include <Eigen/LU>
#include <Eigen/SVD>

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace appell {

struct AppellSolver::Impl {
  Impl(int n_, int m_)
      : n(n_), m(m_), kmax(std::min(n_, m_)), basis(n_, m_), B(MatX::Zero(n_, m_)),
        N(MatX::Zero(n_, n_)), MN(MatX::Zero(n_, n_)), Mpad(MatX::Identity(n_, n_)), lltr(n_),
        xp(VecX::Zero(n_)), rhs(VecX::Zero(n_)), tmp(VecX::Zero(n_)), r(VecX::Zero(n_)),
        yE(VecX::Zero(n_)), lambda(VecX::Zero(m_)), cvec(VecX::Zero(m_)), fbuf(VecX::Zero(n_)),
        xbuf(VecX::Zero(n_)),
        Ar(MatX::Zero(kmax, n_)), cpqr(kmax, n_), Ad(MatX::Identity(kmax, kmax)),
        Ai(MatX::Zero(kmax, n_)), X(MatX::Zero(kmax, n_)), svd(kmax, kmax), lu(kmax),
        cr(VecX::Zero(kmax)), sol(VecX::Zero(kmax)), dep(n_, -1), indep(n_, -1),
        prev_dep(n_, -1) {}

  int n, m, kmax;
  detail::RowBasis basis;
  MatX B;                     // Aᵀ
  MatX N, MN, Mpad;           // basis, M N, [NᵀMN 0; 0 I]
  Eigen::LLT<MatX> lltr;
  VecX xp, rhs, tmp, r, yE, lambda, cvec, fbuf, xbuf;
  double range_residual = 0;

  // Coordinate partition.
  MatX Ar;                                 // independent rows, equilibrated (kmax × n)
  Eigen::ColPivHouseholderQR<MatX> cpqr;   // chooses the dependent columns
  MatX Ad, Ai, X;                          // [A_d 0; 0 I], A_i, A_d⁻¹A_i
  Eigen::JacobiSVD<MatX> svd;
  Eigen::PartialPivLU<MatX> lu;
  VecX cr, sol;
  std::vector<int> dep, indep, prev_dep;
  int ndep = -1, prev_ndep = -1;           // −1: no partition chosen yet
  int changes = 0;
  bool changed_last = false;
  double cond = 1, cond_at_change = 0;

  double dependentCondition() {
    if (kmax == 0) return 1.0;
    svd.compute(Ad);
    const double smin = svd.singularValues().minCoeff();
    return smin > 0 ? 1.0 / smin : std::numeric_limits<double>::infinity();
  }

  void gatherDependent(int rank) {
    Ad.setIdentity();
    for (int t = 0; t < rank; ++t) Ad.col(t).head(rank) = Ar.col(dep[t]).head(rank);
  }

  /// Keeps or re-chooses the dependent velocities for the rows of `A` (the
  /// basis is factored), then forms N = [−A_d⁻¹A_i; I] in N.leftCols(n − rank).
  void updatePartition(const MatX& A, double cond_max) {
    const int rank = basis.rank();
    Ar.setZero();
    for (int k = 0; k < rank; ++k) {
      const int i = basis.pivot(k);
      Ar.row(k) = basis.scale(i) * A.row(i);
    }
    changed_last = false;
    bool keep = ndep == rank;
    if (keep) {
      gatherDependent(rank);
      cond = dependentCondition();
      if (!(cond <= cond_max)) {
        keep = false;
        cond_at_change = cond;
      }
    } else {
      cond_at_change = 0;
    }
    if (!keep) {
      if (ndep >= 0) {
        ++changes;
        changed_last = true;
        prev_dep = dep;
        prev_ndep = ndep;
      }
      // Column pivoting on the independent rows picks the best-conditioned
      // dependent velocities (Businger–Golub; Wehage & Haug 1982).
      if (rank > 0) cpqr.compute(Ar);
      std::fill(dep.begin(), dep.end(), -1);
      for (int t = 0; t < rank; ++t) dep[t] = cpqr.colsPermutation().indices()[t];
      ndep = rank;
      gatherDependent(rank);
      cond = dependentCondition();
    }
    // Independent velocities in increasing order.
    int ni = 0;
    for (int j = 0; j < n; ++j) {
      bool is_dep = false;
      for (int t = 0; t < rank; ++t) is_dep = is_dep || dep[t] == j;
      if (!is_dep) indep[ni++] = j;
    }
    const int k = n - rank;
    N.setZero();
    if (rank > 0) {
      lu.compute(Ad);
      Ai.setZero();
      for (int j = 0; j < k; ++j) Ai.col(j).head(rank) = Ar.col(indep[j]).head(rank);
      X.leftCols(k) = lu.solve(Ai.leftCols(k));
    }
    for (int j = 0; j < k; ++j) {
      N(indep[j], j) = 1.0;
      for (int t = 0; t < rank; ++t) N(dep[t], j) = -X(t, j);
    }
  }

  /// x_p = [A_d⁻¹ D c; 0] on the partition.
  void partitionParticular(const VecX& c) {
    const int rank = basis.rank();
    xp.setZero();
    if (rank == 0) return;
    cr.setZero();
    for (int k = 0; k < rank; ++k) cr[k] = basis.scale(basis.pivot(k)) * c[basis.pivot(k)];
    sol = lu.solve(cr);
    for (int t = 0; t < rank; ++t) xp[dep[t]] = sol[t];
  }

  /// The common core of solve() and projectVelocity():
  ///   x = N e + x_p,  A x_p = c,  Nᵀ M N e = Nᵀ (f − M x_p),  r = M x − f.
  /// Returns "" on success, else the reason (allocates only then).
  std::string reduce(const AppellOptions& ao, const SolverOptions& so,
                     const ConstraintList& constraints, const ConstraintData& cdata,
                     const MatX& M, const VecX& c, const VecX& f, VecX& x) {
    B = cdata.A.transpose();
    basis.factor(B, so);
    if (!basis.solveRows(c, yE)) return basis.describeInconsistency(constraints, cdata);
    const int rank = basis.rank(), k = n - rank;
    if (ao.null_space == NullSpace::Orthonormal) {
      xp = yE;                       // minimum-norm particular solution Q₁z
      N.leftCols(k) = basis.Q2();    // orthonormal null-space basis
    } else {
      updatePartition(cdata.A, ao.partition_cond_max);
      partitionParticular(c);
    }
    x = xp;
    if (k > 0) {
      MN.leftCols(k).noalias() = M * N.leftCols(k);
      Mpad.setIdentity();
      Mpad.topLeftCorner(k, k).noalias() = N.leftCols(k).transpose() * MN.leftCols(k);
      tmp.noalias() = M * xp;
      tmp = f - tmp;
      rhs.setZero();
      rhs.head(k).noalias() = N.leftCols(k).transpose() * tmp;
      lltr.compute(Mpad);
      if (lltr.info() != Eigen::Success)
        return "reduced mass matrix NᵀMN is not positive definite";
      lltr.solveInPlace(rhs);
      x.noalias() += N.leftCols(k) * rhs.head(k);
    }
    // Reaction residual r = M x − f, which must lie in range(Aᵀ).
    r.noalias() = M * x;
    const double scale = r.norm() + f.norm() + std::numeric_limits<double>::min();
    r -= f;
    basis.minNorm(r, lambda);
    range_residual = basis.rangeResidual() / scale;
    if (!(range_residual <= ao.range_tol)) {
      std::ostringstream os;
      os << "reaction M v̇ + h − τ is not in range(Aᵀ): relative residual " << range_residual
         << " exceeds " << ao.range_tol;
      return os.str();
    }
    return {};
  }
};

AppellSolver::AppellSolver(const Model& model, const ConstraintList& constraints,
                           const SolverOptions& options, const AppellOptions& appell)
    : options_(options), appell_(appell),
      impl_(std::make_unique<Impl>(model.nv, detail::totalRows(constraints))) {
  if (!(appell.partition_cond_max > 1))
    throw std::invalid_argument("AppellOptions::partition_cond_max must exceed 1");
}

AppellSolver::~AppellSolver() = default;

void AppellSolver::solve(const Model& model, Data& data, const ConstraintList& constraints,
                         ConstraintData& cdata, const VecX& q, const VecX& v, const VecX& tau,
                         ConstrainedResult& out,
                         SolveOutputs outputs) {
  (void)outputs;  // a dense reference always writes λ and Aᵀλ (they cost little next to its O(n³) factorisation)
  Impl& w = *impl_;
  detail::checkSizes("AppellSolver::solve", model, w.m, cdata, q, v, &tau);
  detail::sizeResult(model.nv, w.m, out);
  last_error_.clear();
  if (cdata.singular) {
    out.ok = false;
    out.error = "singular contact geometry: " + cdata.singular_reason;
    last_error_ = out.error;
    return;
  }
  detail::assembleDense(model, data, constraints, cdata, q, v);
  const MatX& M = crba(model, data, q);
  const VecX& h = nonLinearEffects(model, data, q, v);
  w.fbuf = tau - h;
  w.cvec = -cdata.abias;
  std::string err = w.reduce(appell_, options_, constraints, cdata, M, w.cvec, w.fbuf, out.vdot);
  if (!err.empty()) {
    out.ok = false;
    out.error = std::move(err);
    last_error_ = out.error;
    return;
  }
  out.rank = w.basis.rank();
  out.redundant = cdata.m_active - out.rank;  // open contacts' zero rows are not redundancy
  out.lambda = w.lambda;
  out.reaction.noalias() = cdata.A.transpose() * out.lambda;
}

bool AppellSolver::projectVelocity(const Model& model, Data& data,
                                   const ConstraintList& constraints, ConstraintData& cdata,
                                   const VecX& q, VecX& v, VecX& impulse) {
  Impl& w = *impl_;
  detail::checkSizes("AppellSolver::projectVelocity", model, w.m, cdata, q, v, nullptr);
  impulse.resize(w.m);
  impulse.setZero();
  last_error_.clear();
  if (w.m == 0) return true;
  if (cdata.singular) {
    last_error_ = "singular contact geometry: " + cdata.singular_reason;
    return false;
  }
  detail::assembleDense(model, data, constraints, cdata, q, v);
  const MatX& M = crba(model, data, q);
  // min ½‖v⁺ − v‖²_M subject to A v⁺ = −b: the Maggi equations with f = M v.
  w.fbuf.noalias() = M * v;
  w.cvec = -cdata.b;
  std::string err = w.reduce(appell_, options_, constraints, cdata, M, w.cvec, w.fbuf, w.xbuf);
  if (!err.empty()) {
    last_error_ = std::move(err);
    return false;
  }
  v = w.xbuf;
  impulse = -w.lambda;  // M(v⁺ − v) = Aᵀλ = −Aᵀμ
  return true;
}

double AppellSolver::lastRangeResidual() const { return impl_->range_residual; }
int AppellSolver::partitionChanges() const { return impl_->changes; }
bool AppellSolver::partitionChangedLastSolve() const { return impl_->changed_last; }
double AppellSolver::partitionCondition() const { return impl_->cond; }

std::vector<int> AppellSolver::dependentVelocities() const {
  if (impl_->ndep < 0) return {};
  return std::vector<int>(impl_->dep.begin(), impl_->dep.begin() + impl_->ndep);
}

std::string AppellSolver::partitionMessage() const {
  const Impl& w = *impl_;
  if (w.changes == 0) return {};
  auto list = [](const std::vector<int>& d, int k) {
    std::string s = "{";
    for (int t = 0; t < k; ++t) s += (t ? ", " : "") + std::to_string(d[t]);
    return s + "}";
  };
  std::ostringstream os;
  os << "coordinate partition re-chosen " << w.changes << " time(s); last: dependent velocities "
     << list(w.prev_dep, w.prev_ndep) << " -> " << list(w.dep, w.ndep);
  if (w.cond_at_change > 0)
    os << " because 1/sigma_min of the dependent block reached " << w.cond_at_change
       << " (limit " << appell_.partition_cond_max << ")";
  else
    os << " because the rank of the constraints changed";
  os << "; condition now " << w.cond;
  return os.str();
}

}  // namespace appell
