// Exact contact geometry: rates against finite differences along rigid
// motions, for every shape × support pair (fixed and moving supports);
// closed forms; singular configurations reported without NaN.
#include "test_contact_common.hpp"

#include <gtest/gtest.h>

using namespace appell;
using namespace appell::testing;

namespace {

// Packs the geometry's fields for differencing: point, normal, t1, t2, gap.
Eigen::Matrix<double, 13, 1> pack(const ContactGeometry& g) {
  Eigen::Matrix<double, 13, 1> x;
  x << g.point, g.normal, g.t1, g.t2, g.gap;
  return x;
}

}  // namespace

TEST(SupportMotion, PoseVelocityAccelerationAreConsistent) {
  for (const auto& sc : supportCases()) {
    for (double t0 : {0.0, 0.37, 1.9}) {
      const SupportState S = supportState(sc.support.motion, t0);
      const double h = 1e-3;
      // Material velocity of three support-frame points, and dV/dt.
      for (const Vec3& x0 : {Vec3(0, 0, 0), Vec3(1, -0.5, 0.3), Vec3(-0.2, 0.7, 1.1)}) {
        const Vec3 fd = centralDiff(
            [&](double tau) { return supportState(sc.support.motion, t0 + tau).pose.apply(x0); }, h);
        const Vec3 x = S.pose.apply(x0);
        EXPECT_LT((fd - S.pointVelocity(x)).norm(), 1e-9) << sc.name << " t=" << t0;
      }
      const Vec6 dV =
          centralDiff([&](double tau) { return supportState(sc.support.motion, t0 + tau).V; }, h);
      EXPECT_LT((dV - S.A).norm(), 1e-9) << sc.name << " t=" << t0;
    }
  }
}

TEST(SupportMotion, TwistExpMatchesIntegratedMotion) {
  // A point carried by a constant twist satisfies ẋ = v + Ω × x at every time.
  const Vec6 V = (Vec6() << 0.3, -1.2, 0.8, 0.5, 0.1, -0.4).finished();
  for (double t : {0.0, 0.5, 2.0}) {
    const Vec3 x0(0.3, -0.2, 1.0);
    const Vec3 fd = centralDiff([&](double tau) { return twistExp(V, t + tau).apply(x0); }, 1e-3);
    const Vec3 x = twistExp(V, t).apply(x0);
    EXPECT_LT((fd - (V.tail<3>() + V.head<3>().cross(x))).norm(), 1e-10);
  }
  // Turntable: the centre of rotation stays put.
  const ConstantTwistMotion tt = turntable(Vec3(1, 2, 0), Vec3::UnitZ(), 0.7);
  EXPECT_LT((twistExp(tt.twist, 3.3).apply(Vec3(1, 2, 0)) - Vec3(1, 2, 0)).norm(), 1e-14);
}

TEST(ContactGeometry, RatesMatchFiniteDifferencesForEveryPair) {
  std::mt19937 rng(7);
  int checked = 0;
  for (const auto& shc : shapeCases()) {
    for (const auto& suc : supportCases()) {
      if (!isSmoothContactShape(shc.shape)) continue;
      if (const auto* sp = std::get_if<SphereSurface>(&suc.support.surface);
          sp && sp->side == SphereSurface::Side::Inside && !fitsInBowl(shc.shape, sp->radius))
        continue;
      for (int trial = 0; trial < 6; ++trial) {
        const double t0 = uniform(rng, 0.0, 2.0);
        const SupportState S0 = supportState(suc.support.motion, t0);
        SE3 pose0;
        ASSERT_TRUE(placeNearContact(shc.shape, suc.support.surface, S0, rng,
                                     uniform(rng, -0.02, 0.02), pose0))
            << shc.name << " on " << suc.name;
        Vec6 V;
        V << randomVec(rng, 2.0), randomVec(rng, 1.0);
        ContactGeometry g;
        contactGeometry(shc.shape, suc.support.surface, S0, pose0, V, g);
        ASSERT_FALSE(g.singular) << shc.name << " on " << suc.name << ": " << g.reason;

        const auto fd = centralDiff(
            [&](double tau) {
              ContactGeometry gt;
              contactGeometry(shc.shape, suc.support.surface,
                              supportState(suc.support.motion, t0 + tau), twistExp(V, tau) * pose0,
                              V, gt);
              return pack(gt);
            },
            2.5e-4);
        const std::string where = shc.name + " on " + suc.name + " #" + std::to_string(trial);
        const double tol = 2e-8;
        EXPECT_LT((fd.segment<3>(0) - g.point_rate).norm(), tol * (1 + g.point_rate.norm())) << where;
        EXPECT_LT((fd.segment<3>(3) - g.normal_rate).norm(), tol * (1 + g.normal_rate.norm())) << where;
        EXPECT_LT((fd.segment<3>(6) - g.t1_rate).norm(), tol * (1 + g.t1_rate.norm())) << where;
        EXPECT_LT((fd.segment<3>(9) - g.t2_rate).norm(), tol * (1 + g.t2_rate.norm())) << where;
        // The gap rate is the normal relative velocity of the material points.
        const Vec3 vb = V.tail<3>() + V.head<3>().cross(g.point);
        const double gdot = g.normal.dot(vb - S0.pointVelocity(g.point));
        EXPECT_NEAR(fd[12], gdot, tol * (1 + std::abs(gdot))) << where;
        // Frame: orthonormal, right-handed, n from support toward body.
        EXPECT_NEAR(g.normal.norm(), 1.0, 1e-14);
        EXPECT_NEAR(g.t1.dot(g.normal), 0.0, 1e-14);
        EXPECT_LT((g.t2 - g.normal.cross(g.t1)).norm(), 1e-14);
        EXPECT_LT((g.support_point - (g.point - g.gap * g.normal)).norm(), 1e-14);
        // The body point really is the body point with outward normal −n.
        const GaussPoint gp = inverseGaussMap(shc.shape, -(pose0.R.transpose() * g.normal));
        EXPECT_LT((pose0.apply(gp.y) - g.point).norm(), 1e-12) << where;
        ++checked;
      }
    }
  }
  EXPECT_EQ(checked, 6 * 6 * 10);
}

