// Per-model workspace: every quantity an algorithm writes, allocated once.
// Algorithms take (const Model&, Data&, inputs…) and never allocate.
#pragma once

#include <appell/model.hpp>

#include <vector>

namespace appell {

struct Data {
  explicit Data(const Model& model);

  // Kinematics (forwardKinematics).
  std::vector<SE3> liMi;   ///< body i in its parent
  std::vector<SE3> oMi;    ///< body i in the world
  std::vector<Vec6> v;     ///< body spatial velocity, body frame
  std::vector<Vec6> a;     ///< body spatial acceleration, body frame (gravity NOT included)

  // Dynamics.
  std::vector<Vec6> f;     ///< RNEA: force transmitted by joint i, body frame
  VecX tau;                ///< RNEA output
  VecX nle;                ///< h(q, v) = C v + g (nonLinearEffects)
  MatX M;                  ///< CRBA output (full symmetric)
  VecX ddq;                ///< ABA output
  std::vector<Mat6> Ic;    ///< CRBA composite inertias

  // Articulated-body workspace (ABA and the tree solvers build on it).
  std::vector<Mat6> IA;    ///< articulated inertia, body frame
  std::vector<Vec6> pA;    ///< articulated bias force, body frame
  std::vector<Vec6> c;     ///< velocity-product acceleration v × S q̇
  std::vector<Mat6X> U;    ///< IA S
  std::vector<Eigen::Matrix<double, 6, 6>> Dinv;  ///< (Sᵀ IA S)⁻¹, top-left nv×nv used
  std::vector<Vec6> u;     ///< τ − Sᵀ pA (first nv used)
};

}  // namespace appell
