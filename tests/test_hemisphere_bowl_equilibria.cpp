// Emelyanova & Fufaev (1978; docs/equilibria.md), example 2: a heavy hemisphere rolling
// without slipping inside a spherical bowl. The equilibria form the
// 3-dimensional manifold  ψ = ψ₁,  l₁ sin θ = R sin θ₁  (centre of mass above
// the contact point; tilted states are held by the no-slip reaction).
//
// Zero eigenvalues of the linearization at an equilibrium, derived:
// the state space on the constraint manifold has dimension 2·5 − 2 = 8
// (5 positions: the gap removes one of six; 3 admissible velocities D = the
// rotations about the contact point). With no velocity-dependent forces,
// ∂v̇/∂v = 0 at v = 0, so L = [[0, T], [K, 0]] (T: velocities → position
// rates, injective; K: positions → accelerations, which vanishes on the
// tangent E of the equilibrium manifold, dim E = 3). Hence
//   ker L = E × {0}:  geometric multiplicity of 0 is exactly 3;
//   (0, δv) with T δv ∈ E is mapped into ker L: a Jordan chain of length 2
//   for each direction of D ∩ E, and dim(D ∩ E) ≥ 3 + 3 − 5 = 1 (generically 1:
//   at the bottom it is the pivot spin about the vertical).
// So nullity(L) = 3, nullity(L²) = nullity(L³) = 4: the eigenvalue 0 has
// algebraic multiplicity 4, and the other 4 eigenvalues come in pairs ±μ
// (L is similar to −L: the system is reversible).
#include <gtest/gtest.h>

#include <appell/equilibria.hpp>
#include <appell/kkt.hpp>
#include <appell/linearization.hpp>

#include "hemisphere_bowl.hpp"

#include <Eigen/SVD>

#include <numbers>

using namespace appell;
using namespace appell::scenes;

namespace {

double angleDiff(double a, double b) { return std::remainder(a - b, 2 * std::numbers::pi); }

int nullity(const MatX& M, double tol) {
  Eigen::JacobiSVD<MatX> svd(M);
  const VecX& s = svd.singularValues();
  int r = 0;
  while (r < s.size() && s[r] > tol * s[0]) ++r;
  return static_cast<int>(M.cols()) - r;
}

struct Guess {
  double polar, azimuth, tilt, tilt_azimuth, spin;
};

}  // namespace

TEST(HemisphereBowl, FinderRecoversTheThreeDimensionalManifold) {
  HemisphereBowlParams base;
  const double R = base.radius, l1 = hemisphereComDistance(base), mg = base.mass * 9.81;
  // Guesses away from the manifold: wrong tilt, wrong azimuth, or both.
  const std::vector<Guess> guesses = {{0.2, 0.4, 0.0, 0.4, 0.0},   {0.35, -1.2, 0.9, -0.6, 1.0},
                                      {0.1, 2.5, 0.5, 2.0, -2.0},  {0.5, 1.0, 0.2, 1.5, 0.3},
                                      {0.05, -2.8, 0.3, 3.0, 0.7}, {0.25, 0.0, 0.6, -0.3, 2.5}};
  for (const Guess& g : guesses) {
    HemisphereBowlParams p = base;
    p.contact_polar = g.polar;
    p.contact_azimuth = g.azimuth;
    p.tilt = g.tilt;
    p.tilt_azimuth = g.tilt_azimuth;
    p.spin = g.spin;
    const BuiltScene s = hemisphereInBowl(p);
    const EquilibriumResult r = findEquilibrium(s.model, s.constraints, s.q0);
    ASSERT_TRUE(r.converged) << r.message;
    const HemisphereAngles a = hemisphereAngles(p, r.q);
    // The paper's relations.
    EXPECT_NEAR(l1 * std::sin(a.tilt), R * std::sin(a.contact_polar), 1e-10);
    if (a.contact_polar > 1e-3) {
      EXPECT_NEAR(angleDiff(a.tilt_azimuth, a.contact_azimuth), 0.0, 1e-8);
    }
    EXPECT_GT(a.contact_polar, 1e-3) << "collapsed to the bottom rather than the nearest point";
    // Centre of mass above the contact point, and the reaction carries the weight.
    Data data(s.model);
    ConstraintData cd(s.model, s.constraints);
    evaluateConstraints(s.model, data, s.constraints, cd, 0, r.q, VecX::Zero(6));
    const ContactFrame& fr = cd.blocks[0].frame;
    const Vec3 G = r.q.head<3>() + floatingRotation(r.q, 0) * Vec3(0, 0, -l1);
    EXPECT_LT((G - fr.point).head<2>().norm(), 1e-10);
    const Vec3 F = r.lambda[0] * fr.t1 + r.lambda[1] * fr.t2 + r.lambda[2] * fr.normal;
    EXPECT_LT((F - Vec3(0, 0, mg)).norm(), 1e-9 * mg);
    // Tilted states are held by the no-slip rows: a tangential reaction.
    EXPECT_GT(std::hypot(r.lambda[0], r.lambda[1]), 1e-3 * mg);
    EXPECT_EQ(r.manifold_dimension, 3);
    EXPECT_EQ(r.tangent.cols(), 3);
  }
}

TEST(HemisphereBowl, LinearizationHasExactlyTheZeroEigenvaluesOfTheManifold) {
  for (double polar : {0.0, 0.15, 0.35}) {  // θ₁ ≤ asin(l₁/R) ≈ 0.384 for equilibria
    HemisphereBowlParams p;
    p.contact_polar = polar;
    p.contact_azimuth = 0.7;
    const BuiltScene s = hemisphereInBowl(p);  // on the manifold by construction
    const EquilibriumResult eq = findEquilibrium(s.model, s.constraints, s.q0);
    ASSERT_TRUE(eq.converged) << eq.message;
    KktSolver solver(s.model, s.constraints);
    const LinearizationResult lin = linearize(s.model, s.constraints, solver, eq.q, VecX::Zero(6));
    EXPECT_LT(lin.steady_residual, 1e-10);
    ASSERT_EQ(lin.dimension, 8);
    const MatX& L = lin.matrix;
    EXPECT_EQ(nullity(L, 1e-6), 3) << "polar " << polar << "\n" << lin.eigenvalues.transpose();
    EXPECT_EQ(nullity(L * L, 1e-6), 4) << "polar " << polar;
    EXPECT_EQ(nullity(L * L * L, 1e-6), 4) << "polar " << polar;
    // Four eigenvalues at 0 (a Jordan block of size 2 spreads to ±√ε under
    // finite-difference error ε ≈ 1e-10, hence the looser count tolerance);
    // the other four are away from zero and pair as ±μ.
    EXPECT_EQ(countZeroEigenvalues(lin, 1e-3), 4) << lin.eigenvalues.transpose();
    std::vector<std::complex<double>> nonzero;
    for (Eigen::Index i = 0; i < lin.eigenvalues.size(); ++i)
      if (std::abs(lin.eigenvalues[i]) > 1e-3) nonzero.push_back(lin.eigenvalues[i]);
    ASSERT_EQ(nonzero.size(), 4u);
    for (const auto& mu : nonzero) {
      double best = 1e300;
      for (const auto& nu : nonzero) best = std::min(best, std::abs(mu + nu));
      EXPECT_LT(best, 1e-5 * std::abs(mu)) << "no partner −μ for μ = " << mu;
    }
  }
}
