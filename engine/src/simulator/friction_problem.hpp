// Friction forces as the unknowns of one problem, shared by the friction
// stages that decide several contacts together — the onset at zero slip
// (friction_onset.cpp), the settled directions (friction_settled.cpp), an
// impact's friction impulses (friction_impact.cpp), over-constrained
// sticking (friction_overconstrained.cpp) — and by the time-stepping
// contact problem (timestepping/contact_problem.cpp, diskMinimizer):
//
//   U (nv × F)  the generalized force of a unit force along each friction row,
//   W (F × F)   the slip accelerations' response,  ṡ = a0 + W f,
//   N (K × F)   the normal loads' response,        λₙ = ln0 + N f,
// built by Simulator::Impl::frictionUnitForces and frictionResponses
// (friction_problem.cpp: one dynamics solve at τ and one per unit row force),
// and each contact's disk problem solved exactly by diskMinimizer.
#pragma once

#include <appell/constrained_dynamics.hpp>

#include <algorithm>

namespace appell::detail {

/// The friction forces of a set of contacts as the unknowns of one problem
/// (friction_onset.cpp, friction_settled.cpp), sized for every friction row:
/// their generalized forces per unit row force U (nv × F), the slip
/// accelerations' and normal loads' responses W (F × F) and N (K × F), the
/// free terms a0 and ln0, the forces f, and the solves' workspace.
struct FrictionProblem {
  MatX U, W, N;
  MatX V;  // with_velocities: the generalized velocities' (v̇'s) response (nv × F)
  VecX a0, ln0, acc, load, f, f_old, tau;
  ConstrainedResult res;
  /// Block Gauss–Seidel's view of the contact whose n rows start at o0
  /// (the others' forces fixed): min ½ f_jᵀH f_j + cᵀf_j, H its W block
  /// (symmetrized), c = a0_j + Σ_{i≠j} W_ji f_i.
  void disk(int o0, int n, int F, Mat3& H, Vec3& c) const {
    H.setZero();
    H.topLeftCorner(n, n) = W.block(o0, o0, n, n);
    H = 0.5 * (H + H.transpose()).eval();
    c.setZero();
    c.head(n) = a0.segment(o0, n);  // (products one by one: no temporaries)
    c.head(n).noalias() += W.block(o0, 0, n, F) * f.head(F);
    c.head(n).noalias() -= H.topLeftCorner(n, n) * f.segment(o0, n);
  }
  /// Block Gauss–Seidel from f = 0 over K contacts until f stops changing
  /// (to 1e-14 of the largest radius): block(j) sets contact j's forces in
  /// f (the loads read the others' as they are) and returns its disk's
  /// radius. false when `sweeps` sweeps did not settle it, or when the
  /// change has not shrunk against the sweep two before for kStuckSweeps
  /// sweeps in a row: the sweeps cycle or drift and never settle. (The disk
  /// radii follow the loads, which follow f, so the iteration is not a
  /// descent; on a CAD car's four tyres at a slip onset the change stays at
  /// the same value to four digits for the whole 10⁴ sweeps. The longest
  /// flat stretch that still settled, over every example, test and published
  /// robot, was under 160 sweeps: docs/contacts.md §8.) Each block solved
  /// adds one to `updates` (SimulatorCounters::block_updates).
  template <class Block>
  bool gaussSeidel(int K, int F, int sweeps, long& updates, Block&& block) {
    constexpr int kStuckSweeps = 256;
    constexpr double kShrink = 1e-6;  // less than this relative decrease is none
    f.head(F).setZero();
    double change[2] = {0, 0};  // the last two sweeps' changes
    int stuck = 0;
    for (int sweep = 0; sweep < sweeps; ++sweep) {
      updates += K;
      f_old.head(F) = f.head(F);
      double fmax = 0;
      for (int j = 0; j < K; ++j) fmax = std::max(fmax, block(j));
      const double moved = (f.head(F) - f_old.head(F)).lpNorm<Eigen::Infinity>();
      const double scale = std::max(fmax, 1e-300);
      if (sweep > 0 && moved <= 1e-14 * scale) return true;
      const double d = moved / scale;
      stuck = sweep >= 2 && d >= (1 - kShrink) * change[sweep % 2] ? stuck + 1 : 0;
      if (stuck >= kStuckSweeps) return false;
      change[sweep % 2] = d;
    }
    return false;
  }
  /// Contact j's load (normal force or impulse) at the current forces.
  double loadAt(int j, int F) const { return ln0[j] + N.row(j).head(F).dot(f.head(F)); }
  void size(int nv, int nf, int kf, const ConstrainedResult& like) {
    U = MatX::Zero(nv, nf);
    V = MatX::Zero(nv, nf);
    W = MatX::Zero(nf, nf);
    N = MatX::Zero(kf, nf);
    a0 = acc = f = f_old = VecX::Zero(nf);
    ln0 = load = VecX::Zero(kf);
    tau = VecX::Zero(nv);
    res = like;
  }
};

/// argmin ½ fᵀH f + cᵀf over |f| ≤ r in the first n (≤ 3) components, H
/// symmetric positive semidefinite (friction_problem.cpp).
Vec3 diskMinimizer(const Mat3& H, const Vec3& c, int n, double r);

/// H's eigen-decomposition as diskMinimizer uses it (H padded with the
/// identity beyond n, eigenvalues clamped at 0): computed once where H is
/// fixed and many c are tried (the time-stepping Gauss–Seidel's blocks).
struct DiskFactor {
  Mat3 vectors = Mat3::Identity();
  Vec3 values = Vec3::Ones();
};
DiskFactor factorDisk(const Mat3& H, int n);
/// diskMinimizer(H, c, n, r) from H's factor: the same arithmetic.
Vec3 diskMinimizer(const DiskFactor& H, const Vec3& c, int n, double r);
/// The disk problem without its disk, in H's eigenbasis: cq = Vᵀc (c past n
/// zero) and fq the minimum-norm unconstrained minimizer (zero along H's
/// null directions). false when c has a part in that null space: no finite
/// minimizer, the answer is on the circle. diskMinimizer's first part.
bool diskUnconstrained(const DiskFactor& H, const Vec3& c, int n, Vec3& cq, Vec3& fq);
/// The root x ≥ `lower` of the secular equation |f(x)| = r, fᵢ = −cᵢ/(λᵢ + x)
/// (components with cᵢ = 0 left out), for x above −λᵢ of every cᵢ ≠ 0 —
/// the multiplier of a disk's minimizer on its circle (diskMinimizer, lower
/// 0) and of a settled slip direction (friction_settled.cpp, lower −λ₁).
/// φ(x) = 1/|f(x)| − 1/r is increasing and concave there, so Newton's method
/// from a lower bound of the root climbs to it monotonically and
/// quadratically (Moré & Sorensen, "Computing a trust region step", SIAM J.
/// Sci. Stat. Comput. 4, 1983): ~5 iterations where a bisection to round-off
/// takes ~55. The start: `lower`, or where one component alone reaches r.
double secularRoot(const Vec3& lam, const Vec3& cq, double r, double lower);

}  // namespace appell::detail
