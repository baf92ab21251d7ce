// Per-model workspace: every quantity an algorithm writes, allocated once.
// Algorithms take (const Model&, Data&, inputs…) and never allocate.
#pragma once

#include <appell/model.hpp>

#include <vector>

namespace appell {

/// Whether a Data holds the dense nv × nv mass matrix (crba's output). The
/// O(n) algorithms (aba, rnea, the tree solver) never read it; a Data without
/// it costs O(n) memory, so a 10⁵-body model fits.
enum class MassMatrix { Sized, None };

struct Data {
  /// Sizes every buffer once; M (nv × nv) only with MassMatrix::Sized — a
  /// crba() on a Data without it sizes M on that first call.
  explicit Data(const Model& model, MassMatrix mass = MassMatrix::Sized);

  // Kinematics (forwardKinematics).
  std::vector<SE3> liMi;   ///< body i in its parent
  std::vector<SE3> oMi;    ///< body i in the world
  std::vector<Vec6> v;     ///< body spatial velocity, body frame
  std::vector<Vec6> a;     ///< body spatial acceleration, body frame (gravity NOT included)
  /// The (q, v) the kinematics above were last computed for: forwardKinematics
  /// writes them (kinematics_has_v false after the position-only one), so an
  /// algorithm handed the same (q, v) skips recomputing them
  /// (forwardKinematicsIfStale). Writing liMi, oMi or v by hand: clear
  /// kinematics_has_v.
  VecX kinematics_q, kinematics_v;
  bool kinematics_has_v = false;

  // Dynamics.
  std::vector<Vec6> f;     ///< RNEA: force transmitted by joint i, body frame
  VecX tau;                ///< RNEA output
  VecX nle;                ///< h(q, v) = C v + g (nonLinearEffects)
  MatX M;                  ///< CRBA output (full symmetric); empty with MassMatrix::None
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
