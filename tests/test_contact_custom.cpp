// User-supplied Pfaffian rows (CustomConstraint), the contact factory's
// errors for bad declarations, and contact-kind parsing.
#include "test_contact_common.hpp"

#include <appell/appell.hpp>
#include <appell/constraint_set.hpp>
#include <appell/custom_constraint.hpp>

#include <gtest/gtest.h>

using namespace appell;
using namespace appell::testing;

namespace {

// Three prismatic joints x, y, z: q̇ = v.
Model cartesianPoint() {
  ModelBuilder b;
  const Inertia in{1.0, Vec3::Zero(), Mat3::Identity() * 0.1};
  int i = b.addBody("x", -1, SE3::Identity(), JointType::Prismatic, Vec3::UnitX(), in);
  i = b.addBody("y", i, SE3::Identity(), JointType::Prismatic, Vec3::UnitY(), in);
  b.addBody("z", i, SE3::Identity(), JointType::Prismatic, Vec3::UnitZ(), in);
  return b.build();
}

// The contact oscillator's constraint ẋ + y ż = 0 (McLachlan & Perlmutter
// 2006), made time-dependent: ẋ + y ż + 0.3 sin 2t = 0; and a holonomic row
// d/dt (z − 0.1 t²) = ż − 0.2 t.
CustomRows oscillatorRows() {
  CustomRows r;
  r.name = "oscillator";
  r.rows = 2;
  r.A_b = [](const Model&, const VecX& q, double t, Eigen::Ref<MatX> A, Eigen::Ref<VecX> b) {
    A.setZero();
    A(0, 0) = 1;
    A(0, 2) = q[1];
    A(1, 2) = 1;
    b[0] = 0.3 * std::sin(2 * t);
    b[1] = -0.2 * t;
  };
  r.bias = [](const Model&, const VecX&, const VecX& v, double t, Eigen::Ref<VecX> ab) {
    ab[0] = v[1] * v[2] + 0.6 * std::cos(2 * t);
    ab[1] = -0.2;
  };
  r.gap = [](const Model&, const VecX& q, double t, Eigen::Ref<VecX> g) {
    g[0] = 0;
    g[1] = q[2] - 0.1 * t * t;
  };
  r.labels = {"oscillator", "height"};
  r.holonomic = {false, true};
  return r;
}

}  // namespace

TEST(CustomConstraint, RowsPassThroughAndAccelerationTermIsConsistent) {
  const Model model = cartesianPoint();
  const auto c = std::make_shared<CustomConstraint>(oscillatorRows());
  EXPECT_TRUE(c->jointSpace());
  EXPECT_EQ(c->rows(), 2);
  EXPECT_EQ(c->rowLabel(1), "height");
  // A user's rows are Custom; their labels are the user's, or "custom<k>".
  EXPECT_EQ(c->rowKind(1), RowKind::Custom);
  CustomRows unlabelled = oscillatorRows();
  unlabelled.labels.clear();
  EXPECT_EQ(CustomConstraint(unlabelled).rowLabel(1), "custom1");
  EXPECT_TRUE(c->holonomic(1));
  EXPECT_FALSE(c->holonomic(0));
  const ConstraintList list{c};
  ConstraintData cd(model, list);
  Data data(model);
  std::mt19937 rng(4);
  for (int trial = 0; trial < 10; ++trial) {
    VecX q(3), v(3), vd(3);
    q << randomVec(rng);
    v << randomVec(rng);
    vd << randomVec(rng);
    const double t0 = uniform(rng, 0, 3);
    // Exact motion for q̇ = v, v̇ = const.
    auto value = [&](double tau) {
      const VecX qt = q + tau * v + 0.5 * tau * tau * vd, vt = v + tau * vd;
      evaluateConstraints(model, data, list, cd, t0 + tau, qt, vt);
      return VecX(cd.A * vt + cd.b);
    };
    const VecX fd = centralDiff(value, 1e-3);
    evaluateConstraints(model, data, list, cd, t0, q, v);
    EXPECT_NEAR(cd.A(0, 2), q[1], 1e-15);
    EXPECT_NEAR(cd.b[0], 0.3 * std::sin(2 * t0), 1e-15);
    EXPECT_LT((fd - (cd.A * vd + cd.abias)).norm(), 1e-9);
    EXPECT_FALSE(cd.singular);
    RowBlock blk;
    c->reserve(model, blk);
    forwardKinematics(model, data, q, v);
    c->evaluate(model, data, t0, q, v, blk);
    EXPECT_NEAR(blk.gap[1], q[2] - 0.1 * t0 * t0, 1e-15);
    EXPECT_EQ(blk.gap[0], 0.0);
  }
}

