// Linearization on the constraint manifold (see linearization.hpp).
// The tangent space is the null space of the constraint Jacobian in the reduced
// state x_r = (θ_retained, v); its θ-block is a central difference, its v-block
// is A exactly (the rows are linear in v). The flow's derivative along each
// basis vector is a central difference of f (two constrained solves), so the
// cost is 2k solves — the full 2nv × 2nv Jacobian is never formed.
#include <appell/linearization.hpp>

#include <appell/configuration.hpp>

#include <Eigen/SVD>

#include <algorithm>
#include <stdexcept>

namespace appell {

namespace {

class Flow {
 public:
  Flow(const Model& model, const ConstraintList& constraints, ConstrainedSolver& solver,
       const VecX& q_ref, const LinearizationOptions& opt)
      : model_(model), constraints_(constraints), solver_(solver), q_ref_(q_ref), opt_(opt),
        data_(model), cd_(model, constraints), q_(model.nq), thdot_(model.nv) {
    tau_ = opt.tau.size() == 0 ? VecX::Zero(model.nv) : opt.tau;
    for (int r = 0; r < cd_.m; ++r)
      if (cd_.holonomic[r]) holonomic_.push_back(r);
  }

  int nh() const { return static_cast<int>(holonomic_.size()); }
  int m() const { return cd_.m; }

  /// Full f(θ, v) = (θ̇, v̇), size 2nv.
  VecX operator()(const VecX& theta, const VecX& v) {
    retract(model_, q_ref_, theta, q_);
    evaluateConstraints(model_, data_, constraints_, cd_, opt_.time, q_, v);
    if (cd_.singular) throw std::runtime_error("linearize: singular contact geometry at a probe (" +
                                               cd_.singular_reason + ")");
    solver_.solve(model_, data_, constraints_, cd_, q_, v, tau_, result_);
    if (!result_.ok) throw std::runtime_error("linearize: the constrained solver failed at a probe: " +
                                              result_.error);
    localRate(model_, q_ref_, theta, v, thdot_);
    VecX f(2 * model_.nv);
    f << thdot_, result_.vdot;
    return f;
  }

  /// Constraint function (g_holonomic, A v + b), size nh + m.
  VecX constraints(const VecX& theta, const VecX& v) {
    retract(model_, q_ref_, theta, q_);
    evaluateConstraints(model_, data_, constraints_, cd_, opt_.time, q_, v);
    VecX c(nh() + cd_.m);
    for (int k = 0; k < nh(); ++k) c[k] = cd_.gap[holonomic_[k]];
    if (cd_.m > 0) c.tail(cd_.m) = cd_.A * v + cd_.b;
    return c;
  }
  const MatX& A() const { return cd_.A; }

