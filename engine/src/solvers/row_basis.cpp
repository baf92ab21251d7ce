#include "solvers/row_basis.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace appell::detail {

RowBasis::RowBasis(int n, int m)
    : n_(n), m_(m), k_(std::min(n, m)), D_(VecX::Zero(m)), Be_(MatX::Zero(n, m)),
      qr_(n, m), Q_(MatX::Identity(n, n)), work_n_(VecX::Zero(n)), work_m_(VecX::Zero(m)),
      pd_(VecX::Zero(m)), z_(VecX::Zero(n)), E_(MatX::Zero(m, m)), eqr_(m, m),
      w_(VecX::Zero(m)) {}

void RowBasis::factor(const MatX& B, const SolverOptions& options, bool form_q) {
  opt_ = options;
  form_q_ = form_q;
  Be_ = B;
  double max_norm = 0;
  for (int j = 0; j < m_; ++j) max_norm = std::max(max_norm, Be_.col(j).norm());
  // Equilibrate: unit columns. A row whose norm is negligible against the
  // largest is numerically zero: it constrains nothing (redundant if its
  // right-hand side vanishes, inconsistent otherwise — solveRows decides).
  for (int j = 0; j < m_; ++j) {
    const double nrm = Be_.col(j).norm();
    if (nrm == 0 || nrm <= options.rank_rel_tol * max_norm) {
      D_[j] = 0;
      Be_.col(j).setZero();
    } else {
      D_[j] = 1.0 / nrm;
      Be_.col(j) *= D_[j];
    }
  }
  rank_ = 0;
  if (m_ == 0 || n_ == 0) {
    Q_.setIdentity();
    return;
  }
  qr_.compute(Be_);
  const auto& R = qr_.matrixQR();
  const double r00 = std::abs(R(0, 0));
  const double threshold = options.rank_abs_tol + options.rank_rel_tol * r00;
  while (rank_ < k_ && std::abs(R(rank_, rank_)) > threshold) ++rank_;
  if (form_q_) qr_.householderQ().evalTo(Q_, work_n_);
}

bool RowBasis::solveRows(const VecX& d, VecX& y) {
  bad_pivot_ = -1;
  zero_row_ = -1;
  bad_residual_ = 0;
  y.setZero();
  if (m_ == 0) return true;
  const double dmax = d.lpNorm<Eigen::Infinity>();
  for (int j = 0; j < m_; ++j) pd_[j] = D_[pivot(j)] * d[pivot(j)];
  const double tol = opt_.consistency_tol * (1.0 + pd_.lpNorm<Eigen::Infinity>());
  // Zero rows: 0 = d_i must hold on its own.
  for (int i = 0; i < m_; ++i) {
    if (D_[i] != 0) continue;
    const double res = std::abs(d[i]);
    if (res > opt_.consistency_tol * (1.0 + dmax) && res > bad_residual_) {
      bad_residual_ = res;
      zero_row_ = i;
    }
  }
  if (rank_ > 0) {
    // Independent rows: R₁₁ᵀ z = (Pᵀ D d)₁…ᵣ.
    auto z = z_.head(rank_);
    z = pd_.head(rank_);
    qr_.matrixQR().topLeftCorner(rank_, rank_).triangularView<Eigen::Upper>().transpose().solveInPlace(z);
    if (form_q_) {
      y.noalias() = Q1() * z;
    } else {
      y.head(rank_) = z;
      applyQ(qr_, k_, y);
    }
  }
  // Dropped rows: R₁₂ᵀ z must reproduce their right-hand sides.
  for (int j = rank_; j < m_; ++j) {
    if (D_[pivot(j)] == 0) continue;
    double lhs = 0;
    for (int k = 0; k < rank_; ++k) lhs += qr_.matrixQR()(k, j) * z_[k];
    const double res = std::abs(lhs - pd_[j]);
    if (res > tol && res > bad_residual_) {
      bad_residual_ = res;
      bad_pivot_ = j;
      zero_row_ = -1;
    }
  }
  return bad_pivot_ < 0 && zero_row_ < 0;
}

