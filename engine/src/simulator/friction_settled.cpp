// Sliding contacts on their settled slip directions.
//
// A sliding contact's friction −μₖλₙ ŝ follows the direction of its slip s.
// With the rest of the system, its slip evolves as
//     ṡ = a + W f,        f = −μₖλₙ s/|s|,
// a the slip acceleration without its friction, W its rows' Delassus
// operator under the remaining constraints (friction_onset.cpp). The
// direction of s turns at a rate of order μₖλₙ‖W‖/|s|: when the slip is
// tiny beside that — an axle a micro-radian out of line scrubs at 10⁻⁶ of
// the car's speed, 4·10⁸ s⁻¹ (docs/contacts.md §8) — the direction is a fast
// variable and an explicit integrator crawls through its relaxation. Its
// slow limit is algebraic (Tikhonov's theorem on singularly perturbed
// systems; Kokotović, Khalil & O'Reilly, "Singular Perturbation Methods in
// Control", 1986, ch. 1): the direction has settled when the slip
// accelerates along itself, a + W f = −κ f with κ ≥ 0 and |f| = μₖλₙ, which
// are the optimality conditions of
//     min ½ fᵀW f + aᵀf   over   |f| ≤ μₖλₙ
// with f on the circle — the maximal-dissipation problem the onset solves
// at zero slip (Moreau 1988; Pfeiffer & Glocker 1996, §7.3), here for a slip
// that is small but not zero. The error of the limit is the lag of the true
// direction behind the settled one, about (settling time) × (its rate of
// turning).
//
// So a sliding contact whose settling time |s| / (μₖλₙ‖W‖) is below
// ContactEventOptions::settle_time takes the circle's force. The stationary
// directions come one per side of a soft direction of W: the minimizer
// (κ ≥ 0: the slip grows along itself) and, for a slip that shrinks, the
// stable root on its own side (settledForce below) — a parallel-steered
// car's scrub when the hand wheel turns back, which the minimizer would
// have flipped against the slip. A slip that its own friction brakes as
// fast as it turns it stops before its direction settles: it slides along
// its slip, and the stick event takes it. Each candidate's friction rows are released (as in the onset), W
// and the loads' response N come from one solve per row force, the forces
// from block Gauss–Seidel over the candidates' disks with the loads updated,
// and the last solve applies them: F + 2 solves for F candidate rows, each
// as the other sliding contacts need (friction.cpp). The reported friction
// multipliers are the forces along the rows, as for every sliding contact.
#include <appell/kinematics.hpp>
#include <appell/simulator.hpp>

#include "simulator/simulator_impl.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>

