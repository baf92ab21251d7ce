// Articulated-body algorithm: forward dynamics in O(n) (Featherstone 2008, Table 7.1).
// Gravity enters as a fictitious base acceleration −g.
#include <appell/dynamics.hpp>
#include <appell/kinematics.hpp>

#include <Eigen/Cholesky>

namespace appell {

using MatD = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>;

const VecX& aba(const Model& model, Data& data, const VecX& q, const VecX& v, const VecX& tau,
                const BodyForces* fext) {
  forwardKinematics(model, data, q, v);
  for (int i = 0; i < model.nbodies; ++i) {
    const Joint& j = model.joints[i];
    data.c[i] = crossMotion(data.v[i], j.S * v.segment(j.idx_v, j.nv));
    data.IA[i] = model.spatial_inertia[i];
    data.pA[i] = crossForce(data.v[i], model.spatial_inertia[i] * data.v[i]);
    if (fext) data.pA[i] -= (*fext)[i];
  }
  for (int i = model.nbodies - 1; i >= 0; --i) {
    const Joint& j = model.joints[i];
    const int p = model.parent[i];
    if (j.type == JointType::Floating && p < 0) {
      // A free root body (S = 1): U = D = I^A, and nothing passes to a
      // parent, so D⁻¹ is never formed — the forward pass solves with the
      // Cholesky factor of I^A, kept in Dinv's place (a vector solve, not
      // a 6 × 6 inverse and three 6 × 6 products). Without children I^A is
      // the body's own inertia, factorised once in the model.
      if (model.children[i].empty() && model.spatial_inertia_factor[i](0, 0) > 0)
        data.Dinv[i] = model.spatial_inertia_factor[i];
      else
        data.Dinv[i] = Eigen::LLT<Mat6>(data.IA[i]).matrixL();
      data.u[i] = tau.segment<6>(j.idx_v) - data.pA[i];
      continue;
    }
    Mat6 Ia = data.IA[i];
    Vec6 pa = data.pA[i];
    if (j.nv > 0) {
      data.U[i] = data.IA[i] * j.S;
      const MatD D = j.S.transpose() * data.U[i];
      // Most joints have one DoF: a division, not a general factorisation.
      MatD Dinv(j.nv, j.nv);
      if (j.nv == 1) {
        Dinv(0, 0) = 1.0 / D(0, 0);
      } else {
        Dinv = D.llt().solve(MatD::Identity(j.nv, j.nv));
      }
      data.Dinv[i].topLeftCorner(j.nv, j.nv) = Dinv;
      // Two statements on purpose: Eigen evaluates `segment − Sᵀ p` (a
      // dynamic-size segment minus a max-6 product) through a heap temporary.
      data.u[i].head(j.nv) = tau.segment(j.idx_v, j.nv);
      data.u[i].head(j.nv).noalias() -= j.S.transpose() * data.pA[i];
      Ia.noalias() -= data.U[i] * Dinv * data.U[i].transpose();
      pa.noalias() += data.U[i] * (Dinv * data.u[i].head(j.nv));
    }
    if (p >= 0) {
      pa.noalias() += Ia * data.c[i];
      addTransformedInertia(data.liMi[i], Ia, data.IA[p]);
      data.pA[p] += data.liMi[i].actForce(pa);
    }
  }
  for (int i = 0; i < model.nbodies; ++i) {
    const Joint& j = model.joints[i];
    const int p = model.parent[i];
    // a' = X a_parent + c, with the world's acceleration −g (the gravity trick).
    Vec6 a = p >= 0 ? Vec6(data.liMi[i].actInv(data.a[p]))
                    : spatial(Vec3::Zero(), -(data.liMi[i].R.transpose() * model.gravity));
    a += data.c[i];
    if (j.type == JointType::Floating && p < 0) {
      // q̈ = (I^A)⁻¹(u − I^A a) = (I^A)⁻¹u − a, and the body's a + q̈.
      const Mat6& L = data.Dinv[i];
      Vec6 x = data.u[i];
      L.triangularView<Eigen::Lower>().solveInPlace(x);
      L.transpose().triangularView<Eigen::Upper>().solveInPlace(x);
      data.ddq.segment<6>(j.idx_v) = x - a;
      a = x;
    } else if (j.nv > 0) {
      auto qdd = data.ddq.segment(j.idx_v, j.nv);
      qdd = data.Dinv[i].topLeftCorner(j.nv, j.nv) *
            (data.u[i].head(j.nv) - data.U[i].transpose() * a);
      a += j.S * qdd;
    }
    data.a[i] = a;
  }
  // Report accelerations without the fictitious gravity, as forwardKinematics does.
  for (int i = 0; i < model.nbodies; ++i)
    data.a[i] += spatial(Vec3::Zero(), data.oMi[i].R.transpose() * model.gravity);
  return data.ddq;
}

}  // namespace appell
