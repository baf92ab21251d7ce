// The dense solvers and the simulator with the contacts module's rows: a
// four-wheeled car (chassis on a free joint, four spherical wheels on axles,
// rolling contacts on the ground). Its rows are redundant — the four normal
// rows of a rigid chassis have rank 3, the four lateral no-slip rows rank 2 —
// so rank 9 of 12, one DoF left (rolling straight). Checks: KKT and Appell
// agree (v̇, Aᵀλ, minimum-norm λ) with 3 redundant rows; at rest the normal
// reactions carry the weight with the right moments; coasting keeps speed
// and heading; rear-wheel torque τ gives a = 2τ/r / (m + 4 I_w/r²).
#include <appell/appell_maggi.hpp>
#include <appell/contacts.hpp>
#include <appell/kkt.hpp>
#include <appell/simulator.hpp>

#include "random_tree.hpp"

#include <gtest/gtest.h>

namespace appell {
namespace {

struct Car {
  Model model;
  ConstraintList constraints;
  double r = 0.3, m_chassis = 10, m_wheel = 1, half_length = 1.0, half_width = 0.6;
  double Iw() const { return 0.4 * m_wheel * r * r; }
  double mass() const { return m_chassis + 4 * m_wheel; }
  Vec3 com{0.15, 0.05, 0.1};
  std::vector<int> wheels;
  VecX q0, v0;
};

Car makeCar(double speed) {
  Car c;
  ModelBuilder b;
  const int chassis = b.addBody("chassis", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(),
                                Inertia{c.m_chassis, c.com, Vec3(1.0, 2.0, 2.5).asDiagonal()},
                                "free");
  const Vec3 corners[4] = {{c.half_length, c.half_width, 0}, {c.half_length, -c.half_width, 0},
                           {-c.half_length, c.half_width, 0}, {-c.half_length, -c.half_width, 0}};
  for (int k = 0; k < 4; ++k) {
    SE3 X;
    X.p = corners[k];
    c.wheels.push_back(b.addBody("wheel" + std::to_string(k), chassis, X, JointType::Continuous,
                                 Vec3::UnitY(),
                                 Inertia{c.m_wheel, Vec3::Zero(), Vec3::Constant(c.Iw()).asDiagonal()},
                                 "axle" + std::to_string(k)));
  }
  c.model = b.build();
  Support ground{Plane{}, StaticMotion{}, "ground", -1};
  for (int k = 0; k < 4; ++k) {
    ContactOptions o;
    o.name = "tyre" + std::to_string(k);
    c.constraints.push_back(makeContact(ContactKind::Rolling, c.wheels[k], Sphere{c.r, Vec3::Zero()},
                                        ground, o));
  }
  c.q0 = neutralConfiguration(c.model);
  c.q0[2] = c.r;
  c.v0 = VecX::Zero(c.model.nv);
  c.v0[3] = speed;  // chassis forward velocity (body frame)
  for (int k = 0; k < 4; ++k) c.v0[6 + k] = speed / c.r;
  return c;
}

TEST(SolverContacts, FourWheeledCarHasThreeRedundantRowsAndAgrees) {
  Car car = makeCar(1.0);
  Data data(car.model);
  ConstraintData cd(car.model, car.constraints);
  KktSolver kkt(car.model, car.constraints);
  AppellSolver orth(car.model, car.constraints);
  AppellSolver part(car.model, car.constraints, {}, {NullSpace::CoordinatePartition});
  std::mt19937 rng(4);
  for (int s = 0; s < 50; ++s) {
    VecX q = car.q0;
    q[0] = test::randomVector(1, rng)[0];
    q.segment<4>(3) = Eigen::Vector4d(0, 0, std::sin(0.5 * s), std::cos(0.5 * s));  // any heading
    for (int k = 0; k < 4; ++k) q[7 + k] = test::randomVector(1, rng, 3.0)[0];
    VecX v = (s == 0) ? car.v0 : test::randomVector(car.model.nv, rng);
    const VecX tau = test::randomVector(car.model.nv, rng);
    // An admissible velocity: off the constraint set the velocity products of
    // the duplicated rows differ (a yawing car would need its two front tyres
    // to slip differently), and the solvers rightly call that inconsistent.
    evaluateConstraints(car.model, data, car.constraints, cd, 0, q, v);
    if (s > 0) {
      ConstrainedResult bad;
      kkt.solve(car.model, data, car.constraints, cd, q, v, tau, bad);
      EXPECT_FALSE(bad.ok);
      EXPECT_NE(bad.error.find("tyre"), std::string::npos);
      VecX mu;
      ASSERT_TRUE(kkt.projectVelocity(car.model, data, car.constraints, cd, q, v, mu));
    }
    evaluateConstraints(car.model, data, car.constraints, cd, 0, q, v);
    ASSERT_FALSE(cd.singular) << cd.singular_reason;
    ConstrainedResult rk, ro, rp;
    kkt.solve(car.model, data, car.constraints, cd, q, v, tau, rk);
    orth.solve(car.model, data, car.constraints, cd, q, v, tau, ro);
    part.solve(car.model, data, car.constraints, cd, q, v, tau, rp);
    ASSERT_TRUE(rk.ok && ro.ok && rp.ok) << rk.error << ro.error << rp.error;
    EXPECT_EQ(rk.rank, 9);
    EXPECT_EQ(rk.redundant, 3);
    EXPECT_EQ(ro.redundant, 3);
    EXPECT_EQ(rp.redundant, 3);
    for (const ConstrainedResult* r : {&ro, &rp}) {
      EXPECT_LT((r->vdot - rk.vdot).norm(), 1e-10 * (1 + rk.vdot.norm()));
      EXPECT_LT((r->reaction - rk.reaction).norm(), 1e-10 * (1 + rk.reaction.norm()));
      EXPECT_LT((r->lambda - rk.lambda).norm(), 1e-10 * (1 + rk.lambda.norm()));
    }
  }
}

TEST(SolverContacts, CarAtRestCarriesItsWeight) {
  Car car = makeCar(0.0);
  Data data(car.model);
  ConstraintData cd(car.model, car.constraints);
  KktSolver kkt(car.model, car.constraints);
  const VecX tau = VecX::Zero(car.model.nv);
  evaluateConstraints(car.model, data, car.constraints, cd, 0, car.q0, car.v0);
  ConstrainedResult r;
  kkt.solve(car.model, data, car.constraints, cd, car.q0, car.v0, tau, r);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_LT(r.vdot.norm(), 1e-12);
  // Resultant of the contact forces = −gravity on the whole car; moments about
  // the origin balance the weight acting at the centre of mass.
  Vec3 F = Vec3::Zero(), N = Vec3::Zero();
  for (size_t k = 0; k < car.constraints.size(); ++k) {
    const RowBlock& blk = cd.blocks[k];
    for (int i = 0; i < blk.m; ++i) {
      const double l = r.lambda[cd.offset[k] + i];
      N += l * blk.Wa.row(i).head<3>().transpose();
      F += l * blk.Wa.row(i).tail<3>().transpose();
    }
  }
  const double W = car.mass() * 9.81;
  const Vec3 c_total = car.m_chassis * car.com / car.mass();  // wheels centred on the corners (sum 0)
  EXPECT_NEAR(F.z(), W, 1e-9 * W);
  EXPECT_NEAR(F.x(), 0.0, 1e-9 * W);
  EXPECT_NEAR(F.y(), 0.0, 1e-9 * W);
  EXPECT_NEAR(N.x(), W * c_total.y(), 1e-9 * W);
  EXPECT_NEAR(N.y(), -W * c_total.x(), 1e-9 * W);
  // Statically indeterminate: λ is the least-norm split, no tangential forces.
  for (int k = 0; k < 4; ++k) {
    EXPECT_NEAR(r.lambda[3 * k], 0.0, 1e-9 * W);
    EXPECT_NEAR(r.lambda[3 * k + 1], 0.0, 1e-9 * W);
  }
}

TEST(SolverContacts, CarCoastsStraightAndAcceleratesUnderWheelTorque) {
  for (int which = 0; which < 2; ++which) {
    Car car = makeCar(2.0);
    std::unique_ptr<ConstrainedSolver> solver;
    if (which == 0) solver = std::make_unique<KktSolver>(car.model, car.constraints);
    else solver = std::make_unique<AppellSolver>(car.model, car.constraints);
    IntegratorOptions io;
    io.rtol = io.atol = 1e-11;
    Simulator sim(car.model, car.constraints, std::move(solver), IntegratorType::DormandPrince54, io);
    sim.setState(0, car.q0, car.v0);
    const double E0 = sim.energy();
    ASSERT_TRUE(sim.advanceTo(2.0, 1e-2).ok);
    EXPECT_NEAR(sim.q()[0], 4.0, 1e-9);
    EXPECT_NEAR(sim.q()[1], 0.0, 1e-9);
    EXPECT_NEAR(sim.v()[3], 2.0, 1e-9);
    EXPECT_NEAR(sim.energy(), E0, 1e-9 * E0);
    EXPECT_EQ(sim.redundantRows(), 3);
    EXPECT_LT(sim.velocityResidual(), 1e-10);
    // Rear-wheel drive: each rear axle motor applies τ (and −τ on the chassis).
    const double torque = 0.5;
    sim.setJointForces([&](double, const VecX&, const VecX&, VecX& tau) {
      tau[6 + 2] = torque;
      tau[6 + 3] = torque;
    });
    const double x0 = sim.q()[0], t0 = sim.time();
    ASSERT_TRUE(sim.advanceTo(t0 + 1.0, 1e-2).ok);
    const double a = 2 * torque / car.r / (car.mass() + 4 * car.Iw() / (car.r * car.r));
    EXPECT_NEAR(sim.v()[3], 2.0 + a, 1e-9);
    EXPECT_NEAR(sim.q()[0], x0 + 2.0 + 0.5 * a, 1e-9);
    EXPECT_NEAR(sim.dynamics().vdot[3], a, 1e-9);
  }
}

}  // namespace
}  // namespace appell
