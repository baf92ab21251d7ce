// Recursive Newton–Euler: inverse dynamics (Featherstone 2008, Table 5.1).
#include <appell/dynamics.hpp>
#include <appell/kinematics.hpp>

namespace appell {

namespace {

/// Gravity as a spatial acceleration in body i's frame.
Vec6 gravityIn(const Model& model, const Data& data, int i) {
  return spatial(Vec3::Zero(), data.oMi[i].R.transpose() * model.gravity);
}

}  // namespace

const VecX& rnea(const Model& model, Data& data, const VecX& q, const VecX& v, const VecX& a,
                 const BodyForces* fext) {
  forwardKinematics(model, data, q, v, a);
  for (int i = 0; i < model.nbodies; ++i) {
    const Mat6& I = model.spatial_inertia[i];
    const Vec6 Iv = I * data.v[i];
    data.f[i] = I * (data.a[i] - gravityIn(model, data, i)) + crossForce(data.v[i], Iv);
    if (fext) data.f[i] -= (*fext)[i];
  }
  for (int i = model.nbodies - 1; i >= 0; --i) {
    const Joint& j = model.joints[i];
    data.tau.segment(j.idx_v, j.nv) = j.S.transpose() * data.f[i];
    if (model.parent[i] >= 0) data.f[model.parent[i]] += data.liMi[i].actForce(data.f[i]);
  }
  return data.tau;
}

const VecX& nonLinearEffects(const Model& model, Data& data, const VecX& q, const VecX& v) {
  // h = RNEA(q, v, 0); data.ddq is free scratch here (zeroed) and restored as zero.
  data.ddq.setZero();
  data.nle = rnea(model, data, q, v, data.ddq);
  return data.nle;
}

}  // namespace appell
