// The contact rows in motion: a small dense KKT solve (M v̇ + h = Aᵀλ,
// A v̇ + Ȧv + ḃ = 0) integrated with Runge–Kutta–Munthe-Kaas RK4, no
// projection. If a κ term were wrong the constraints would drift and the
// reactions would do work; these tests see that:
//   - a ball on a turntable: its centre's velocity turns at 2Ω/7 (solid ball);
//   - passive rolling (ellipsoid, disk, torus on a tilted plane; hemisphere in
//     a bowl; a ball on a globe; a rubber-rolling ball): energy is conserved
//     and the rows stay satisfied.
#include "test_contact_common.hpp"

#include <appell/appell.hpp>
#include <appell/constraint_set.hpp>

#include <gtest/gtest.h>

using namespace appell;
using namespace appell::testing;

namespace {

struct Sim {
  const Model& model;
  ConstraintList list;
  Data data;
  ConstraintData cd;
  Sim(const Model& m, ConstraintList l) : model(m), list(std::move(l)), data(m), cd(m, list) {}

  // v̇ from the KKT system; fails the test on singular geometry.
  VecX acceleration(double t, const VecX& q, const VecX& v) {
    evaluateConstraints(model, data, list, cd, t, q, v);
    EXPECT_FALSE(cd.singular) << cd.singular_reason;
    const MatX M = crba(model, data, q);
    const VecX h = nonLinearEffects(model, data, q, v);
    const int n = model.nv, m = cd.m;
    MatX K = MatX::Zero(n + m, n + m);
    K.topLeftCorner(n, n) = M;
    K.topRightCorner(n, m) = cd.A.transpose();
    K.bottomLeftCorner(m, n) = cd.A;
    VecX rhs(n + m);
    rhs << -h, -cd.abias;
    return Eigen::ColPivHouseholderQR<MatX>(K).solve(rhs).head(n);
  }

  // One RKMK4 step in local coordinates about q.
  void step(double& t, VecX& q, VecX& v, double dt) {
    const int n = model.nv;
    VecX th = VecX::Zero(n), qs(model.nq), kq[4], kv[4];
    const double c[4] = {0, 0.5, 0.5, 1};
    for (int s = 0; s < 4; ++s) {
      const VecX ths = s == 0 ? th : VecX(th + c[s] * dt * kq[s - 1]);
      const VecX vs = s == 0 ? v : VecX(v + c[s] * dt * kv[s - 1]);
      retract(model, q, ths, qs);
      kq[s].resize(n);
      localRate(model, q, ths, vs, kq[s]);
      kv[s] = acceleration(t + c[s] * dt, qs, vs);
    }
    th = dt / 6 * (kq[0] + 2 * kq[1] + 2 * kq[2] + kq[3]);
    v += dt / 6 * (kv[0] + 2 * kv[1] + 2 * kv[2] + kv[3]);
    VecX q1(model.nq);
    retract(model, q, th, q1);
    q = q1;
    t += dt;
  }

  double energy(const VecX& q, const VecX& v) {
    return kineticEnergy(model, data, q, v) + potentialEnergy(model, data, q);
  }
  // ‖A v + b‖∞ and max |gap| at (q, v, t).
  std::pair<double, double> residuals(double t, const VecX& q, const VecX& v) {
    evaluateConstraints(model, data, list, cd, t, q, v);
    return {velocityResidual(data, list, cd, v), gapResidual(cd)};
  }
};

Model singleBody(const Inertia& inertia) {
  ModelBuilder b;
  b.addBody("body", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(), inertia);
  return b.build();
}

// Floating-joint state from a world pose and world spatial velocity [ω; v_O].
void floatingState(const SE3& pose, const Vec6& V, VecX& q, VecX& v) {
  const Quat r(pose.R);
  q.resize(7);
  q << pose.p, r.x(), r.y(), r.z(), r.w();
  const Vec3 w = V.head<3>(), pdot = V.tail<3>() + w.cross(pose.p);
  v.resize(6);
  v << pose.R.transpose() * w, pose.R.transpose() * pdot;
}

}  // namespace

