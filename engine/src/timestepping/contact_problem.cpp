// Non-smooth block Gauss–Seidel on the Moreau–Jean contact problem, with
// its active-set finish (contact_problem.hpp states the problem, the
// residual and the finish).
#include "timestepping/contact_problem.hpp"

#include <algorithm>
#include <cmath>

namespace appell::timestepping {

namespace {

using Vec6d = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1>;

/// Π onto {|z_f| ≤ μ z_n} (Euclidean), z = (z_n, z_f) with nf friction parts.
Vec3 projectOntoCone(double zn, const Vec3& zf, double mu, Vec3& out_f) {
  const double r = zf.norm();
  if (r <= mu * zn) {
    out_f = zf;
    return Vec3(zn, 0, 0);
  }
  if (mu * r <= -zn) {
    out_f.setZero();
    return Vec3::Zero();
  }
  const double a = (zn + mu * r) / (1 + mu * mu);
  out_f = (mu * a / r) * zf;
  return Vec3(a, 0, 0);
}

}  // namespace

void ContactProblem::reserve(int rows, int contacts) {
  W = MatX::Zero(rows, rows);
  u_free = target = P = u = start = VecX::Zero(rows);
  blocks.reserve(contacts);
  disk_.resize(contacts);
  ldlt_.resize(contacts);
  stick_solve_.resize(contacts);
  unknown_row_.reserve(rows);
  unknown_block_.reserve(rows);
  mode_.reserve(contacts);
  failed_modes_.reserve(contacts);
  skip_modes.reserve(contacts);
  tried_modes_.reserve(contacts);
  dir_.resize(contacts);
  A_ = B_ = MatX::Zero(rows, rows);
  x_ = r_ = y_ = P_save_ = u_save_ = delta_ = VecX::Zero(rows);
  piv_.resize(rows);
}

int ContactProblem::add(int nf, int ne, double mu) {
  ProblemBlock b;
  b.first = n;
  b.nf = nf;
  b.ne = ne;
  b.mu = mu;
  blocks.push_back(b);
  n += b.rows();
  return b.first;
}

// Each block's own matrix, fixed while the others' impulses change: the
// friction disk's eigen-decomposition and the equality rows' LDLᵀ, once.
void ContactProblem::factorBlocks() {
  for (int j = 0; j < static_cast<int>(blocks.size()); ++j) {
    const ProblemBlock& b = blocks[j];
    const int o = b.first, d = b.rows();
    // The whole block's LDLᵀ: the equality rows' solve, and a friction
    // block's sticking solve (used when W_bb is safely positive definite).
    ldlt_[j].compute(W.block(o, o, d, d));
    const auto D = ldlt_[j].vectorD();
    stick_solve_[j] = b.nf > 0 && ldlt_[j].info() == Eigen::Success &&
                      D.minCoeff() > 1e-10 * std::max(D.maxCoeff(), 1e-300);
    if (b.nf > 0) {
      Mat3 H = Mat3::Zero();
      H.topLeftCorner(b.nf, b.nf) = W.block(o + 1, o + 1, b.nf, b.nf);
      H = (0.5 * (H + H.transpose())).eval();
      disk_[j] = detail::factorDisk(H, b.nf);
    }
  }
}

// Block j exactly, the others' impulses fixed: c = its velocity without
// its own impulse.
void ContactProblem::solveBlock(int j) {
  const ProblemBlock& b = blocks[j];
  const int o = b.first, d = b.rows();
  Vec6d c = u_free.segment(o, d);
  c.noalias() += W.middleRows(o, d).leftCols(n) * P.head(n);
  c.noalias() -= W.block(o, o, d, d) * P.segment(o, d);
  const double wnn = W(o, o);
  if (!(wnn > 0)) {  // a row the bilateral constraints already hold
    P.segment(o, d).setZero();
    return;
  }
  if (b.ne > 0) {  // equalities while it pushes
    Vec6d rhs = target.segment(o, d) - c;
    Vec6d x = ldlt_[j].solve(rhs);
    if (x.allFinite() && x[0] >= 0) P.segment(o, d) = x;
    else P.segment(o, d).setZero();
    return;
  }
  if (b.nf == 0) {
    P[o] = std::max(0.0, (target[o] - c[0]) / wnn);
    return;
  }
  const int nf = b.nf;
  if (stick_solve_[j]) {
    // Sticking: u_b = target_b exactly, when that impulse lies in the cone.
    const Vec6d x = ldlt_[j].solve(target.segment(o, d) - c);
    Vec3 xf = Vec3::Zero();  // (a fixed-size copy: GCC misreads a 6-capacity segment's norm)
    xf.head(nf) = x.segment(1, nf);
    if (x[0] >= 0 && xf.norm() <= b.mu * x[0]) {
      P.segment(o, d) = x;
      return;
    }
  }
  // Sliding (or W_bb near singular): the normal row, then the friction
  // disk at the new normal impulse — once per sweep. (Alternating the two
  // to their fixed point within the block, up to 100 times as before
  // 2026-11-27, cost ~90 % of a problem's time and saved no sweeps on the
  // box's, the CAD car's or the skid-steer's problems: the sweeps couple
  // the normal and the friction rows anyway.)
  Vec3 pf = Vec3::Zero();
  pf.head(nf) = P.segment(o + 1, nf);
  const double pn = std::max(0.0, (target[o] - c[0] - W.row(o).segment(o + 1, nf).dot(pf.head(nf))) / wnn);
  Vec3 cf = Vec3::Zero();
  cf.head(nf) = c.segment(1, nf) + W.col(o).segment(o + 1, nf) * pn;
  const double radius = b.mu * pn;
  const double hff = W(o + 1, o + 1);
  if (nf == 1) pf[0] = hff > 0 ? std::clamp(-cf[0] / hff, -radius, radius) : (cf[0] > 0 ? -radius : radius);
  else pf = detail::diskMinimizer(disk_[j], cf, nf, radius);
  P[o] = pn;
  P.segment(o + 1, nf) = pf.head(nf);
}

double ContactProblem::blockResidual(const ProblemBlock& b) const {
  const int o = b.first, d = b.rows();
  const double tr = W.diagonal().segment(o, d).sum();
  if (!(W(o, o) > 0)) return 0;
  const double rho = d / tr;
  const double pn = P[o], un = u[o] - target[o];
  if (b.ne > 0) {
    const double rn = std::abs(pn - std::max(0.0, pn - rho * un)) / rho;
    const double re = pn > 0 ? (u.segment(o + 1, b.ne) - target.segment(o + 1, b.ne)).lpNorm<Eigen::Infinity>()
                             : P.segment(o + 1, b.ne).lpNorm<Eigen::Infinity>() / rho;
    return std::max(rn, re);
  }
  if (b.nf == 0) return std::abs(pn - std::max(0.0, pn - rho * un)) / rho;
  Vec3 uf = Vec3::Zero(), pf = Vec3::Zero(), proj_f;
  uf.head(b.nf) = u.segment(o + 1, b.nf);
  pf.head(b.nf) = P.segment(o + 1, b.nf);
  // De Saxcé's modified velocity: u_n + μ|u_f| on the normal.
  const double zn = pn - rho * (un + b.mu * uf.norm());
  const Vec3 zf = pf - rho * uf;
  const Vec3 pn_proj = projectOntoCone(zn, zf, b.mu, proj_f);
  const double dn = pn - pn_proj[0];
  return std::sqrt(dn * dn + (pf - proj_f).squaredNorm()) / rho;
}

void ContactProblem::sweep() {
  for (int j = 0; j < static_cast<int>(blocks.size()); ++j) solveBlock(j);
  u.head(n) = u_free.head(n);
  u.head(n).noalias() += W.topLeftCorner(n, n) * P.head(n);
}

double ContactProblem::maxResidual() const {
  double r = 0;
  for (const ProblemBlock& b : blocks) r = std::max(r, blockResidual(b));
  return r;
}

// Gauss–Seidel sweeps, with the active-set finish tried from the second
// sweep on (each try costs about one sweep: an m × m Cholesky, m ≤ n) — at
// every sweep for the first 20 sweeps, then at every 10th.
void ContactProblem::solve(double tol, int max_sweeps) {
  sweeps = 0;
  residual = 0;
  converged = true;
  polished = false;
  min_norm_failed_ = false;
  failed_finishes_ = 0;
  failed_modes_.assign(skip_modes.begin(), skip_modes.end());
  if (n == 0) return;
  start.head(n) = P.head(n);
  factorBlocks();
  const double scale = std::max(1.0, u_free.head(n).lpNorm<Eigen::Infinity>());
  for (sweeps = 1; sweeps <= max_sweeps; ++sweeps) {
    sweep();
    residual = maxResidual();
    if (residual <= tol * scale) return;
    if ((sweeps <= 3 || (sweeps & (sweeps - 1)) == 0 || sweeps % 100 == 0) && polish(tol * scale)) {
      polished = true;
      return;
    }
  }
  sweeps = max_sweeps;
  converged = false;
}

// The modes Gauss–Seidel has reached (mode_: 0 open or held by the
// bilateral rows, 1 pushing with every row an equation — sticking, equality
// or normal-only —, 2 sliding along dir_ = −u_f/|u_f|). false when no block
// pushes (nothing to finish).
bool ContactProblem::readModes() {
  mode_.assign(blocks.size(), 0);
  bool any = false;
  for (int j = 0; j < static_cast<int>(blocks.size()); ++j) {
    const ProblemBlock& b = blocks[j];
    const int o = b.first;
    if (!(W(o, o) > 0) || !(P[o] > 0)) continue;
    any = true;
    mode_[j] = 1;
    const double pf = P.segment(o + 1, b.nf).norm();
    const double slip = u.segment(o + 1, b.nf).norm();
    if (b.nf > 0 && pf >= (1 - 1e-9) * b.mu * P[o] && slip > 0) {
      mode_[j] = 2;
      dir_[j].setZero();
      dir_[j].head(b.nf) = -u.segment(o + 1, b.nf) / slip;
    }
  }
  return any;
}

// The unknowns and equations of the modes: a pushing block's rows, or a
// sliding block's normal row (its friction dragged along dir_).
void ContactProblem::activeSet() {
  unknown_row_.clear();
  unknown_block_.clear();
  for (int j = 0; j < static_cast<int>(blocks.size()); ++j) {
    const ProblemBlock& b = blocks[j];
    const int rows = mode_[j] == 1 ? b.rows() : mode_[j] == 2 ? 1 : 0;
    for (int i = 0; i < rows; ++i) {
      unknown_row_.push_back(b.first + i);
      unknown_block_.push_back(j);
    }
  }
}

// P from the unknowns x: sliding blocks' friction μ P_n along dir_, open
// blocks zero.
void ContactProblem::expand(const VecX& x) {
  P.head(n).setZero();
  for (int k = 0; k < static_cast<int>(unknown_row_.size()); ++k) {
    const int row = unknown_row_[k], j = unknown_block_[k];
    P[row] = x[k];
    if (mode_[j] == 2) {
      const ProblemBlock& b = blocks[j];
      P.segment(row + 1, b.nf) = b.mu * x[k] * dir_[j].head(b.nf);
    }
  }
  u.head(n) = u_free.head(n);
  u.head(n).noalias() += W.topLeftCorner(n, n) * P.head(n);
}

// One correction of x towards A x = target on the equation rows, r =
// target − u, by iterated Tikhonov regularization (the proximal-point
// method on A δ = r): δ ← δ + (A + εI)⁻¹ (r − A δ), ε = 1e-10 · trace(A)/m.
// Each iteration divides the error along an eigenvector of eigenvalue λ by
// 1 + λ/ε, so directions well above ε converge in a few iterations and the
// null directions of redundant contacts (λ = 0) take no part: δ tends to
// the correction nearest the Gauss–Seidel iterate, never squaring A's
// condition number (the normal equations A Aᵀ did: the CAD car's sticking
// W spans 3.5 … 1.7e-10, its square lost the small end to round-off and
// the finish stalled at 1e-10 … 3e-9 m/s). (A + εI) is factored once by LU
// with partial pivoting, in place. false when the factorization fails or
// the iteration does not reduce the equations' residual.
bool ContactProblem::solveActiveSet(double tol) {
  const int m = static_cast<int>(unknown_row_.size());
  // A: the equation rows' response to each unknown (a sliding normal
  // drags its friction along).
  for (int k = 0; k < m; ++k) {
    const int row = unknown_row_[k], j = unknown_block_[k];
    for (int i = 0; i < m; ++i) {
      const int e = unknown_row_[i];  // (each unknown's own row is its equation)
      double a = W(e, row);
      if (mode_[j] == 2) {
        const ProblemBlock& b = blocks[j];
        for (int f = 0; f < b.nf; ++f) a += b.mu * dir_[j][f] * W(e, row + 1 + f);
      }
      A_(i, k) = a;
    }
    r_[k] = target[row] - u[row];
  }
  bool sliding = false;
  for (int k = 0; k < m; ++k) sliding = sliding || mode_[unknown_block_[k]] == 2;
  if (sliding) return solveNormalEquations();
  auto Am = A_.topLeftCorner(m, m);
  auto Bm = B_.topLeftCorner(m, m);
  Bm = Am;
  const double eps = 1e-10 * std::max(Am.diagonal().cwiseAbs().sum() / m, 1e-300);
  Bm.diagonal().array() += eps;
  // LU with partial pivoting of B = A + εI, in place (pivots in piv_).
  for (int c = 0; c < m; ++c) {
    int p = c;
    for (int i = c + 1; i < m; ++i)
      if (std::abs(Bm(i, c)) > std::abs(Bm(p, c))) p = i;
    if (!(std::abs(Bm(p, c)) > 0)) return false;
    piv_[c] = p;
    if (p != c) Bm.row(p).swap(Bm.row(c));
    for (int i = c + 1; i < m; ++i) {
      const double l = Bm(i, c) / Bm(c, c);
      Bm(i, c) = l;
      for (int k = c + 1; k < m; ++k) Bm(i, k) -= l * Bm(c, k);
    }
  }
  auto delta = delta_.head(m);
  delta.setZero();
  double last = r_.head(m).lpNorm<Eigen::Infinity>();
  // (to a hundredth of the problem's tolerance, or round-off)
  const double goal = std::max(1e-2 * tol, 1e-16 * Am.cwiseAbs().maxCoeff() * x_.head(m).lpNorm<Eigen::Infinity>());
  for (int it = 0; it < 60 && last > goal; ++it) {
    // y = B⁻¹ (r − A δ): permute, forward and back substitution.
    y_.head(m) = r_.head(m);
    y_.head(m).noalias() -= Am * delta;
    for (int c = 0; c < m; ++c)
      if (piv_[c] != c) std::swap(y_[c], y_[piv_[c]]);
    for (int i = 0; i < m; ++i)
      for (int k = 0; k < i; ++k) y_[i] -= Bm(i, k) * y_[k];
    for (int i = m - 1; i >= 0; --i) {
      for (int k = i + 1; k < m; ++k) y_[i] -= Bm(i, k) * y_[k];
      y_[i] /= Bm(i, i);
    }
    delta += y_.head(m);
    y_.head(m) = r_.head(m);
    y_.head(m).noalias() -= Am * delta;
    const double now = y_.head(m).lpNorm<Eigen::Infinity>();
    if (!(now < last)) break;  // (round-off reached, or diverging: keep the best δ)
    last = now;
  }
  x_.head(m) += delta;
  return x_.head(m).allFinite();
}

// The correction with sliding modes (A not symmetric): the minimum-norm
// one, A Aᵀ y = r (Cholesky with a relative 1e-14 shift),
// x += Aᵀ y. false when the factorization fails.
bool ContactProblem::solveNormalEquations() {
  const int m = static_cast<int>(unknown_row_.size());
  auto Am = A_.topLeftCorner(m, m);
  auto Bm = B_.topLeftCorner(m, m);
  Bm.noalias() = Am * Am.transpose();
  const double shift = 1e-14 * std::max(Bm.trace() / m, 1e-300);
  // In-place Cholesky of B + shift·I (lower), then y by two triangular solves.
  for (int c = 0; c < m; ++c) {
    double d = Bm(c, c) + shift;
    for (int k = 0; k < c; ++k) d -= Bm(c, k) * Bm(c, k);
    if (!(d > 0)) return false;
    const double l = std::sqrt(d);
    Bm(c, c) = l;
    for (int i = c + 1; i < m; ++i) {
      double s = Bm(i, c);
      for (int k = 0; k < c; ++k) s -= Bm(i, k) * Bm(c, k);
      Bm(i, c) = s / l;
    }
  }
  for (int i = 0; i < m; ++i) {
    double s = r_[i];
    for (int k = 0; k < i; ++k) s -= Bm(i, k) * y_[k];
    y_[i] = s / Bm(i, i);
  }
  for (int i = m - 1; i >= 0; --i) {
    double s = y_[i];
    for (int k = i + 1; k < m; ++k) s -= Bm(k, i) * y_[k];
    y_[i] = s / Bm(i, i);
  }
  x_.head(m).noalias() += Am.transpose() * y_.head(m);
  return x_.head(m).allFinite();
}

// The active-set finish (contact_problem.hpp): from the modes Gauss–Seidel
// reached, solve their equalities; a block that then pulls opens, a
// sticking block outside its cone slides along its impulse, and the
// equalities are solved again (at most once per block). Accepted when every
// block's natural-map residual is within `tol` (which also checks the cone
// and the sign of every normal impulse); else P and u are as Gauss–Seidel
// left them.
//
// The equalities of redundant contacts — four tyres on a rigid chassis, a
// box on four corners — leave some impulses undetermined (the chassis'
// warp). The finish first solves them from zero: the minimum-norm
// impulses, the event scheme's tie-break (docs/contacts.md §8), the same at
// every step whatever the last step left. Solved from the Gauss–Seidel
// iterate instead — warm-started from the last step — the undetermined part
// is carried from step to step and drifts: a skid-steer's loads went from
// 125/151/129/155 N (the events' split) to 217/60/42/241 N in 6 s and its
// turn from 1.005 to 0.85 rad/s. Where the minimum-norm solve does not meet
// the tolerance (ill-conditioned sticking: the CAD car's W spans 3.5 …
// 1.7e-10), the correction nearest the iterate is tried next, and for the
// rest of this step's sweeps alone (trying both at every finish doubled
// cad_car's cost for the same trajectory).
//
// A finish that failed is not tried again until Gauss–Seidel reaches other
// modes: from the same modes it fails again. The caller may carry a failed
// finish's modes into the next problems over the same contacts (skip_modes;
// MoreauJean::solveProblem). Measured on cad_car's first
// 3 s time-stepped (3 064 problems, 676 at the sweep limit): of 28 637
// tries 28 416 failed, 25 921 of them from the modes of the problem's last
// failed try, and one of those 25 921 succeeded; the retries were ~55 % of
// the run's time.
bool ContactProblem::polish(double tol) {
  if (!readModes()) return false;
  if (std::equal(mode_.begin(), mode_.end(), failed_modes_.begin(), failed_modes_.end())) return false;
  tried_modes_.assign(mode_.begin(), mode_.end());
  if (!min_norm_failed_) {
    if (polishFrom(tol, true)) return true;
    min_norm_failed_ = true;  // (not tried again in this problem: half the finish's cost)
  }
  if (polishFrom(tol, false)) return true;
  failed_modes_.swap(tried_modes_);
  ++failed_finishes_;
  return false;
}

bool ContactProblem::polishFrom(double tol, bool from_zero) {
  if (!readModes()) return false;
  P_save_.head(n) = P.head(n);
  u_save_.head(n) = u.head(n);
  opened_least_ = false;
  bool ok = false;
  for (int round = 0; round <= static_cast<int>(blocks.size()) && !ok; ++round) {
    activeSet();
    if (unknown_row_.empty()) break;
    if (!solveModes(tol, from_zero)) break;
    ok = maxResidual() <= tol;
    if (ok || !adjustModes(tol)) break;
  }
  if (ok) {
    residual = maxResidual();
  } else {
    P.head(n) = P_save_.head(n);
    u.head(n) = u_save_.head(n);
  }
  return ok;
}

// x from zero (from_zero) or Gauss–Seidel's impulses, then minimum-norm corrections (each
// sliding direction renewed from the new slip) until the residual is within
// tol or 12 solves are done (iterative refinement of the normal equations,
// whose shift and round-off limit one solve to ~1e-10 on the car's rows);
// P and u at the result. false when a solve fails.
bool ContactProblem::solveModes(double tol, bool from_zero) {
  const int m = static_cast<int>(unknown_row_.size());
  for (int k = 0; k < m; ++k) x_[k] = from_zero ? 0.0 : P_save_[unknown_row_[k]];
  for (int it = 0; it < 12; ++it) {
    expand(x_);
    if (it > 0) {
      for (int j = 0; j < static_cast<int>(blocks.size()); ++j) {
        if (mode_[j] != 2) continue;
        const ProblemBlock& b = blocks[j];
        const double slip = u.segment(b.first + 1, b.nf).norm();
        if (slip > 0) dir_[j].head(b.nf) = -u.segment(b.first + 1, b.nf) / slip;
      }
      expand(x_);
      if (maxResidual() <= tol) return true;
    }
    if (!solveActiveSet(tol)) return false;
  }
  expand(x_);
  return true;
}

// After a solve whose result is off: the block that pulls most opens; else
// the sticking block farthest outside its cone slides along its impulse.
// false when neither applies (the finish gives up).
bool ContactProblem::adjustModes(double tol) {
  int pulling = -1, outside = -1;
  double most_negative = 0, most_outside = 0;
  for (int j = 0; j < static_cast<int>(blocks.size()); ++j) {
    if (mode_[j] == 0) continue;
    const ProblemBlock& b = blocks[j];
    const double pn = P[b.first];
    if (pn < most_negative) {
      most_negative = pn;
      pulling = j;
    }
    const double excess = P.segment(b.first + 1, b.nf).norm() - b.mu * pn;
    if (mode_[j] == 1 && b.nf > 0 && b.ne == 0 && excess > most_outside) {
      most_outside = excess;
      outside = j;
    }
  }
  if (pulling >= 0) {
    mode_[pulling] = 0;
    return true;
  }
  if (outside >= 0) {
    const ProblemBlock& b = blocks[outside];
    const double pf = P.segment(b.first + 1, b.nf).norm();
    mode_[outside] = 2;
    dir_[outside].setZero();
    dir_[outside].head(b.nf) = P.segment(b.first + 1, b.nf) / pf;
    return true;
  }
  // Equalities that no impulse meets (a contact whose gap target the others
  // forbid, as a fourth tyre's on a rigid car): the least loaded one opens,
  // once per finish. (Not for a result near the tolerance: that is the
  // solve's accuracy, and Gauss–Seidel's modes stand.) Measured over every
  // example time-stepped for 3 s, and cad_car's 10 s under `auto`: no finish
  // succeeded after a second such opening — 11 262 of cad_car's 15 542 tries
  // went on to open a third and a fourth tyre, 41 % of the finish's rounds.
  if (maxResidual() < 1e4 * tol || opened_least_) return false;
  int least = -1;
  for (int j = 0; j < static_cast<int>(blocks.size()); ++j)
    if (mode_[j] != 0 && (least < 0 || P[blocks[j].first] < P[blocks[least].first])) least = j;
  if (least < 0) return false;
  mode_[least] = 0;
  opened_least_ = true;
  return true;
}

}  // namespace appell::timestepping