TEST(ContactGeometry, SupportPointLiesOnTheSupport) {
  std::mt19937 rng(11);
  for (const auto& shc : shapeCases()) {
    for (const auto& suc : supportCases()) {
      const SupportState S = supportState(suc.support.motion, 0.8);
      SE3 pose;
      ASSERT_TRUE(placeNearContact(shc.shape, suc.support.surface, S, rng, 0.05, pose));
      ContactGeometry g;
      contactGeometry(shc.shape, suc.support.surface, S, pose, Vec6::Zero(), g);
      EXPECT_NEAR(g.gap, 0.05, 1e-12);
      if (const auto* p = std::get_if<Plane>(&suc.support.surface)) {
        EXPECT_NEAR((S.pose.R * p->normal).dot(g.support_point - S.pose.apply(p->point)), 0, 1e-12);
      } else {
        const auto& sp = std::get<SphereSurface>(suc.support.surface);
        const Vec3 C = S.pose.apply(sp.centre);
        EXPECT_NEAR((g.support_point - C).norm(), sp.radius, 1e-12);
        // n from the support toward the body: outward on a globe, inward in a bowl.
        const double side = sp.side == SphereSurface::Side::Outside ? 1.0 : -1.0;
        EXPECT_LT((g.normal - side * (g.support_point - C) / sp.radius).norm(), 1e-12);
      }
    }
  }
}

TEST(ContactGeometry, SphereOnPlaneClosedForm) {
  const Sphere ball{0.25, Vec3(0.1, 0, 0)};
  const Vec3 n = Vec3(0.3, -0.1, 1).normalized();
  const Plane plane{Vec3(0, 0, 0.2), n};
  SE3 pose;
  pose.R = axisAngle(Vec3(1, 1, 0).normalized(), 0.6);
  pose.p = Vec3(0.5, 0.5, 1.0);
  ContactGeometry g;
  contactGeometry(ball, plane, SupportState{}, pose, Vec6::Zero(), g);
  const Vec3 c = pose.apply(ball.centre);
  EXPECT_LT((g.point - (c - 0.25 * n)).norm(), 1e-14);
  EXPECT_NEAR(g.gap, n.dot(c - Vec3(0, 0, 0.2)) - 0.25, 1e-14);
  EXPECT_LT((g.normal - n).norm(), 1e-15);
}