template <class QR>
void RowBasis::applyQ(const QR& qr, int reflectors, VecX& x) {
  const auto& H = qr.matrixQR();
  const int n = static_cast<int>(H.rows());
  for (int j = reflectors - 1; j >= 0; --j) {
    // H_j = I − τ v vᵀ with v = [1; essential part stored below the diagonal].
    const double tau = qr.hCoeffs()[j];
    if (tau == 0) continue;
    auto ess = H.col(j).tail(n - j - 1);
    auto tail = x.tail(n - j - 1);
    const double dot = x[j] + ess.dot(tail);
    x[j] -= tau * dot;
    tail -= (tau * dot) * ess;
  }
}

void RowBasis::minNormOfSolution(VecX& lambda) {
  lambda.setZero();
  range_residual_ = 0;
  if (m_ == 0 || rank_ == 0) return;
  w_.head(rank_) = z_.head(rank_);
  minNormFromRowSpace(lambda);
}

void RowBasis::minNorm(const VecX& y, VecX& lambda) {
  lambda.setZero();
  range_residual_ = 0;
  if (m_ == 0) return;
  // Part of y outside range(B): ‖Q₂ᵀ y‖.
  if (rank_ < n_) {
    auto outside = work_n_.head(n_ - rank_);
    outside.noalias() = Q2().transpose() * y;
    range_residual_ = outside.norm();
  }
  if (rank_ == 0) return;
  w_.head(rank_).noalias() = Q1().transpose() * y;
  minNormFromRowSpace(lambda);
}

void RowBasis::minNormFromRowSpace(VecX& lambda) {
  // Kᵀ = D⁻¹ P R₁ᵀ: row i = pivot(j) of Kᵀ is column j of R₁ times ‖B_i‖.
  // Rows the rank decision called zero (D_i = 0) take no multiplier.
  E_.setZero();
  const auto& R = qr_.matrixQR();
  for (int j = 0; j < m_; ++j) {
    const int i = pivot(j);
    if (D_[i] == 0) continue;
    const int top = std::min(rank_, j + 1);
    for (int k = 0; k < top; ++k) E_(i, k) = R(k, j) / D_[i];
  }
  eqr_.compute(E_);
  auto s = w_.head(rank_);
  eqr_.matrixQR().topLeftCorner(rank_, rank_).triangularView<Eigen::Upper>().transpose().solveInPlace(s);
  lambda.head(rank_) = s;
  applyQ(eqr_, m_, lambda);
}

std::string rowName(const ConstraintList& constraints, const ConstraintData& cdata, int i) {
  const int k = cdata.row_constraint[i];
  const Constraint& c = *constraints[k];
  return "'" + c.name() + "' row '" + c.rowLabel(i - cdata.offset[k]) + "' (#" +
         std::to_string(i) + ")";
}

std::string RowBasis::describeInconsistency(const ConstraintList& constraints,
                                            const ConstraintData& cdata,
                                            const std::vector<int>* row_map) const {
  auto name = [&](int i) {
    return rowName(constraints, cdata, row_map ? (*row_map)[i] : i);
  };
  std::ostringstream os;
  os.precision(3);
  if (zero_row_ >= 0) {
    os << "inconsistent constraints: " << name(zero_row_)
       << " cannot be influenced by any motion but demands a nonzero value (residual "
       << bad_residual_ << ")";
    return os.str();
  }
  if (bad_pivot_ < 0) return "constraints are consistent";
  // The dropped row is a combination of independent rows: c = R₁₁⁻¹ R₁ⱼ.
  VecX c = qr_.matrixQR().col(bad_pivot_).head(rank_);
  qr_.matrixQR().topLeftCorner(rank_, rank_).triangularView<Eigen::Upper>().solveInPlace(c);
  const double cmax = rank_ > 0 ? c.lpNorm<Eigen::Infinity>() : 0.0;
  os << "inconsistent constraints: " << name(pivot(bad_pivot_))
     << " is a combination of ";
  bool first = true;
  for (int k = 0; k < rank_; ++k) {
    if (std::abs(c[k]) <= 1e-9 * cmax) continue;
    os << (first ? "" : ", ") << name(pivot(k));
    first = false;
  }
  if (first) os << "no other row";
  os << " but demands a different value (residual " << bad_residual_
     << " in equilibrated units)";
  return os.str();
}

}  // namespace appell::detail