TEST(CustomConstraint, NonFiniteCallbackIsReportedNotPassedOn) {
  const Model model = cartesianPoint();
  CustomRows r = oscillatorRows();
  r.bias = [](const Model&, const VecX&, const VecX&, double, Eigen::Ref<VecX> ab) {
    ab[0] = std::nan("");
    ab[1] = 0;
  };
  const CustomConstraint c(r);
  RowBlock blk;
  c.reserve(model, blk);
  Data data(model);
  const VecX q = VecX::Zero(3), v = VecX::Zero(3);
  c.evaluate(model, data, 0, q, v, blk);
  EXPECT_TRUE(blk.singular);
  EXPECT_NE(blk.singular_reason.find("non-finite"), std::string::npos);
}

TEST(CustomConstraint, BadSpecificationsAreClearErrors) {
  auto expectError = [](CustomRows r, const std::string& fragment) {
    try {
      CustomConstraint c(std::move(r));
      ADD_FAILURE() << "no error for: " << fragment;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("oscillator"), std::string::npos) << e.what();
    }
  };
  CustomRows r = oscillatorRows();
  r.rows = 0;
  expectError(r, "rows");
  r = oscillatorRows();
  r.A_b = nullptr;
  expectError(r, "callback is empty");
  r = oscillatorRows();
  r.bias = nullptr;
  expectError(r, "acceleration-term");
  r = oscillatorRows();
  r.gap = nullptr;
  expectError(r, "gap callback");
  r = oscillatorRows();
  r.labels = {"only one"};
  expectError(r, "labels");
}

namespace {

void expectContactError(ContactKind kind, int body, const Shape& shape, const Support& support,
                        const ContactOptions& o, const std::string& fragment) {
  try {
    makeContact(kind, body, shape, support, o);
    ADD_FAILURE() << "no error for: " << fragment;
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("contact '"), std::string::npos) << e.what();
  }
}

}  // namespace

TEST(ContactFactory, BadDeclarationsAreClearErrors) {
  const Support ground{Plane{}};
  const ContactOptions none;
  expectContactError(ContactKind::Rolling, 0, Box{}, ground, none, "a box cannot roll");
  expectContactError(ContactKind::RollingWithoutSpin, 0, Cylinder{0.2, 0.1, {}}, ground, none,
                     "cylinder cannot roll");
  expectContactError(ContactKind::Rolling, 0, Mesh{"wheel.stl", Vec3::Ones(), {}, {}, {}}, ground, none,
                     "collision-only");
  expectContactError(ContactKind::RollingWithoutSpin, 0, PointShape{}, ground, none,
                     "point cannot roll");
  expectContactError(ContactKind::Sliding, 0, Box{}, ground, none, "no smooth contact point");
  expectContactError(ContactKind::KnifeEdge, 0, PointShape{}, ground, none,
                     "non-zero blade direction");
  expectContactError(ContactKind::KnifeEdge, 0, Sphere{0.1, Vec3::Zero()}, ground, none,
                     "needs a blade");
  ContactOptions blade;
  blade.blade_direction = Vec3::UnitX();
  expectContactError(ContactKind::KnifeEdge, 0, Disk{0.3, Vec3::Zero(), Vec3::UnitY()}, ground,
                     blade, "leave blade_direction unset");
  expectContactError(ContactKind::Rolling, -1, Sphere{0.1, Vec3::Zero()}, ground, none,
                     "body index");
  expectContactError(ContactKind::Rolling, 0, Sphere{-0.1, Vec3::Zero()}, ground, none,
                     "radius");
  expectContactError(ContactKind::Rolling, 0, Disk{0.3, Vec3::Zero(), Vec3(0, 2, 0)}, ground,
                     none, "unit vector");
  expectContactError(ContactKind::Rolling, 0, Torus{0.0, 0.2, Vec3::Zero(), Vec3::UnitY()},
                     ground, none, "major radius");
  expectContactError(ContactKind::Rolling, 0,
                     SphericalCap{0.3, Vec3::Zero(), -Vec3::UnitZ(), 4.0}, ground, none,
                     "half-angle");
  expectContactError(ContactKind::Rolling, 0,
                     Ellipsoid{Vec3(0.4, 0.2, 0.1), Vec3::Zero(), 2 * Mat3::Identity()}, ground,
                     none, "rotation");
  // Supports.
  expectContactError(ContactKind::Rolling, 0, Sphere{0.1, Vec3::Zero()},
                     Support{Plane{Vec3::Zero(), Vec3::Zero()}, StaticMotion{}, "floor"}, none,
                     "normal");
  expectContactError(ContactKind::Rolling, 0, Sphere{0.1, Vec3::Zero()},
                     Support{SphereSurface{Vec3::Zero(), -1.0}, StaticMotion{}, "bowl"}, none,
                     "radius");
  expectContactError(ContactKind::Rolling, 0, Sphere{0.1, Vec3::Zero()},
                     Support{Plane{}, PrescribedMotion{}, "belt"}, none, "no callback");
  // Bowl fit: a ball as big as the bowl, an ellipsoid too flat for it.
  const Support bowl{SphereSurface{Vec3(0, 0, 1), 1.0, SphereSurface::Side::Inside},
                     StaticMotion{}, "bowl"};
  expectContactError(ContactKind::Rolling, 0, Sphere{1.0, Vec3::Zero()}, bowl, none,
                     "does not fit the bowl");
  expectContactError(ContactKind::Rolling, 0,
                     Ellipsoid{Vec3(0.6, 0.3, 0.2), Vec3::Zero(), Mat3::Identity()}, bowl, none,
                     "radius of curvature");
  // The contact's name is in the message when given.
  ContactOptions named;
  named.name = "left_wheel";
  try {
    makeContact(ContactKind::Rolling, 0, Box{}, ground, named);
    ADD_FAILURE();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("left_wheel"), std::string::npos);
  }
  // Body index beyond the model: reported when the contact is set up.
  ModelBuilder mb;
  mb.addBody("b", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(),
             Inertia{1, Vec3::Zero(), Mat3::Identity()});
  const Model model = mb.build();
  const auto c = makeContact(ContactKind::Rolling, 3, Sphere{0.1, Vec3::Zero()}, ground);
  RowBlock blk;
  EXPECT_THROW(c->reserve(model, blk), std::invalid_argument);
}