 private:
  const Model& model_;
  const ConstraintList& constraints_;
  ConstrainedSolver& solver_;
  const VecX& q_ref_;
  const LinearizationOptions& opt_;
  Data data_;
  ConstraintData cd_;
  ConstrainedResult result_;
  VecX q_, thdot_, tau_;
  std::vector<int> holonomic_;
};

/// The arguments linearize() accepts; throws naming the one it refuses.
/// Returns the per-velocity flag "cyclic".
std::vector<char> validate(const Model& model, const VecX& q, const VecX& v, const LinearizationOptions& opt) {
  const int nv = model.nv;
  if (q.size() != model.nq || v.size() != nv)
    throw std::invalid_argument("linearize: q must have size nq = " + std::to_string(model.nq) +
                                " and v size nv = " + std::to_string(nv));
  if (!q.allFinite() || !v.allFinite()) throw std::invalid_argument("linearize: q or v is not finite");
  if (opt.tau.size() != 0 && opt.tau.size() != nv)
    throw std::invalid_argument("linearize: tau must be empty or have size nv");
  std::vector<char> is_cyclic(nv, 0);
  for (int c : opt.cyclic) {
    if (c < 0 || c >= nv)
      throw std::invalid_argument("linearize: cyclic index " + std::to_string(c) + " outside 0…" +
                                  std::to_string(nv - 1));
    if (is_cyclic[c]) throw std::invalid_argument("linearize: cyclic index " + std::to_string(c) + " repeated");
    is_cyclic[c] = 1;
  }
  if (!(opt.fd_step > 0) || !(opt.rank_tolerance > 0))
    throw std::invalid_argument("linearize: fd_step and rank_tolerance must be positive");
  return is_cyclic;
}

/// Tangent space of the reduced state x_r = (θ_retained, δv): the null space
/// of ∂(g, A v + b)/∂x_r, by central differences in θ (step h) and A in v.
/// Returns its basis Z (columns), of dimension n − rank.
MatX tangentBasis(Flow& flow, const std::vector<int>& retained, const VecX& v, double h,
                  double rank_tolerance) {
  const int nr = static_cast<int>(retained.size()), nv = static_cast<int>(v.size()), n = nr + nv;
  const VecX theta0 = VecX::Zero(nv);
  const int nc = flow.nh() + flow.m();
  MatX Jc = MatX::Zero(nc, n);
  for (int i = 0; i < nr; ++i) {
    VecX th = theta0;
    th[retained[i]] = h;
    const VecX cp = flow.constraints(th, v);
    th[retained[i]] = -h;
    const VecX cm = flow.constraints(th, v);
    Jc.col(i) = (cp - cm) / (2 * h);
  }
  flow.constraints(theta0, v);
  if (flow.m() > 0) Jc.bottomRightCorner(flow.m(), nv) = flow.A();
  if (nc == 0) return MatX::Identity(n, n);
  int rank = 0;
  Eigen::JacobiSVD<MatX> svd(Jc, Eigen::ComputeFullV);
  const VecX& s = svd.singularValues();
  const double ref = s.size() ? s[0] : 0.0;
  while (rank < s.size() && s[rank] > rank_tolerance * std::max(ref, 1e-300)) ++rank;
  return svd.matrixV().rightCols(n - rank);
}

}  // namespace

LinearizationResult linearize(const Model& model, const ConstraintList& constraints,
                              ConstrainedSolver& solver, const VecX& q, const VecX& v,
                              const LinearizationOptions& opt) {
  const int nv = model.nv;
  const std::vector<char> is_cyclic = validate(model, q, v, opt);
  LinearizationResult out;
  for (int k = 0; k < nv; ++k)
    if (!is_cyclic[k]) out.retained.push_back(k);
  const int nr = static_cast<int>(out.retained.size());
  const int n = nr + nv;  // reduced state size

  Flow flow(model, constraints, solver, q, opt);
  const VecX theta0 = VecX::Zero(nv);
  // Embedding of x_r into (θ, v) and projection of f onto f_r.
  auto expand = [&](const VecX& xr, VecX& th, VecX& vv) {
    th = theta0;
    for (int i = 0; i < nr; ++i) th[out.retained[i]] = xr[i];
    vv = v + xr.tail(nv);
  };
  auto reduce = [&](const VecX& f) {
    VecX fr(n);
    for (int i = 0; i < nr; ++i) fr[i] = f[out.retained[i]];
    fr.tail(nv) = f.tail(nv);
    return fr;
  };

  const VecX f0 = flow(theta0, v);
  out.drift = f0.head(nv);
  out.steady_residual = reduce(f0).lpNorm<Eigen::Infinity>();
  const VecX c0 = flow.constraints(theta0, v);
  out.constraint_residual = c0.size() ? c0.lpNorm<Eigen::Infinity>() : 0.0;

  const double scale = std::max(1.0, v.lpNorm<Eigen::Infinity>());
  const double h = opt.fd_step * scale;

  // Symmetry check: f must not depend on the cyclic coordinates.
  for (int c : opt.cyclic) {
    VecX th = theta0;
    th[c] = h;
    const VecX fp = flow(th, v);
    th[c] = -h;
    const VecX fm = flow(th, v);
    // Only the reduced outputs must be invariant: the cyclic rates themselves
    // may depend on the cyclic coordinates (a planar joint's world-frame
    // rates turn with its heading).
    out.symmetry_residual =
        std::max(out.symmetry_residual, (reduce(fp - fm) / (2 * h)).lpNorm<Eigen::Infinity>());
  }

  const MatX Z = tangentBasis(flow, out.retained, v, h, opt.rank_tolerance);
  out.dimension = static_cast<int>(Z.cols());
  out.basis = Z;

  // L = Zᵀ ∂f_r Z by central differences along each basis vector.
  out.matrix.resize(out.dimension, out.dimension);
  VecX th, vv;
  for (int j = 0; j < out.dimension; ++j) {
    expand(h * Z.col(j), th, vv);
    const VecX fp = reduce(flow(th, vv));
    expand(-h * Z.col(j), th, vv);
    const VecX fm = reduce(flow(th, vv));
    out.matrix.col(j) = Z.transpose() * ((fp - fm) / (2 * h));
  }
  if (out.dimension > 0) {
    Eigen::EigenSolver<MatX> es(out.matrix, false);
    out.eigenvalues = es.eigenvalues();
  }
  return out;
}

int countZeroEigenvalues(const LinearizationResult& result, double tol) {
  int k = 0;
  for (Eigen::Index i = 0; i < result.eigenvalues.size(); ++i)
    if (std::abs(result.eigenvalues[i]) <= tol) ++k;
  return k;
}

}  // namespace appell
