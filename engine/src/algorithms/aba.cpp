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
      const Mat6 X = data.liMi[i].toInverseMotionMatrix();
      data.IA[p].noalias() += X.transpose() * Ia * X;
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
    if (j.nv > 0) {
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