namespace appell {

using detail::UnilateralRow;

namespace {

/// The settled friction force of a slip on `side`: f on the circle |f| = r
/// with c + H f = −κ f (H symmetric positive semidefinite in the first n
/// components, eigenvalues λ₁ ≤ λ₂ ≤ …), the stable stationary direction of
///     ŝ' = (1 − ŝŝᵀ)(c − r H ŝ) / |s|,   f = −r ŝ,
/// whose slip ŝ = −f/r lies on side's half (ŝ·side > 0). Stable means H + κI
/// positive on the plane across ŝ. In H's eigenbasis fᵢ = −cᵢ/(λᵢ + κ), and
/// |f(κ)|² = Σ cᵢ²/(λᵢ + κ)² equals r² at one κ > −λ₁ (the upper root: the
/// disk minimizer when κ ≥ 0, the slip growing along itself; κ < 0, the slip
/// shrinking, when the minimizer is inside the circle) and at most at two in
/// (−λ₂, −λ₁), convex there: the one nearest −λ₁ is stable, on the other
/// side of e₁ (the slip shrinking along itself). Taken: the upper root with
/// κ ≥ 0 on side's half; a shrinking root (κ < 0) on side's half when the
/// slip along `side` shrinks, under the exact law, at most kSettledShrink
/// times as fast as its direction relaxes onto the root — rates
/// −ŝᵀ(c − rHŝ)/|s| and r(λ₂ + κ)/|s| (the smallest eigenvalue of H + κI
/// across the root). false otherwise: the slip's direction is not settled,
/// and it slides along it.
/// The largest ratio of a slip's shrinking rate to its direction's
/// relaxation rate for a shrinking settled direction to be taken.
constexpr double kSettledShrink = 0.1;

}  // namespace

/// H's n eigenpairs as settledForce uses them (H's n × n block padded with
/// zeros; the padding's eigenvalues left out, ascending). H is fixed over
/// one island's sweeps: factored once, at its candidate's first use.
detail::SettleFactor detail::settleFactor(const Mat3& H, int n) {
  Mat3 Hp = Mat3::Zero();
  Hp.topLeftCorner(n, n) = H.topLeftCorner(n, n);
  Eigen::SelfAdjointEigenSolver<Mat3> es(Hp);
  // The padded zero block's eigenvalues sit beside the real ones: keep the n
  // whose eigenvectors lie in the first n components (ascending).
  SettleFactor out;
  for (int i = 0; i < 3 && out.m < n; ++i) {
    if (es.eigenvectors().col(i).head(n).norm() < 0.5) continue;
    out.lam[out.m] = std::max(es.eigenvalues()[i], 0.0);
    out.E.col(out.m) = es.eigenvectors().col(i);
    ++out.m;
  }
  return out;
}

namespace {

/// The root of g, increasing on (a, b) with g < 0 left of the root and
/// g ≥ 0 right of it: Newton's steps, a step that leaves the bracket
/// replaced by its midpoint (a safeguarded Newton method, "rtsafe" in Press
/// et al., Numerical Recipes, 3rd ed. 2007, §9.4), from x, to round-off —
/// ~5 evaluations where bisection took ~55. g(x, value, slope).
template <class G>
double bracketedRoot(double a, double b, double x, G&& g) {
  if (!(x > a && x < b)) x = 0.5 * (a + b);
  for (int it = 0; it < 200 && b - a > 1e-16 * (std::abs(a) + std::abs(b)); ++it) {
    double v, dv;
    g(x, v, dv);
    if (v == 0) return x;
    (v < 0 ? a : b) = x;
    const double step = v / dv;
    if (std::abs(step) <= 4e-16 * std::abs(x)) return x - step;  // (round-off reached)
    x -= step;
    if (!(x > a && x < b)) x = 0.5 * (a + b);
  }
  return x;
}

bool settledForce(const detail::SettleFactor& fac, const Mat3& H, const Vec3& c, int n, double r,
                  const Vec3& side, Vec3& f) {
  const Vec3& lam = fac.lam;
  const Mat3& E = fac.E;
  const int m = fac.m;
  Vec3 cq = Vec3::Zero();
  for (int i = 0; i < m; ++i) cq[i] = E.col(i).dot(c);
  const double cn = cq.norm();  // (its components past n are zero)
  if (m != n || !(r > 0) || !(std::abs(cq[0]) > 1e-14 * cn)) return false;
  auto norm2 = [&](double kappa) {
    double s = 0;
    for (int i = 0; i < n; ++i) s += cq[i] * cq[i] / ((lam[i] + kappa) * (lam[i] + kappa));
    return s;
  };
  auto force = [&](double kappa) {
    Vec3 fq = Vec3::Zero();
    for (int i = 0; i < n; ++i) fq[i] = -cq[i] / (lam[i] + kappa);
    Vec3 out = E * fq;
    out.tail(3 - n).setZero();
    return out;
  };
  // The upper root, κ > −λ₁ (|f| decreases from +∞ there).
  const double b = detail::secularRoot(lam, cq, r, -lam[0]);
  double a;
  // A growing slip (κ ≥ 0) keeps its direction while it relaxes onto this
  // one; a shrinking one may stop first — a slip that its own friction
  // brakes about as fast as it turns it ends in a stick event, and its
  // direction on the way is the exact law's — so it takes a shrinking root
  // only when it shrinks slowly beside that relaxation (a scrub that the
  // geometry, not its friction, winds down).
  const double shrink = -side.dot(c - r * (H * side));  // d|s|/dt = −shrink (exact law)
  auto slowly = [&](double kappa) {
    const double across = n > 1 ? lam[1] + kappa : HUGE_VAL;
    return shrink <= kSettledShrink * r * across;
  };
  f = force(b);
  if (f.allFinite() && -f.dot(side) > 0 && (b >= 0 || slowly(b))) return true;
  // The lower root nearest −λ₁: right of |f|²'s minimum on (−λ₂, −λ₁) (one
  // direction: on (−λ₁ − 2|c|/r, −λ₁), |f| < r at its left end).
  const double hi = -lam[0];
  double lo = n > 1 ? -lam[1] : hi - 2 * cn / r;
  if (!(lo < hi)) return false;
  a = lo;
  if (n > 1) {
    // The minimum: d|f|²/dκ = −2 Σ cᵢ²/dᵢ³ (dᵢ = λᵢ + κ) vanishes. With two
    // rows, d₁ < 0 < d₂, where c₁²/|d₁|³ = c₂²/d₂³ and |d₁| + d₂ = λ₂ − λ₁:
    // d₂ = (λ₂ − λ₁)/(1 + (|c₁|/|c₂|)^⅔). With three, the increasing slope's root.
    if (n == 2) {
      a = cq[1] == 0 ? lo : (lam[1] - lam[0]) / (1 + std::cbrt(cq[0] * cq[0] / (cq[1] * cq[1]))) - lam[1];
      a = std::clamp(a, lo, hi);
    } else {
      a = bracketedRoot(lo, hi, 0.5 * (lo + hi), [&](double kappa, double& s, double& ds) {
        s = ds = 0;
        for (int i = 0; i < n; ++i) {
          const double d = lam[i] + kappa, c2 = cq[i] * cq[i];
          s -= c2 / (d * d * d);
          ds += 3 * c2 / (d * d * d * d);
        }
      });
    }
    if (!(norm2(a) <= r * r)) return false;
  }
  // |f| = r right of it, where |f| grows to ∞ at −λ₁: Newton's method on
  // 1/r − 1/|f|, nearly linear there (1/|f| ≈ |d₁|/|c₁| near the pole),
  // from where the first component alone reaches r.
  a = bracketedRoot(a, hi, hi - std::abs(cq[0]) / r, [&](double kappa, double& g, double& dg) {
    double f2 = 0, df2 = 0;  // |f|² and its derivative
    for (int i = 0; i < n; ++i) {
      const double d = lam[i] + kappa, c2 = cq[i] * cq[i];
      f2 += c2 / (d * d);
      df2 -= 2 * c2 / (d * d * d);
    }
    const double fn = std::sqrt(f2);
    g = 1 / r - 1 / fn;
    dg = 0.5 * df2 / (f2 * fn);
  });
  f = force(a);
  return f.allFinite() && -f.dot(side) > 0 && slowly(a);
}

}  // namespace

// One candidate's turn in the block Gauss–Seidel (the loads updated as it
// sweeps): its force on the disk of radius μₖλₙ, at the settled direction's
// minimizer while its slip is slow beside the disk's answer, or along its
// slip (its force then known, still affine in its load). Returns the radius.
double Simulator::Impl::settleCandidate(std::span<const int> run, int j, int F) {
  auto& u = *uni_;
  auto& p = u.settle_problem;
  const double floor = 10 * options_.contacts.speed_tol;
  UnilateralRow& r = u.rows[run[j]];
  const int o0 = r.settle_force, n = r.nf;
  const double radius = r.mu_k * std::max(0.0, p.loadAt(j, F));
  const double slip = cdata_->slide[r.c].slip.norm();
  Vec3 fj = Vec3::Zero();
  if (slip < options_.contacts.settle_time * radius * u.swmax[j]) {
    Mat3 H;
    Vec3 c;
    p.disk(o0, n, F, H, c);
    // The stable settled direction on the slip's own side.
    detail::slipDirection(*cdata_, r, floor);
    if (!u.settle_factored[j]) {
      u.settle_factor[j] = detail::settleFactor(H, n);
      u.settle_factored[j] = 1;
    }
    if (!settledForce(u.settle_factor[j], H, c, n, radius, r.dir, fj)) fj.setZero();  // along its slip (below)
  }
  if (!(fj.norm() >= (1 - 1e-9) * radius) || radius == 0) {
    detail::slipDirection(*cdata_, r, floor);
    fj = -radius * r.dir;
  }
  p.f.segment(o0, n) = fj.head(n);
  return radius;
}

// The settled candidates' directions from their forces, and their forces
// reported on their friction rows' multipliers.
void Simulator::Impl::recordSettledForces(ConstrainedResult& out, SolveOutputs outputs) {
  auto& u = *uni_;
  for (int k : u.settle) {
    UnilateralRow& r = u.rows[k];
    const auto& sr = cdata_->slide[r.c];
    const double fn = r.settled.head(r.nf).norm();
    if (fn > 0) {
      r.dir.setZero();
      r.dir.head(r.nf) = -r.settled.head(r.nf) / fn;
    }
    if (outputs == SolveOutputs::All)
      for (int i = 0; i < sr.n; ++i)
        out.lambda[cdata_->offset[r.c] + sr.row[i]] = r.settled[i] * sr.scale[i];
  }
}

// One island's candidates: their forces (kept in r.settled), added to
// u.settle_tau, and the power they take added to `power`. false with
// out.error when a solve fails; true with out.ok false when the sweeps did
// not settle.
bool Simulator::Impl::settleIsland(double t, const VecX& q, const VecX& v, const VecX& tau,
                                   std::span<const int> run, double& power,
                                   ConstrainedResult& out) {
  auto& u = *uni_;
  auto& p = u.settle_problem;
  const int K = static_cast<int>(run.size());
  const int F = detail::numberUnknowns(u.rows, run, &UnilateralRow::settle_force);
  frictionUnitForces(run, &UnilateralRow::settle_force, p);
  // (The other sliding contacts superposed as usual in each solve.)
  if (!frictionResponses(t, q, v, tau, run, &UnilateralRow::settle_force, F, p)) {
    out.ok = false;
    out.error = "sliding friction (settled directions): " + p.res.error;
    return false;
  }
  for (int j = 0; j < K; ++j) {
    const UnilateralRow& r = u.rows[run[j]];
    Mat3 H = Mat3::Zero();
    H.topLeftCorner(r.nf, r.nf) = p.W.block(r.settle_force, r.settle_force, r.nf, r.nf);
    H = 0.5 * (H + H.transpose()).eval();
    u.swmax[j] = Eigen::SelfAdjointEigenSolver<Mat3>(H, Eigen::EigenvaluesOnly).eigenvalues().maxCoeff();
  }
  // Block Gauss–Seidel over the candidates' disks, the loads updated as it
  // sweeps. A candidate slow to settle, or whose minimizer is inside its
  // circle, slides along its slip (its force then known, still affine in
  // its load).
  std::fill_n(u.settle_factored.begin(), K, 0);
  out.ok = p.gaussSeidel(K, F, 1000, counters_.block_updates, [&](int j) { return settleCandidate(run, j, F); });
  if (!out.ok) return true;
  u.settle_tau.noalias() += p.U.leftCols(F) * p.f.head(F);
  for (int c = 0; c < F; ++c) power -= p.f[c] * p.U.col(c).dot(v);
  for (int k : run) {
    UnilateralRow& r = u.rows[k];
    r.settled.setZero();
    r.settled.head(r.nf) = p.f.segment(r.settle_force, r.nf);
  }
  return true;
}

bool Simulator::Impl::solveSettling(double t, const VecX& q, const VecX& v, const VecX& tau,
                              ConstrainedResult& out, SolveOutputs outputs) {
  auto& u = *uni_;
  detail::gatherByIsland(u.islands, u.settle, u.settle_runs, [&](int k) {
    if (!u.rows[k].settling) return false;
    u.rows[k].released = true;  // its force is this solve's unknown
    return true;
  });
  auto restore = [&] {
    for (int k : u.settle) {
      u.rows[k].released = false;
      u.rows[k].settling = false;
    }
  };
  u.settle_tau = tau;
  double power = 0;
  for (int i = 0; i + 1 < static_cast<int>(u.settle_runs.size()); ++i) {
    if (!settleIsland(t, q, v, tau, detail::runOf(u.settle, u.settle_runs, i), power, out)) {
      restore();
      return false;
    }
    if (out.ok) continue;
    // Unsettled: every contact along its slip, as without this path (the
    // loads still exact).
    ++counters_.settle_unsettled;
    restore();
    u.settle_off = true;
    const bool ok = solveDynamics(t, q, v, tau, out, outputs);
    u.settle_off = false;
    return ok;
  }
  // The last solve, with the candidates' forces applied.
  if (!solveDynamics(t, q, v, u.settle_tau, out, outputs)) {
    restore();
    return false;
  }
  u.friction_power += power;  // beside the other sliding contacts'
  recordSettledForces(out, outputs);
  restore();
  return true;
}

}  // namespace appell
