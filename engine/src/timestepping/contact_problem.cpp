// Non-smooth block Gauss–Seidel on the Moreau–Jean contact problem
// (contact_problem.hpp states the problem and the residual).
#include "timestepping/contact_problem.hpp"

#include "simulator/friction_problem.hpp"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>

namespace appell::timestepping {

namespace {

using Vec6d = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1>;
using Mat6d = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>;

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
  u_free = target = P = u = VecX::Zero(rows);
  blocks.reserve(contacts);
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

// Block b exactly, the others' impulses fixed: c = its velocity without
// its own impulse.
void ContactProblem::solveBlock(const ProblemBlock& b) {
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
    Mat6d Wb = W.block(o, o, d, d);
    Eigen::LDLT<Mat6d> ldlt(Wb);
    Vec6d x = ldlt.solve(rhs);
    if (x.allFinite() && x[0] >= 0) P.segment(o, d) = x;
    else P.segment(o, d).setZero();
    return;
  }
  if (b.nf == 0) {
    P[o] = std::max(0.0, (target[o] - c[0]) / wnn);
    return;
  }
  // Normal row and friction disk, alternated to their fixed point.
  const int nf = b.nf;
  Mat3 H = Mat3::Zero();
  H.topLeftCorner(nf, nf) = W.block(o + 1, o + 1, nf, nf);
  H = (0.5 * (H + H.transpose())).eval();
  double pn = P[o];
  Vec3 pf = Vec3::Zero();
  pf.head(nf) = P.segment(o + 1, nf);
  for (int it = 0; it < 100; ++it) {
    const double pn_old = pn;
    const Vec3 pf_old = pf;
    pn = std::max(0.0, (target[o] - c[0] - W.row(o).segment(o + 1, nf).dot(pf.head(nf))) / wnn);
    Vec3 cf = Vec3::Zero();
    cf.head(nf) = c.segment(1, nf) + W.col(o).segment(o + 1, nf) * pn;
    const double radius = b.mu * pn;
    if (nf == 1) {
      pf[0] = H(0, 0) > 0 ? std::clamp(-cf[0] / H(0, 0), -radius, radius)
                          : (cf[0] > 0 ? -radius : radius);
    } else {
      pf = detail::diskMinimizer(H, cf, nf, radius);
    }
    const double change = std::abs(pn - pn_old) + (pf - pf_old).norm();
    if (change <= 1e-15 * (std::abs(pn) + pf.norm()) || change == 0) break;
  }
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

void ContactProblem::solve(double tol, int max_sweeps) {
  sweeps = 0;
  residual = 0;
  converged = true;
  if (n == 0) return;
  const double scale = std::max(1.0, u_free.head(n).lpNorm<Eigen::Infinity>());
  for (sweeps = 1; sweeps <= max_sweeps; ++sweeps) {
    for (const ProblemBlock& b : blocks) solveBlock(b);
    u.head(n) = u_free.head(n);
    u.head(n).noalias() += W.topLeftCorner(n, n) * P.head(n);
    residual = 0;
    for (const ProblemBlock& b : blocks) residual = std::max(residual, blockResidual(b));
    if (residual <= tol * scale) return;
  }
  sweeps = max_sweeps;
  converged = false;
}

}  // namespace appell::timestepping