TEST(ContactPhysics, BallOnTurntableOrbitsAtTwoSeventhsOfTheTableRate) {
  const double r = 0.1, mass = 1.0, Omega = 3.0;
  const Model model = singleBody({mass, Vec3::Zero(), Mat3::Identity() * 0.4 * mass * r * r});
  const Support table{Plane{}, turntable(Vec3::Zero(), Vec3::UnitZ(), Omega), "table"};
  Sim sim(model, {makeContact(ContactKind::Rolling, 0, Sphere{r, Vec3::Zero()}, table)});
  // Rolling start: v_c + ω × (−r z) = Ω z × x.
  SE3 pose;
  pose.p = Vec3(0.3, 0.0, r);
  const Vec3 vc0(0.1, 0.2, 0), vt = Omega * Vec3::UnitZ().cross(Vec3(0.3, 0, 0));
  const Vec3 w0 = Vec3::UnitZ().cross(vc0 - vt) / r + Vec3(0, 0, 1.5);
  Vec6 V;
  V << w0, vc0 - w0.cross(pose.p);
  VecX q, v;
  floatingState(pose, V, q, v);
  double t = 0;
  const double dt = 1e-3, T = 2.0;
  for (int k = 0; k < static_cast<int>(T / dt + 0.5); ++k) sim.step(t, q, v, dt);
  const Mat3 R = Quat(q[6], q[3], q[4], q[5]).toRotationMatrix();
  const Vec3 vc = R * v.tail<3>();
  const Vec3 expected = axisAngle(Vec3::UnitZ(), 2.0 * Omega * T / 7.0) * vc0;
  EXPECT_LT((vc - expected).norm(), 1e-9) << vc.transpose() << " vs " << expected.transpose();
  // No projection here: what remains is the integrator's truncation error.
  EXPECT_NEAR(q[2], r, 1e-8);
  const auto [rv, rg] = sim.residuals(t, q, v);
  EXPECT_LT(rv, 1e-8);
  EXPECT_LT(rg, 1e-8);
}

namespace {

struct PassiveCase {
  std::string name;
  ContactKind kind;
  Shape shape;
  Support support;
  Inertia inertia;
  SE3 pose;       ///< world pose, before being put into contact
  Vec3 omega;     ///< world angular velocity at start
};

}  // namespace