TEST(ContactGeometry, TiltedDiskAndTorusClosedForm) {
  // Axle a = (0, cos θ, sin θ): the lowest rim point is c + ρ (0, sin θ, −cos θ).
  for (double th : {0.0, 0.3, -1.1}) {
    const Vec3 a(0, std::cos(th), std::sin(th)), u(0, std::sin(th), -std::cos(th));
    SE3 pose;
    pose.p = Vec3(1.0, 2.0, 0.4 * std::cos(th));
    ContactGeometry g;
    contactGeometry(Disk{0.4, Vec3::Zero(), a}, Plane{}, SupportState{}, pose, Vec6::Zero(), g);
    EXPECT_LT((g.point - (pose.p + 0.4 * u)).norm(), 1e-14);
    EXPECT_NEAR(g.gap, 0.0, 1e-14);
    contactGeometry(Torus{0.4, 0.1, Vec3::Zero(), a}, Plane{}, SupportState{}, pose, Vec6::Zero(), g);
    EXPECT_LT((g.point - (pose.p + 0.4 * u - Vec3(0, 0, 0.1))).norm(), 1e-14);
    EXPECT_NEAR(g.gap, -0.1, 1e-14);
  }
}

TEST(ContactGeometry, EllipsoidOnPlaneClosedForm) {
  // Height of the lowest point below the centre is √(nᵀQn) (support function).
  const Ellipsoid e{Vec3(0.5, 0.3, 0.2), Vec3::Zero(), axisAngle(Vec3::UnitY(), 0.3)};
  SE3 pose;
  pose.R = axisAngle(Vec3(1, 2, 0).normalized(), 0.8);
  pose.p = Vec3(0, 0, 1);
  const Mat3 Q = e.orientation * e.semi_axes.cwiseAbs2().asDiagonal() * e.orientation.transpose();
  const Vec3 nb = pose.R.transpose() * Vec3::UnitZ();
  ContactGeometry g;
  contactGeometry(e, Plane{}, SupportState{}, pose, Vec6::Zero(), g);
  EXPECT_NEAR(g.gap, 1.0 - std::sqrt(nb.dot(Q * nb)), 1e-14);
  // The contact point is on the surface.
  const Vec3 y = e.orientation.transpose() * g.point_body;
  EXPECT_NEAR(y.cwiseQuotient(e.semi_axes).squaredNorm(), 1.0, 1e-13);
}

TEST(ContactGeometry, SphereInBowlAndOnGlobeClosedForm) {
  const SphereSurface bowl{Vec3(0, 0, 1), 1.0, SphereSurface::Side::Inside};
  const SphereSurface globe{Vec3(0, 0, -1), 1.0, SphereSurface::Side::Outside};
  SE3 pose;
  pose.p = Vec3(0.2, -0.1, 0.5);
  const Sphere ball{0.3, Vec3::Zero()};
  ContactGeometry g;
  contactGeometry(ball, bowl, SupportState{}, pose, Vec6::Zero(), g);
  const Vec3 dir = (pose.p - Vec3(0, 0, 1)).normalized();
  EXPECT_LT((g.point - (pose.p + 0.3 * dir)).norm(), 1e-14);
  EXPECT_NEAR(g.gap, 1.0 - (pose.p - Vec3(0, 0, 1)).norm() - 0.3, 1e-14);
  EXPECT_LT((g.normal + dir).norm(), 1e-14);
  contactGeometry(ball, globe, SupportState{}, pose, Vec6::Zero(), g);
  const Vec3 dir2 = (pose.p - Vec3(0, 0, -1)).normalized();
  EXPECT_LT((g.point - (pose.p - 0.3 * dir2)).norm(), 1e-14);
  EXPECT_NEAR(g.gap, (pose.p - Vec3(0, 0, -1)).norm() - 1.3, 1e-14);
}

TEST(ContactGeometry, EllipsoidInBowlIsTheFarthestPoint) {
  // Brute force over the surface: the solver's point is the farthest from C.
  const Ellipsoid e{Vec3(0.4, 0.25, 0.15), Vec3(0.01, 0, 0), axisAngle(Vec3::UnitX(), 0.2)};
  const SphereSurface bowl{Vec3(0, 0, 1.2), 1.2, SphereSurface::Side::Inside};
  std::mt19937 rng(3);
  for (int trial = 0; trial < 20; ++trial) {
    SE3 pose;
    ASSERT_TRUE(placeNearContact(e, bowl, SupportState{}, rng, -0.01, pose));
    ContactGeometry g;
    contactGeometry(e, bowl, SupportState{}, pose, Vec6::Zero(), g);
    ASSERT_FALSE(g.singular) << g.reason;
    EXPECT_GT(g.iterations, 0);
    const Vec3 C(0, 0, 1.2);
    const double dsol = (g.point - C).norm();
    double dmax = 0;
    for (int k = 0; k < 20000; ++k) {
      const Vec3 m = randomUnit(rng);
      dmax = std::max(dmax, (pose.apply(inverseGaussMap(e, m).y) - C).norm());
    }
    EXPECT_GE(dsol, dmax - 1e-12);
    EXPECT_LT(dsol - dmax, 1e-3);  // the sampling gets close
  }
}

