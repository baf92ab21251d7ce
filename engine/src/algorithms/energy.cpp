#include <appell/dynamics.hpp>
#include <appell/kinematics.hpp>

namespace appell {

double kineticEnergy(const Model& model, Data& data, const VecX& q, const VecX& v) {
  forwardKinematics(model, data, q, v);
  double T = 0;
  for (int i = 0; i < model.nbodies; ++i)
    T += 0.5 * data.v[i].dot(model.spatial_inertia[i] * data.v[i]);
  return T;
}

double potentialEnergy(const Model& model, Data& data, const VecX& q) {
  forwardKinematics(model, data, q);
  double V = 0;
  for (int i = 0; i < model.nbodies; ++i)
    V -= model.inertias[i].mass * model.gravity.dot(data.oMi[i].apply(model.inertias[i].com));
  return V;
}

Vec6 momentum(const Model& model, Data& data, const VecX& q, const VecX& v) {
  forwardKinematics(model, data, q, v);
  Vec6 h = Vec6::Zero();
  for (int i = 0; i < model.nbodies; ++i)
    h += data.oMi[i].actForce(model.spatial_inertia[i] * data.v[i]);
  return h;
}

}  // namespace appell