TEST(ContactPhysics, PassiveRollingConservesEnergyAndKeepsTheConstraints) {
  const Vec3 tiltn = Vec3(0.15, -0.1, 1).normalized();
  const Support slope{Plane{Vec3::Zero(), tiltn}, StaticMotion{}, "slope"};
  const Support bowl{SphereSurface{Vec3(0, 0, 1.0), 1.0, SphereSurface::Side::Inside},
                     StaticMotion{}, "bowl"};
  const Support globe{SphereSurface{Vec3(0, 0, -1.0), 1.0, SphereSurface::Side::Outside},
                      StaticMotion{}, "globe"};
  const double m = 1.3;
  auto ellipsoidInertia = [&](const Vec3& s) {
    return Inertia{m, Vec3::Zero(),
                   Vec3(s[1] * s[1] + s[2] * s[2], s[0] * s[0] + s[2] * s[2],
                        s[0] * s[0] + s[1] * s[1])
                           .asDiagonal() *
                       (m / 5)};
  };
  SE3 upright;  // wheels: axle along y, slightly leaning
  upright.R = axisAngle(Vec3::UnitX(), 0.25);
  SE3 tilted;
  tilted.R = axisAngle(Vec3(1, 1, 0).normalized(), 0.5);
  SE3 leaning;  // hemisphere, pole down, tilted by 0.3
  leaning.R = axisAngle(Vec3::UnitY(), 0.3);
  leaning.p = Vec3(0.2, 0.1, 0.5);
  const std::vector<PassiveCase> cases{
      {"ellipsoid on a slope", ContactKind::Rolling,
       Ellipsoid{Vec3(0.3, 0.2, 0.12), Vec3::Zero(), Mat3::Identity()}, slope,
       ellipsoidInertia(Vec3(0.3, 0.2, 0.12)), tilted, Vec3(1.0, -2.0, 3.0)},
      {"disk on a slope", ContactKind::Rolling, Disk{0.3, Vec3::Zero(), Vec3::UnitY()}, slope,
       Inertia{m, Vec3::Zero(), Vec3(0.25, 0.5, 0.25).asDiagonal() * (m * 0.09)}, upright,
       upright.R * Vec3(0.0, 8.0, 1.0)},
      {"torus on a slope", ContactKind::Rolling, Torus{0.25, 0.05, Vec3::Zero(), Vec3::UnitY()},
       slope, Inertia{m, Vec3::Zero(), Vec3(0.3, 0.55, 0.3).asDiagonal() * (m * 0.09)}, upright,
       upright.R * Vec3(0.5, 7.0, -1.0)},
      {"knife-edge disk on a slope", ContactKind::KnifeEdge,
       Disk{0.3, Vec3::Zero(), Vec3::UnitY()}, slope,
       Inertia{m, Vec3::Zero(), Vec3(0.25, 0.5, 0.25).asDiagonal() * (m * 0.09)}, upright,
       upright.R * Vec3(0.0, 6.0, 1.0)},
      {"hemisphere in a bowl", ContactKind::Rolling,
       SphericalCap{0.3, Vec3::Zero(), -Vec3::UnitZ(), M_PI / 2}, bowl,
       Inertia{m, Vec3(0, 0, -0.3 * 3 / 8), Vec3(0.83, 0.83, 0.4).asDiagonal() * (m * 0.09)},
       leaning, Vec3(0.5, -0.3, 2.0)},
      {"ellipsoid in a bowl", ContactKind::Rolling,
       Ellipsoid{Vec3(0.25, 0.2, 0.15), Vec3::Zero(), Mat3::Identity()}, bowl,
       ellipsoidInertia(Vec3(0.25, 0.2, 0.15)), tilted, Vec3(0.4, 0.3, 1.0)},
      {"rubber ball on a globe", ContactKind::RollingWithoutSpin,
       Sphere{0.2, Vec3(0.02, 0, 0)}, globe,
       Inertia{m, Vec3::Zero(), Vec3(0.4, 0.45, 0.5).asDiagonal() * (m * 0.04)}, tilted,
       Vec3(0.7, 0.2, 0.0)},
  };
  for (const auto& pc : cases) {
    const Model model = singleBody(pc.inertia);
    const auto c = makeContact(pc.kind, 0, pc.shape, pc.support);
    Sim sim(model, {c});
    // Into contact: shift along the normal until the gap is zero.
    SE3 pose = pc.pose;
    ContactGeometry g;
    for (int k = 0; k < 4; ++k) {
      c->geometry(pose, Vec6::Zero(), 0.0, g);
      ASSERT_FALSE(g.singular) << pc.name << ": " << g.reason;
      pose.p -= g.gap * g.normal;
    }
    c->geometry(pose, Vec6::Zero(), 0.0, g);
    // A velocity satisfying every row: contact point at rest (knife edges: a
    // slip along the blade allowed), no spin about n for rubber rolling.
    Vec3 w = pc.omega;
    if (pc.kind == ContactKind::RollingWithoutSpin) w -= g.normal * g.normal.dot(w);
    Vec3 slip = Vec3::Zero();
    if (pc.kind == ContactKind::KnifeEdge) {
      const Vec3 a = pose.R * Vec3::UnitY();
      slip = 0.3 * a.cross(g.normal).normalized();
    }
    Vec6 V;
    V << w, slip - w.cross(g.point);
    VecX q, v;
    floatingState(pose, V, q, v);
    double t = 0;
    const auto r0 = sim.residuals(t, q, v);
    ASSERT_LT(r0.first, 1e-12) << pc.name;
    const double E0 = sim.energy(q, v);
    double maxv = 0, maxg = 0;
    const double dt = 5e-4;
    for (int k = 0; k < 3000; ++k) {
      sim.step(t, q, v, dt);
      if (k % 100 == 99) {
        const auto [rv, rg] = sim.residuals(t, q, v);
        maxv = std::max(maxv, rv);
        maxg = std::max(maxg, rg);
      }
    }
    const double E1 = sim.energy(q, v);
    EXPECT_LT(std::abs(E1 - E0), 1e-9 * std::abs(E0) + 1e-12) << pc.name << " E0=" << E0;
    EXPECT_LT(maxv, 1e-8) << pc.name;
    EXPECT_LT(maxg, 1e-8) << pc.name;
    // The body moved (the test is not trivially static).
    EXPECT_GT((q.head<3>() - pose.p).norm(), 1e-3) << pc.name;
  }
}