TEST(ContactGeometry, EllipsoidOnGlobeIsTheNearestPoint) {
  const Ellipsoid e{Vec3(0.4, 0.25, 0.15), Vec3::Zero(), Mat3::Identity()};
  const SphereSurface globe{Vec3(0, 0, -1), 1.0, SphereSurface::Side::Outside};
  std::mt19937 rng(5);
  for (int trial = 0; trial < 20; ++trial) {
    SE3 pose;
    ASSERT_TRUE(placeNearContact(e, globe, SupportState{}, rng, 0.03, pose));
    ContactGeometry g;
    contactGeometry(e, globe, SupportState{}, pose, Vec6::Zero(), g);
    ASSERT_FALSE(g.singular);
    const Vec3 C(0, 0, -1);
    double dmin = 1e9;
    for (int k = 0; k < 20000; ++k)
      dmin = std::min(dmin, (pose.apply(inverseGaussMap(e, randomUnit(rng)).y) - C).norm());
    EXPECT_LE((g.point - C).norm(), dmin + 1e-12);
  }
}

namespace {

void expectSingular(const Shape& shape, const SupportSurface& surf, const SE3& pose,
                    const std::string& fragment) {
  ContactGeometry g;
  Vec6 V;
  V << 0.3, -0.2, 0.5, 0.1, 0.2, -0.3;
  contactGeometry(shape, surf, SupportState{}, pose, V, g);
  EXPECT_TRUE(g.singular) << fragment;
  ASSERT_NE(g.reason, nullptr);
  EXPECT_NE(std::string(g.reason).find(fragment), std::string::npos) << g.reason;
  EXPECT_TRUE(g.point.allFinite() && g.normal.allFinite() && g.t1.allFinite() &&
              g.t2.allFinite() && std::isfinite(g.gap) && g.point_rate.allFinite() &&
              g.normal_rate.allFinite() && g.t1_rate.allFinite() && g.t2_rate.allFinite());
}

}  // namespace

TEST(ContactGeometry, SingularConfigurationsAreReportedWithoutNaN) {
  SE3 up;
  up.p = Vec3(0, 0, 0.5);
  // A disk or a torus lying flat on a plane: every rim point touches.
  expectSingular(Disk{0.3, Vec3::Zero(), Vec3::UnitZ()}, Plane{}, up, "flat");
  expectSingular(Torus{0.3, 0.05, Vec3::Zero(), Vec3::UnitZ()}, Plane{}, up, "flat");
  // A hemisphere upside down: the plane would touch its flat face.
  expectSingular(SphericalCap{0.3, Vec3::Zero(), Vec3::UnitZ(), M_PI / 2}, Plane{}, up,
                 "outside the spherical cap");
  // A ball centred at the bowl's centre: every direction is a contact normal.
  const SphereSurface bowl{Vec3(0, 0, 0.5), 1.0, SphereSurface::Side::Inside};
  expectSingular(Sphere{0.3, Vec3::Zero()}, bowl, up, "coincides");
  // A wheel whose axis passes through the bowl's centre.
  expectSingular(Disk{0.3, Vec3::Zero(), Vec3::UnitZ()}, bowl, up, "axis");
  // An ellipsoid floating at the bowl's centre: two mirror farthest points.
  expectSingular(Ellipsoid{Vec3(0.4, 0.25, 0.15), Vec3::Zero(), Mat3::Identity()}, bowl, up,
                 "unique");
  // An ellipsoid off-centre but far from the wall: contact not unique.
  SE3 off = up;
  off.p.x() += 0.05;
  expectSingular(Ellipsoid{Vec3(0.4, 0.25, 0.15), Vec3::Zero(), Mat3::Identity()}, bowl, off,
                 "unique");
  // The centre of a globe inside an ellipsoid.
  const SphereSurface globe{Vec3(0, 0, 0.5), 1.0, SphereSurface::Side::Outside};
  expectSingular(Ellipsoid{Vec3(0.4, 0.25, 0.15), Vec3::Zero(), Mat3::Identity()}, globe, up,
                 "inside the ellipsoid");
  // A ball on a globe poking through a ring (the wheel's non-convex side).
  SE3 ring;
  ring.p = Vec3(0.3, 0, 1.4);
  expectSingular(Torus{1.2, 0.05, Vec3::Zero(), Vec3::UnitZ()}, globe, ring, "inner");
}
