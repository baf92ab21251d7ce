// Conventions a user can guess (docs/engine.md): a planar joint's in-plane
// directions, the coordinate names the CSV, the CLI and Python share, and
// which of them name local coordinates (cyclic coordinates by position or
// velocity name).
#include <appell/appell.hpp>
#include <appell/output.hpp>
#include <appell/urdf.hpp>

#include <gtest/gtest.h>

#include <string>

using namespace appell;

namespace {

// One body on a planar joint from the world, plane normal `axis`.
Model planarBody(const Vec3& axis) {
  ModelBuilder b;
  b.addBody("puck", -1, SE3::Identity(), JointType::Planar, axis,
            Inertia{1.0, Vec3::Zero(), 0.1 * Mat3::Identity()}, "slide");
  return b.build();
}

// World position of the body at planar coordinates (x₁, x₂, φ).
Vec3 placeAt(const Model& m, double x1, double x2, double phi) {
  Data d(m);
  VecX q(3);
  q << x1, x2, phi;
  forwardKinematics(m, d, q, VecX::Zero(3));
  return d.oMi[0].p;
}

}  // namespace

// Axis z moves along x and y (what the CSV's .x .y say); axis x along y and
// z; axis y along x and −z — t₁ the first of x, y not within 45° of the
// normal, t₂ = normal × t₁.
TEST(Conventions, PlanarJointCoordinatesMoveAlongTheAxesTheyAreNamedFor) {
  const Model z = planarBody(Vec3::UnitZ());
  EXPECT_TRUE(placeAt(z, 1, 0, 0).isApprox(Vec3::UnitX()));
  EXPECT_TRUE(placeAt(z, 0, 1, 0).isApprox(Vec3::UnitY()));
  const Model x = planarBody(Vec3::UnitX());
  EXPECT_TRUE(placeAt(x, 1, 0, 0).isApprox(Vec3::UnitY()));
  EXPECT_TRUE(placeAt(x, 0, 1, 0).isApprox(Vec3::UnitZ()));
  const Model y = planarBody(Vec3::UnitY());
  EXPECT_TRUE(placeAt(y, 1, 0, 0).isApprox(Vec3::UnitX()));
  EXPECT_TRUE(placeAt(y, 0, 1, 0).isApprox(-Vec3::UnitZ()));
  // A tilted normal: t₁ is x projected into the plane, and the pair is
  // orthonormal and right-handed with the normal.
  const Vec3 n = Vec3(0.3, -0.2, 1).normalized();
  const Joint& j = planarBody(n).joints[0];
  EXPECT_NEAR(j.t1.dot(n), 0, 1e-15);
  EXPECT_NEAR(j.t1.norm(), 1, 1e-15);
  EXPECT_GT(j.t1.x(), 0.9);
  EXPECT_TRUE(j.t1.cross(j.t2).isApprox(n, 1e-15));
  // The rotation coordinate turns about the normal.
  Data d(z);
  VecX q(3);
  q << 0, 0, 0.5;
  forwardKinematics(z, d, q, VecX::Zero(3));
  EXPECT_TRUE(d.oMi[0].R.isApprox(Eigen::AngleAxisd(0.5, Vec3::UnitZ()).toRotationMatrix()));
}

// The names the CSV gives, and the local coordinate each one names: a
// velocity's name is its own slot; a floating base's .x .y .z are θ's
// world-frame translation (slots 3–5), a planar joint's positions its slots,
// a one-degree-of-freedom joint its name; quaternion components are refused
// with the names to use instead.
TEST(Conventions, CoordinateNamesAndTheLocalCoordinatesTheyName) {
  const Scene s = loadScene(std::string(APPELL_SOURCE_DIR) + "/examples/diff_drive/diff_drive.urdf");
  const Model& m = s.model;
  const std::vector<std::string> q = coordinateNames(m, false), v = coordinateNames(m, true);
  ASSERT_EQ(static_cast<int>(q.size()), m.nq);
  ASSERT_EQ(static_cast<int>(v.size()), m.nv);
  EXPECT_EQ(q[0], "root_joint.x");
  EXPECT_EQ(q[6], "root_joint.qw");
  EXPECT_EQ(v[0], "root_joint.wx");
  EXPECT_EQ(v[6], "left_wheel_joint");
  for (int k = 0; k < m.nv; ++k) EXPECT_EQ(localCoordinateIndex(m, v[k]), k) << v[k];
  EXPECT_EQ(localCoordinateIndex(m, "root_joint.x"), 3);
  EXPECT_EQ(localCoordinateIndex(m, "root_joint.z"), 5);
  EXPECT_EQ(localCoordinateIndex(m, "right_wheel_joint"), 7);
  EXPECT_EQ(localCoordinateIndex(m, "root_joint.spin"), -1);
  EXPECT_EQ(localCoordinateIndex(m, "root"), -1);
  try {
    localCoordinateIndex(m, "root_joint.qz");
    FAIL() << "a quaternion component named a coordinate";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("root_joint.wx"), std::string::npos) << e.what();
  }
  const Model p = planarBody(Vec3::UnitZ());
  EXPECT_EQ(localCoordinateIndex(p, "slide.theta"), 2);
  EXPECT_EQ(localCoordinateIndex(p, "slide.omega"), 2);
  EXPECT_EQ(localCoordinateIndex(p, "slide.y"), 1);
}