TEST(ContactPhysics, BallRollingOnAFreeCartConservesMomentumAndEnergy) {
  // No gravity; a free cart carries the support, a ball rolls on it. The
  // contact forces are internal: total momentum is conserved, and passive
  // rolling does no work.
  for (const SupportSurface& surf :
       std::vector<SupportSurface>{Plane{Vec3(0, 0, 0.2), Vec3(0.1, 0.2, 1).normalized()},
                                   SphereSurface{Vec3(0, 0, 1.0), 1.0,
                                                 SphereSurface::Side::Inside}}) {
    ModelBuilder mb;
    mb.setGravity(Vec3::Zero());
    mb.addBody("cart", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(),
               Inertia{4.0, Vec3(0.1, 0, 0), Vec3(0.5, 0.7, 0.9).asDiagonal()});
    mb.addBody("ball", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(),
               // Off-centre mass, unequal moments (a Chaplygin ball): rolling needs forces.
               Inertia{1.0, Vec3(0.03, 0, 0), Vec3(0.3, 0.4, 0.5).asDiagonal() * 0.01});
    const Model model = mb.build();
    Support sup{surf, StaticMotion{}, "cart top"};
    sup.body = 0;
    const auto c = makeContact(ContactKind::Rolling, 1, Sphere{0.1, Vec3::Zero()}, sup);
    Sim sim(model, {c});
    // Cart at rest at the origin, then the ball put in contact with a rolling velocity.
    SE3 cart, ball;
    ball.p = Vec3(0.3, -0.2, 0.5);
    ContactGeometry g;
    const SupportState S = c->supportStateAt(0, cart);
    for (int k = 0; k < 4; ++k) {
      contactGeometry(c->shape(), surf, S, ball, Vec6::Zero(), g);
      ball.p -= g.gap * g.normal;
    }
    contactGeometry(c->shape(), surf, S, ball, Vec6::Zero(), g);
    const Vec3 w(1.0, 2.0, -0.5);
    Vec6 Vb;
    Vb << w, -w.cross(g.point);
    VecX qc, vc, qb, vb;
    floatingState(cart, Vec6::Zero(), qc, vc);
    floatingState(ball, Vb, qb, vb);
    VecX q(14), v(12);
    q << qc, qb;
    v << vc, vb;
    double t = 0;
    ASSERT_LT(sim.residuals(t, q, v).first, 1e-12);
    const Vec6 P0 = momentum(model, sim.data, q, v);
    const double E0 = sim.energy(q, v);
    for (int k = 0; k < 2000; ++k) sim.step(t, q, v, 5e-4);
    const Vec6 P1 = momentum(model, sim.data, q, v);
    EXPECT_LT((P1 - P0).norm(), 1e-10 * (1 + P0.norm()));
    EXPECT_NEAR(sim.energy(q, v), E0, 1e-9 * E0);
    const auto [rv, rg] = sim.residuals(t, q, v);
    EXPECT_LT(rv, 1e-8);
    EXPECT_LT(rg, 1e-8);
    // The cart was set moving by the ball.
    EXPECT_GT(v.head<6>().norm(), 1e-2);
  }
}
