// Embeds appell through the installed package: a two-body pendulum, forward
// dynamics by ABA, checked against the mass-matrix formulation M⁻¹(τ − h)
// and against the constrained solver (no rows) built by makeSolver — both
// reached through the one include <appell/appell.hpp>.
#include <appell/appell.hpp>

#include <Eigen/Cholesky>

#include <cmath>
#include <cstdio>

int main() {
  using namespace appell;
  ModelBuilder b;
  // Point-like bobs (tiny rotational inertia) on massless rods along −z.
  const Inertia bob{1.0, Vec3(0, 0, -1.0), 1e-6 * Mat3::Identity()};
  const int upper = b.addBody("upper", -1, SE3::Identity(), JointType::Revolute, Vec3::UnitY(), bob);
  SE3 elbow;
  elbow.p = Vec3(0, 0, -1.0);
  b.addBody("lower", upper, elbow, JointType::Revolute, Vec3::UnitY(), bob);
  const Model model = b.build();
  Data data(model);

  VecX q(2), v(2), tau = VecX::Zero(2);
  q << 0.4, -0.3;
  v << 0.5, 1.0;
  const VecX ddq = aba(model, data, q, v, tau);
  const MatX M = crba(model, data, q);
  const VecX h = nonLinearEffects(model, data, q, v);
  const VecX ddq_ref = M.ldlt().solve(tau - h);
  const double err = (ddq - ddq_ref).norm() / ddq_ref.norm();
  const ConstraintList none;
  ConstraintData cdata(model, none);
  evaluateConstraints(model, data, none, cdata, 0.0, q, v);
  ConstrainedResult res;
  makeSolver(Formulation::Tree, model, none)->solve(model, data, none, cdata, q, v, tau, res);
  const double err_tree = (res.vdot - ddq_ref).norm() / ddq_ref.norm();
  std::printf("appell consumer: nq=%d nv=%d  ddq = (%.12f, %.12f)  |ABA - CRBA^-1(tau-h)|/|.| = %.2e"
              "  |tree - CRBA^-1(tau-h)|/|.| = %.2e\n",
              model.nq, model.nv, ddq[0], ddq[1], err, err_tree);
  return err < 1e-12 && err_tree < 1e-12 && ddq.allFinite() && res.ok ? 0 : 1;
}
