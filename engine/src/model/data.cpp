#include <appell/data.hpp>

namespace appell {

Data::Data(const Model& model, MassMatrix mass)
    : liMi(model.nbodies), oMi(model.nbodies), v(model.nbodies, Vec6::Zero()),
      a(model.nbodies, Vec6::Zero()), kinematics_q(VecX::Zero(model.nq)),
      kinematics_v(VecX::Zero(model.nv)), f(model.nbodies, Vec6::Zero()), tau(VecX::Zero(model.nv)),
      nle(VecX::Zero(model.nv)), M(mass == MassMatrix::Sized ? MatX::Zero(model.nv, model.nv) : MatX()), ddq(VecX::Zero(model.nv)),
      Ic(model.nbodies, Mat6::Zero()), IA(model.nbodies, Mat6::Zero()),
      pA(model.nbodies, Vec6::Zero()), c(model.nbodies, Vec6::Zero()),
      U(model.nbodies), Dinv(model.nbodies, Mat6::Zero()), u(model.nbodies, Vec6::Zero()) {
  for (int i = 0; i < model.nbodies; ++i) U[i] = Mat6X::Zero(6, model.joints[i].nv);
}

}  // namespace appell
