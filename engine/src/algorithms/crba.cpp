// Composite-rigid-body algorithm: the joint-space mass matrix (Featherstone 2008, Table 6.2).
#include <appell/dynamics.hpp>
#include <appell/kinematics.hpp>

namespace appell {

const MatX& crba(const Model& model, Data& data, const VecX& q) {
  forwardKinematics(model, data, q);
  if (data.M.rows() != model.nv) data.M.setZero(model.nv, model.nv);  // a Data built with MassMatrix::None
  for (int i = 0; i < model.nbodies; ++i) data.Ic[i] = model.spatial_inertia[i];
  for (int i = model.nbodies - 1; i >= 0; --i) {
    const int p = model.parent[i];
    if (p >= 0) addTransformedInertia(data.liMi[i], data.Ic[i], data.Ic[p]);
  }
  for (int i = 0; i < model.nbodies; ++i) {
    const Joint& ji = model.joints[i];
    if (ji.nv == 0) continue;
    Mat6X F = data.Ic[i] * ji.S;  // force columns, body i frame
    data.M.block(ji.idx_v, ji.idx_v, ji.nv, ji.nv) = ji.S.transpose() * F;
    for (int k = i; model.parent[k] >= 0;) {
      for (int c = 0; c < ji.nv; ++c) F.col(c) = data.liMi[k].actForce(F.col(c));
      k = model.parent[k];
      const Joint& jk = model.joints[k];
      if (jk.nv == 0) continue;
      auto block = data.M.block(jk.idx_v, ji.idx_v, jk.nv, ji.nv);
      block = jk.S.transpose() * F;
      data.M.block(ji.idx_v, jk.idx_v, ji.nv, jk.nv) = block.transpose();
    }
  }
  return data.M;
}

}  // namespace appell
