// The friction problem's maps and its per-contact disk problem
// (friction_problem.hpp): the unit-force columns U, the affine responses W,
// N of the slip accelerations and the normal loads, a contact's slip, and
// the exact minimizer of a convex quadratic over a disk.
#include <appell/kinematics.hpp>
#include <appell/simulator.hpp>

#include "simulator/simulator_impl.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>

namespace appell {

using detail::UnilateralRow;

/// argmin ½ fᵀH f + cᵀf over |f| ≤ r in the first n (≤ 3) components, H
/// symmetric positive semidefinite: the unconstrained (minimum-norm)
/// minimizer when it lies inside, else f = −(H + νI)⁻¹c with ν > 0 on the
/// circle (secularRoot).
Vec3 detail::diskMinimizer(const Mat3& H, const Vec3& c, int n, double r) {
  if (!(r > 0)) return Vec3::Zero();
  return diskMinimizer(factorDisk(H, n), c, n, r);
}

detail::DiskFactor detail::factorDisk(const Mat3& H, int n) {
  Mat3 Hp = Mat3::Identity();
  Hp.topLeftCorner(n, n) = H.topLeftCorner(n, n);
  Eigen::SelfAdjointEigenSolver<Mat3> es(Hp);
  DiskFactor f;
  f.vectors = es.eigenvectors();
  f.values = es.eigenvalues().cwiseMax(0.0);
  return f;
}

bool detail::diskUnconstrained(const DiskFactor& H, const Vec3& c, int n, Vec3& cq, Vec3& fq) {
  Vec3 cp = Vec3::Zero();
  cp.head(n) = c.head(n);
  const Vec3& lam = H.values;
  cq = H.vectors.transpose() * cp;
  const double tiny = 1e-12 * std::max(lam.maxCoeff(), 1e-300);
  // The minimum-norm unconstrained minimizer exists when c has no part in
  // H's null space.
  bool bounded = true;
  fq.setZero();
  for (int i = 0; i < 3; ++i) {
    if (lam[i] > tiny) fq[i] = -cq[i] / lam[i];
    else if (std::abs(cq[i]) > 1e-14 * (cq.norm() + 1e-300)) bounded = false;
  }
  return bounded;
}

Vec3 detail::diskMinimizer(const DiskFactor& H, const Vec3& c, int n, double r) {
  if (!(r > 0)) return Vec3::Zero();
  Vec3 cq, fq;
  const bool bounded = diskUnconstrained(H, c, n, cq, fq);
  const Vec3& lam = H.values;
  if (bounded && fq.norm() <= r) {
    Vec3 f = H.vectors * fq;
    f.tail(3 - n).setZero();
    return f;
  }
  const double nu = secularRoot(lam, cq, r, 0.0);
  for (int i = 0; i < 3; ++i) fq[i] = lam[i] + nu > 0 ? -cq[i] / (lam[i] + nu) : 0.0;
  Vec3 f = H.vectors * fq;
  f.tail(3 - n).setZero();
  return f;
}

double detail::secularRoot(const Vec3& lam, const Vec3& cq, double r, double lower) {
  double x = lower;  // (a component alone reaches r at |cᵢ|/r − λᵢ: the root is above)
  for (int i = 0; i < 3; ++i)
    if (cq[i] != 0) x = std::max(x, std::abs(cq[i]) / r - lam[i]);
  for (int it = 0; it < 50; ++it) {
    double s2 = 0, ds = 0;  // |f|² and −d|f|²/dx / 2
    for (int i = 0; i < 3; ++i) {
      if (cq[i] == 0) continue;
      const double d = lam[i] + x;
      s2 += cq[i] * cq[i] / (d * d);
      ds += cq[i] * cq[i] / (d * d * d);
    }
    const double s = std::sqrt(s2);
    if (!(s > r * (1 + 1e-15)) || !(ds > 0)) break;  // at (or, by round-off, past) the root
    const double step = (s - r) / r * s2 / ds;       // −φ/φ' = (1/r − 1/s) s³ / ds
    if (!(step > 0)) break;
    x += step;
    if (step <= 1e-15 * std::abs(x)) break;
  }
  return x;
}

/// Column first + i of p.U: the generalized force of a unit force along
/// friction row i of each of `ks`'s rows (row k's first unknown at k.*first),
/// with data_ at the state's kinematics.
void Simulator::Impl::frictionUnitForces(std::span<const int> ks, int UnilateralRow::*first,
                                   detail::FrictionProblem& p) {
  auto& u = *uni_;
  for (int k : ks) {
    const UnilateralRow& r = u.rows[k];
    const auto& sr = cdata_->slide[r.c];
    for (int i = 0; i < r.nf; ++i) {
      auto col = p.U.col(r.*first + i);
      col.setZero();
      if (r.a >= 0) {
        spatialJacobianWorld(model_, *data_, r.a, u.J);
        col.noalias() += u.J.transpose() * sr.Wa.row(i).transpose();
      }
      if (r.b >= 0) {
        spatialJacobianWorld(model_, *data_, r.b, u.J);
        col.noalias() -= u.J.transpose() * sr.Wb.row(i).transpose();
      }
    }
  }
}

/// The affine maps of the problem over `ks` (their F friction rows released
/// by the caller): slip accelerations a0 + W f and normal loads ln0 + N f at
/// (t, q, v) under τ + U f — one solve at τ and one per unit row force, at
/// the scale of the loads (the map is affine: any scale is exact up to
/// round-off relative to τ). false with p.res.error when a solve fails.
bool Simulator::Impl::frictionResponses(double t, const VecX& q, const VecX& v, const VecX& tau,
                                  std::span<const int> ks, int UnilateralRow::*first, int F,
                                  detail::FrictionProblem& p, bool with_velocities) {
  const int K = static_cast<int>(ks.size());
  auto respond = [&](const VecX& tau_prime, Eigen::Ref<VecX> acc, Eigen::Ref<VecX> load) {
    if (!solveDynamics(t, q, v, tau_prime, p.res)) return false;
    forwardKinematics(model_, *data_, q, v, p.res.vdot);
    for (int j = 0; j < K; ++j) {
      const UnilateralRow& r = uni_->rows[ks[j]];
      const auto& sr = cdata_->slide[r.c];
      const Vec6 aa = r.a >= 0 ? spatialAccelerationWorld(*data_, r.a) : Vec6::Zero();
      const Vec6 ab = r.b >= 0 ? spatialAccelerationWorld(*data_, r.b) : Vec6::Zero();
      for (int i = 0; i < r.nf; ++i)
        acc[r.*first + i] = sr.kappa[i] + sr.Wa.row(i).dot(aa) - sr.Wb.row(i).dot(ab);
      load[j] = p.res.lambda[r.global];
    }
    return true;
  };
  if (!respond(tau, p.a0.head(F), p.ln0.head(K))) return false;
  if (with_velocities) p.V.col(0) = p.res.vdot;  // (the base, until column 0's response)
  const double scale = std::max(1.0, p.ln0.head(K).cwiseAbs().maxCoeff());
  for (int c = 0; c < F; ++c) {
    // (Its own vector: the solve superposes sliding friction in tau_f.)
    p.tau = tau + scale * p.U.col(c);
    if (!respond(p.tau, p.acc.head(F), p.load.head(K))) return false;
    p.W.col(c).head(F) = (p.acc.head(F) - p.a0.head(F)) / scale;
    p.N.col(c).head(K) = (p.load.head(K) - p.ln0.head(K)) / scale;
    if (with_velocities) {
      // Column c − 1 held the base: move it along (no extra storage).
      if (c + 1 < F) p.V.col(c + 1) = p.V.col(c);
      p.V.col(c) = (p.res.vdot - p.V.col(c)) / scale;
    }
  }
  return true;
}

/// The slip velocity of unilateral row k's friction rows at data_'s
/// velocities (a sliding contact's as evaluated; a sticking one's from its
/// rows, before any projection).
Vec3 Simulator::Impl::contactSlip(int k) const {
  const UnilateralRow& r = uni_->rows[k];
  const auto& sr = cdata_->slide[r.c];
  if (cdata_->isSliding(r.c)) return sr.slip;
  const RowBlock& blk = cdata_->blocks[r.c];
  Vec3 slip = Vec3::Zero();
  for (int i = 0; i < sr.n; ++i) {
    const int row = sr.row[i];
    double val = blk.b[row];
    if (r.a >= 0) val += blk.Wa.row(row).dot(data_->oMi[r.a].act(data_->v[r.a]));
    if (r.b >= 0) val -= blk.Wb.row(row).dot(data_->oMi[r.b].act(data_->v[r.b]));
    slip[i] = sr.scale[i] * val;
  }
  return slip;
}

}  // namespace appell