TEST(ContactFactory, KindsAndLabels) {
  EXPECT_EQ(contactKindFromString("rolling"), ContactKind::Rolling);
  EXPECT_EQ(contactKindFromString("rolling_without_spin"), ContactKind::RollingWithoutSpin);
  EXPECT_EQ(contactKindFromString("knife_edge"), ContactKind::KnifeEdge);
  EXPECT_EQ(contactKindFromString("sliding"), ContactKind::Sliding);
  EXPECT_THROW(contactKindFromString("glued"), std::invalid_argument);
  const Support g{Plane{}};
  const auto r = makeContact(ContactKind::RollingWithoutSpin, 0, Sphere{0.1, Vec3::Zero()}, g);
  EXPECT_EQ(r->rows(), 4);
  EXPECT_EQ(r->rowLabel(3), "spin");
  // The rows' meaning is data; the labels (CSV column names) derive from it.
  const RowKind rolling[] = {RowKind::Tangent1, RowKind::Tangent2, RowKind::Normal, RowKind::Spin};
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(r->rowKind(k), rolling[k]);
    EXPECT_EQ(r->rowLabel(k), toString(rolling[k]));
    EXPECT_EQ(r->holonomic(k), rolling[k] == RowKind::Normal);
  }
  EXPECT_TRUE(r->holonomic(2));
  EXPECT_FALSE(r->holonomic(3));
  ContactOptions o;
  o.blade_direction = Vec3(0, 2, 0);
  const auto k = makeContact(ContactKind::KnifeEdge, 0, PointShape{}, g, o);
  EXPECT_EQ(k->rows(), 2);
  EXPECT_EQ(k->rowLabel(0), "lateral");
  EXPECT_EQ(k->rowKind(0), RowKind::Lateral);
  EXPECT_EQ(k->rowKind(1), RowKind::Normal);
  EXPECT_TRUE(isTangential(RowKind::Lateral));
  EXPECT_FALSE(isTangential(RowKind::Spin));
  EXPECT_TRUE(k->bladeDirection().isApprox(Vec3::UnitY()));
  std::string why;
  EXPECT_FALSE(canRoll(Box{}, &why));
  EXPECT_NE(why.find("box"), std::string::npos);
  EXPECT_TRUE(canRoll(Torus{0.3, 0.05, Vec3::Zero(), Vec3::UnitY()}));
}

TEST(ContactRows, SingularRowsAreReportedFiniteThroughTheConstraint) {
  // Knife edge along the normal; a disk lying flat: singular, finite, with reasons.
  const Support g{Plane{}};
  ContactOptions o;
  o.blade_direction = Vec3::UnitZ();
  const auto knife = makeContact(ContactKind::KnifeEdge, 0, PointShape{}, g, o);
  const auto disk = makeContact(ContactKind::Rolling, 0, Disk{0.3, Vec3::Zero(), Vec3::UnitZ()}, g);
  SE3 pose;
  pose.p = Vec3(0, 0, 0.2);
  Vec6 V;
  V << 0.1, 0.2, 0.3, -0.1, 0.4, 0.2;
  for (const auto& c : {knife, disk}) {
    RowBlock blk;
    c->evaluateAt(pose, V, 0.0, blk);
    EXPECT_TRUE(blk.singular) << c->name();
    EXPECT_FALSE(blk.singular_reason.empty());
    EXPECT_TRUE(blk.Wa.allFinite() && blk.b.allFinite() && blk.kappa.allFinite() &&
                blk.gap.allFinite());
  }
  RowBlock blk;
  knife->evaluateAt(pose, V, 0.0, blk);
  EXPECT_NE(blk.singular_reason.find("knife edge parallel"), std::string::npos);
  // Tilting the blade away from the normal clears it.
  pose.R = axisAngle(Vec3::UnitX(), 0.3);
  knife->evaluateAt(pose, V, 0.0, blk);
  EXPECT_FALSE(blk.singular);
  EXPECT_TRUE(blk.singular_reason.empty());
}
