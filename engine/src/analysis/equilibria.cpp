// Equilibrium finder: minimum-norm Gauss–Newton / Levenberg–Marquardt on
//   F(θ, λ) = [ (Q(q) + Aᵀ(q) λ) / f_s ;  g(q) / ℓ_s ],   q = retract(q_k, θ),
// re-based at every iterate (θ = 0 at q_k, so the local coordinates stay small).
// ∂F/∂λ = [Aᵀ; 0]/f_s exactly; ∂F/∂θ by central differences.
// Why minimum norm: the equilibria form a manifold (Emelyanova & Fufaev 1978, docs/equilibria.md: dimension ≥ the
// number of nonholonomic rows), so J is wide or rank-deficient and the
// Gauss–Newton step is not unique; the minimum-norm one (complete orthogonal
// decomposition) moves least, i.e. toward the nearest point of the manifold.
// Columns are scaled to unit norm first (θ mixes radians and metres, λ is in
// newtons) so "minimum norm" does not favour one unit over another.
#include <appell/equilibria.hpp>

#include <appell/configuration.hpp>
#include <appell/dynamics.hpp>

#include <Eigen/QR>
#include <Eigen/SVD>

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace appell {

namespace {

class Residual {
 public:
  Residual(const Model& model, const ConstraintList& constraints, const EquilibriumOptions& opt)
      : model_(model), constraints_(constraints), opt_(opt), data_(model), cd_(model, constraints),
        zero_(VecX::Zero(model.nv)) {
    tau_ = opt.tau.size() == 0 ? VecX::Zero(model.nv) : opt.tau;
    for (int r = 0; r < cd_.m; ++r)
      if (cd_.holonomic[r]) holonomic_.push_back(r);
  }

  int m() const { return cd_.m; }
  int nh() const { return static_cast<int>(holonomic_.size()); }
  int ne() const { return model_.nv + nh(); }
  const ConstraintData& cd() const { return cd_; }

  /// Evaluates A, gaps, b, abias and Q at q (v = 0). False when the geometry is
  /// singular or anything is not finite.
  bool at(const VecX& q, VecX& Q) {
    evaluateConstraints(model_, data_, constraints_, cd_, opt_.time, q, zero_);
    if (cd_.singular) {
      last_singular_ = cd_.singular_reason;
      return false;
    }
    Q = tau_ - nonLinearEffects(model_, data_, q, zero_);
    return Q.allFinite() && cd_.A.allFinite() && cd_.gap.allFinite();
  }

  bool residual(const VecX& q, const VecX& lambda, double fs, double ls, VecX& F) {
    VecX Q;
    if (!at(q, Q)) return false;
    F.resize(ne());
    F.head(model_.nv) = (Q + cd_.A.transpose() * lambda) / fs;
    for (int k = 0; k < nh(); ++k) F[model_.nv + k] = cd_.gap[holonomic_[k]] / ls;
    return F.allFinite();
  }

  /// ∂F/∂θ at (q, λ) by central differences; false if a probe hit a singular point.
  bool jacobianTheta(const VecX& q, const VecX& lambda, double fs, double ls, MatX& Jt) {
    const int nv = model_.nv;
    Jt.resize(ne(), nv);
    VecX th = VecX::Zero(nv), qp(model_.nq), Fp, Fm;
    const double h = opt_.fd_step;
    for (int k = 0; k < nv; ++k) {
      th.setZero();
      th[k] = h;
      retract(model_, q, th, qp);
      if (!residual(qp, lambda, fs, ls, Fp)) return false;
      th[k] = -h;
      retract(model_, q, th, qp);
      if (!residual(qp, lambda, fs, ls, Fm)) return false;
      Jt.col(k) = (Fp - Fm) / (2 * h);
    }
    return true;
  }

  const std::string& lastSingular() const { return last_singular_; }

 private:
  const Model& model_;
  const ConstraintList& constraints_;
  const EquilibriumOptions& opt_;
  Data data_;
  ConstraintData cd_;
  VecX zero_, tau_;
  std::vector<int> holonomic_;
  std::string last_singular_;
};

void validate(const Model& model, const VecX& q, const EquilibriumOptions& opt) {
  if (q.size() != model.nq)
    throw std::invalid_argument("findEquilibrium: q_guess has size " + std::to_string(q.size()) +
                                ", the model has nq = " + std::to_string(model.nq));
  if (!q.allFinite()) throw std::invalid_argument("findEquilibrium: q_guess is not finite");
  if (opt.tau.size() != 0 && opt.tau.size() != model.nv)
    throw std::invalid_argument("findEquilibrium: tau has size " + std::to_string(opt.tau.size()) +
                                ", expected nv = " + std::to_string(model.nv) + " or empty");
  if (!(opt.tolerance > 0) || !(opt.length_scale > 0) || !(opt.fd_step > 0) || opt.max_iterations < 1)
    throw std::invalid_argument(
        "findEquilibrium: tolerance, length_scale and fd_step must be positive, max_iterations ≥ 1");
}

double maxAbs(const VecX& x) { return x.size() == 0 ? 0.0 : x.lpNorm<Eigen::Infinity>(); }

/// The Gauss–Newton / Levenberg–Marquardt search over x = (θ, λ): the
/// scaled residual F(q, λ) = 0 (force balance over fs, holonomic gaps over
/// ls). Updates q, λ and F; returns the iterations taken, and in stop why it
/// ended short of the tolerance.
class Search {
 public:
  Search(const Model& model, Residual& res, double fs, double ls)
      : model_(model), res_(res), fs_(fs), ls_(ls), nv_(model.nv), m_(res.m()), ne_(res.ne()),
        nx_(nv_ + m_), J_(ne_, nx_), Js_(ne_, nx_), D_(nx_), qn_(model.nq) {}

  int run(VecX& q, VecX& lambda, VecX& F, const EquilibriumOptions& opt, std::string& stop) {
    stop = "iteration limit reached";
    int it = 0;
    for (; it < opt.max_iterations; ++it) {
      if (maxAbs(F) <= opt.tolerance) break;
      if (!scaledJacobian(q, lambda)) {
        stop = "a finite-difference probe hit singular geometry (" + res_.lastSingular() + ")";
        break;
      }
      const VecX grad = Js_.transpose() * F;
      if (grad.norm() <= 1e-13 * std::max(1.0, Js_.norm()) * F.norm()) {
        stop = "the residual is stationary (a local minimum of ‖F‖ that is not zero)";
        break;
      }
      if (!dampedStep(q, lambda, F)) {
        stop = "no step reduces the residual (a local minimum of ‖F‖ that is not zero)";
        break;
      }
      if (slow_ >= 30) {
        stop = "the residual stopped decreasing";
        break;
      }
    }
    return it;
  }

 private:
  /// J = ∂F/∂(θ, λ) at (q, λ), and Js = J D⁻¹ with D its column norms.
  bool scaledJacobian(const VecX& q, const VecX& lambda) {
    if (!res_.jacobianTheta(q, lambda, fs_, ls_, Jt_)) return false;
    VecX Q;
    res_.at(q, Q);
    J_.leftCols(nv_) = Jt_;
    J_.rightCols(m_).setZero();
    J_.topRightCorner(nv_, m_) = res_.cd().A.transpose() / fs_;
    // Column scaling, floored: a column that is zero up to finite-difference
    // noise (a direction along the equilibrium manifold, e.g. a cyclic
    // coordinate) must not be blown up to unit size — the minimum-norm step
    // would then move far along it to cancel noise.
    double cmax = 0;
    for (int c = 0; c < nx_; ++c) cmax = std::max(cmax, J_.col(c).norm());
    for (int c = 0; c < nx_; ++c) {
      D_[c] = std::max(J_.col(c).norm(), 1e-3 * cmax);
      if (!(D_[c] > 0)) D_[c] = 1.0;
      Js_.col(c) = J_.col(c) / D_[c];
    }
    return true;
  }

  /// Up to 16 tries of the step with Levenberg–Marquardt damping μ; true
  /// when one reduced ‖F‖ (and was taken).
  bool dampedStep(VecX& q, VecX& lambda, VecX& F) {
    const double scale2 = (Js_.transpose() * Js_).diagonal().maxCoeff();
    for (int tries = 0; tries < 16; ++tries) {
      VecX ds;
      if (mu_ == 0) {
        // Singular values below the finite-difference noise are rank
        // deficiency, not directions to follow.
        Eigen::CompleteOrthogonalDecomposition<MatX> cod(Js_);
        cod.setThreshold(1e-6);
        ds = cod.solve(-F);
      } else {
        MatX Aug(ne_ + nx_, nx_);
        Aug << Js_, std::sqrt(mu_) * MatX::Identity(nx_, nx_);
        VecX rhs = VecX::Zero(ne_ + nx_);
        rhs.head(ne_) = -F;
        ds = Eigen::ColPivHouseholderQR<MatX>(Aug).solve(rhs);
      }
      const VecX dx = ds.cwiseQuotient(D_);
      retract(model_, q, dx.head(nv_), qn_);
      lam_n_ = lambda + dx.tail(m_);
      if (dx.allFinite() && res_.residual(qn_, lam_n_, fs_, ls_, Fn_) && Fn_.norm() < F.norm()) {
        slow_ = Fn_.norm() > 0.999 * F.norm() ? slow_ + 1 : 0;
        q = qn_;
        lambda = lam_n_;
        F = Fn_;
        mu_ = mu_ < 1e-12 * scale2 ? 0.0 : mu_ / 10;
        return true;
      }
      mu_ = mu_ == 0 ? 1e-6 * scale2 : mu_ * 10;
    }
    return false;
  }

  const Model& model_;
  Residual& res_;
  const double fs_, ls_;
  const int nv_, m_, ne_, nx_;
  MatX Jt_, J_, Js_;
  VecX D_, qn_, Fn_, lam_n_;
  double mu_ = 0;
  int slow_ = 0;
};

/// First or second kind: can the holonomic rows alone hold Q? The force
/// the holonomic rows leave unbalanced.
double holonomicResidual(const ConstraintData& cd, const VecX& Q, int nv) {
  const int m = cd.m;
  std::vector<int> hrows;
  for (int r = 0; r < m; ++r)
    if (cd.holonomic[r]) hrows.push_back(r);
  if (static_cast<int>(hrows.size()) == m) return 0;  // no nonholonomic row: the first kind by definition
  if (hrows.empty()) return maxAbs(Q);
  MatX Ah(nv, hrows.size());
  for (std::size_t k = 0; k < hrows.size(); ++k) Ah.col(k) = cd.A.row(hrows[k]).transpose();
  Eigen::CompleteOrthogonalDecomposition<MatX> cod(Ah);
  cod.setThreshold(1e-10);
  const VecX lh = cod.solve(-Q);
  return maxAbs(Q + Ah * lh);
}

/// The final report at q: minimum-norm multipliers, residuals, rank, kind.
void reportAt(Residual& res, const VecX& q, double fs, double ls, double tol, int nv,
              EquilibriumResult& out) {
  VecX Q;
  res.at(q, Q);
  const ConstraintData& cd = res.cd();
  const int m = cd.m;
  out.q = q;
  out.generalized_force = Q;
  if (m > 0) {
    Eigen::CompleteOrthogonalDecomposition<MatX> cod(cd.A.transpose());
    cod.setThreshold(1e-10);
    out.lambda = cod.solve(-Q);
    out.rank_A = static_cast<int>(cod.rank());
  } else {
    out.lambda = VecX();
  }
  out.redundant_rows = m - out.rank_A;
  out.holonomic_residual = holonomicResidual(cd, Q, nv);
  // A margin over the convergence tolerance: the held force is O(fs) when
  // a nonholonomic row is needed, round-off when not.
  out.second_kind = out.holonomic_residual > std::max(tol, 1e-8) * fs;
  out.reaction = m > 0 ? VecX(cd.A.transpose() * out.lambda) : VecX::Zero(nv);
  out.force_residual = maxAbs(Q + out.reaction);
  double g = 0;
  for (int r = 0; r < m; ++r)
    if (cd.holonomic[r]) g = std::max(g, std::abs(cd.gap[r]));
  out.gap_residual = g;
  out.motion_residual = maxAbs(cd.b) + maxAbs(cd.abias);
  out.residual = std::max(out.force_residual / fs, out.gap_residual / ls);
}

std::string searchMessage(const EquilibriumResult& out, bool balanced_but_moving, int it,
                          const std::string& stop) {
  std::ostringstream msg;
  msg.precision(3);
  if (out.converged) {
    msg << "converged in " << it << " iterations: scaled residual " << out.residual;
  } else if (balanced_but_moving) {
    msg << "no equilibrium: forces balance but the support moves here (|b| + |abias| = "
        << out.motion_residual << "), so v = 0 is not admissible";
  } else {
    msg << "no equilibrium near the guess: smallest scaled residual " << out.residual
        << " (force " << out.force_residual << ", gap " << out.gap_residual << ") after " << it
        << " iterations; " << stop;
  }
  return msg.str();
}

/// Local dimension: directions δθ along which some δλ keeps F = 0 to first
/// order, i.e. the null space of P ∂F/∂θ, P = 1 − U Uᵀ with U spanning range(∂F/∂λ).
void localDimension(Residual& res, double fs, double ls, const EquilibriumOptions& opt, int nv,
                    EquilibriumResult& out) {
  MatX Jt;
  if (!res.jacobianTheta(out.q, out.lambda, fs, ls, Jt)) return;
  const int m = res.m();
  MatX PJ = Jt;
  if (m > 0) {
    MatX Jl = MatX::Zero(res.ne(), m);
    Jl.topRows(nv) = res.cd().A.transpose() / fs;
    Eigen::JacobiSVD<MatX> svl(Jl, Eigen::ComputeThinU);
    const VecX& s = svl.singularValues();
    int r = 0;
    while (r < s.size() && s[r] > 1e-10 * std::max(s[0], 1e-300)) ++r;
    const MatX U = svl.matrixU().leftCols(r);
    PJ -= U * (U.transpose() * Jt);
  }
  Eigen::JacobiSVD<MatX> sv(PJ, Eigen::ComputeFullV);
  const VecX& s = sv.singularValues();
  const double ref = std::max(Jt.norm(), 1e-300);
  int rank = 0;
  while (rank < s.size() && s[rank] > opt.rank_tolerance * ref) ++rank;
  out.manifold_dimension = nv - rank;
  out.tangent = sv.matrixV().rightCols(nv - rank);
}

}  // namespace

EquilibriumResult findEquilibrium(const Model& model, const ConstraintList& constraints,
                                  const VecX& q_guess, const EquilibriumOptions& opt) {
  validate(model, q_guess, opt);
  Residual res(model, constraints, opt);
  const int m = res.m();
  EquilibriumResult out;
  for (size_t k = 0; k < constraints.size(); ++k)
    for (int r = 0; r < constraints[k]->rows(); ++r)
      out.row_labels.push_back(constraints[k]->name() + "/" + constraints[k]->rowLabel(r));

  VecX q = q_guess;
  normalizeQuaternions(model, q);
  VecX Q;
  if (!res.at(q, Q)) {
    out.q = q;
    out.lambda = VecX::Zero(m);
    out.message = "no equilibrium search: the starting guess is singular (" + res.lastSingular() + ")";
    out.residual = std::numeric_limits<double>::infinity();
    return out;
  }
  double fs = opt.force_scale;
  if (!(fs > 0)) {
    fs = std::max(maxAbs(Q), model.totalMass() * model.gravity.norm());
    if (!(fs > 0)) fs = 1.0;
  }
  const double ls = opt.length_scale, tol = opt.tolerance;
  // Start from the least-squares multipliers at the guess.
  VecX lambda = m > 0 ? VecX(Eigen::CompleteOrthogonalDecomposition<MatX>(res.cd().A.transpose()).solve(-Q))
                      : VecX();
  VecX F;
  res.residual(q, lambda, fs, ls, F);
  std::string stop;
  const int it = Search(model, res, fs, ls).run(q, lambda, F, opt, stop);
  out.iterations = it;
  reportAt(res, q, fs, ls, tol, model.nv, out);
  const bool moving = out.motion_residual > tol * ls;
  out.converged = out.residual <= tol && !moving;
  out.message = searchMessage(out, moving && out.residual <= tol, it, stop);
  localDimension(res, fs, ls, opt, model.nv, out);
  return out;
}

MultiStartResult findEquilibria(const Model& model, const ConstraintList& constraints,
                                const std::vector<VecX>& guesses, const EquilibriumOptions& options,
                                double same_tol) {
  MultiStartResult out;
  VecX d(model.nv);
  for (size_t k = 0; k < guesses.size(); ++k) {
    out.runs.push_back(findEquilibrium(model, constraints, guesses[k], options));
    const EquilibriumResult& r = out.runs.back();
    if (!r.converged) continue;
    bool dup = false;
    for (int j : out.distinct) {
      difference(model, out.runs[j].q, r.q, d);
      if (d.lpNorm<Eigen::Infinity>() <= same_tol) {
        dup = true;
        break;
      }
    }
    if (!dup) out.distinct.push_back(static_cast<int>(k));
  }
  // Equilibrium sets: a distinct equilibrium joins the set of an earlier one
  // when the straight path (in local coordinates) between them stays on
  // equilibria. Only sets of positive dimension can hold two.
  EquilibriumOptions walk = options;
  walk.max_iterations = 20;
  VecX q(model.nq);
  for (std::size_t a = 0; a < out.distinct.size(); ++a) {
    const EquilibriumResult& ra = out.runs[out.distinct[a]];
    int set = -1;
    for (std::size_t b = 0; b < a && set < 0; ++b) {
      const EquilibriumResult& rb = out.runs[out.distinct[b]];
      if (ra.manifold_dimension == 0 || rb.manifold_dimension == 0) continue;
      difference(model, rb.q, ra.q, d);
      const double length = d.norm();
      bool on = true;
      for (int k = 1; k < 8 && on; ++k) {
        retract(model, rb.q, (k / 8.0) * d, q);
        const EquilibriumResult e = findEquilibrium(model, constraints, q, walk);
        VecX step(model.nv);
        difference(model, q, e.q, step);
        on = e.converged && step.norm() <= 1e-3 * length;
      }
      if (on) set = out.set[b];
    }
    out.set.push_back(set >= 0 ? set : out.sets++);
  }
  return out;
}

}  // namespace appell
