// The dense references declared in dense_reference.hpp.
#include "dense_reference.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>

namespace appell::test {

VecX pinvSolve(const MatX& A, const VecX& b, double rel) {
  Eigen::JacobiSVD<MatX> svd(A, Eigen::ComputeThinU | Eigen::ComputeThinV);
  svd.setThreshold(rel);
  return svd.solve(b);
}

Reference denseReference(const Model& model, const ConstraintData& cd, const VecX& q, const VecX& v,
                         const VecX& tau) {
  using ML = Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic>;
  using VL = Eigen::Matrix<long double, Eigen::Dynamic, 1>;
  Data data(model);
  const MatX M = crba(model, data, q);
  const VecX h = nonLinearEffects(model, data, q, v);
  const ML Ml = M.cast<long double>();
  const VL rhs = (tau - h).cast<long double>();
  Eigen::SelfAdjointEigenSolver<ML> es(Ml);
  const ML Mih = es.operatorInverseSqrt();
  const VL a = Ml.ldlt().solve(rhs);
  Reference r;
  if (cd.m == 0) {
    r.vdot = a.cast<double>();
    r.lambda = VecX::Zero(0);
    r.reaction = VecX::Zero(model.nv);
    return r;
  }
  const ML A = cd.A.cast<long double>();
  // Pseudo-inverse solves truncated at σ ≤ max(1e-10 σ₀, 1e-14): the
  // absolute floor keeps round-off residue (a row the joints cannot move,
  // ~1e-17) from becoming a constraint, which a purely relative threshold
  // does when every row is such residue.
  int rank = 0;
  auto solve = [&rank](const ML& B, const VL& y) {
    Eigen::JacobiSVD<ML> svd(B, Eigen::ComputeThinU | Eigen::ComputeThinV);
    const auto& sv = svd.singularValues();
    rank = 0;
    while (rank < sv.size() && sv(rank) > std::max(1e-10L * sv(0), 1e-14L)) ++rank;
    const VL z = (svd.matrixU().leftCols(rank).transpose() * y).cwiseQuotient(sv.head(rank));
    return VL(svd.matrixV().leftCols(rank) * z);
  };
  const VL vd = a + Mih * solve(A * Mih, VL(-cd.abias.cast<long double>() - A * a));
  const VL reaction = Ml * (vd - a);
  r.vdot = vd.cast<double>();
  r.reaction = reaction.cast<double>();
  r.lambda = solve(A.transpose(), reaction).cast<double>();
  r.rank = rank;
  return r;
}

VecX denseProjection(const Model& model, const ConstraintData& cd, const VecX& q, const VecX& v) {
  if (cd.m == 0) return v;
  Data data(model);
  const MatX M = crba(model, data, q);
  Eigen::SelfAdjointEigenSolver<MatX> es(M);
  const MatX Mih = es.operatorInverseSqrt();
  return v + Mih * pinvSolve(cd.A * Mih, -cd.b - cd.A * v);
}

}  // namespace appell::test
