// Links on fixed joints as ROS tools load them: a base_footprint with no
// inertial, sensor frames with mass="0" (CAD exporters), point masses with
// zero inertia — each merged into the rigid group of the moving link it hangs
// on (Pinocchio/KDL: inertias of fixed-joint children are combined), and only
// a group's combined inertia is judged.
#include <appell/appell.hpp>
#include <appell/urdf.hpp>

#include <gtest/gtest.h>

#include <random>

using namespace appell;

namespace {

const char* kInertial0 =
    "<inertial><mass value=\"0\"/><inertia ixx=\"0\" ixy=\"0\" ixz=\"0\" iyy=\"0\" iyz=\"0\" izz=\"0\"/></inertial>";

// A ROS-style mobile base: base_footprint (no inertial) is the root, base_link
// hangs 0.1 m above it; a laser (SolidWorks-style mass="0"), a camera point
// mass (mass 0.5, zero inertia, its centre 5 cm above its frame) and an IMU
// rotated 90° about z with an anisotropic inertia are fixed to base_link.
std::string mobileBase() {
  return std::string(R"(<robot name="base">
  <link name="base_footprint"/>
  <joint name="footprint_joint" type="fixed"><parent link="base_footprint"/><child link="base_link"/>
    <origin xyz="0 0 0.1"/></joint>
  <link name="base_link"><inertial><origin xyz="0.01 0 0"/><mass value="2"/>
    <inertia ixx="0.02" ixy="0" ixz="0" iyy="0.03" iyz="0" izz="0.04"/></inertial></link>
  <joint name="laser_joint" type="fixed"><parent link="base_link"/><child link="laser"/>
    <origin xyz="0.2 0 0.1"/></joint>
  <link name="laser">)") + kInertial0 + R"(</link>
  <joint name="camera_joint" type="fixed"><parent link="base_link"/><child link="camera"/>
    <origin xyz="0.1 0 0.3"/></joint>
  <link name="camera"><inertial><origin xyz="0 0 0.05"/><mass value="0.5"/>
    <inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>
  <joint name="imu_joint" type="fixed"><parent link="laser"/><child link="imu"/>
    <origin xyz="0 0.05 0" rpy="0 0 1.5707963267948966"/></joint>
  <link name="imu"><inertial><mass value="0.1"/>
    <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.0025"/></inertial></link>
</robot>)";
}

}  // namespace

TEST(FixedLinks, SensorFramesAndPointMassesMergeIntoTheirMovingLink) {
  const Scene s = loadSceneFromString(mobileBase(), ".", "base.urdf");
  const Model& m = s.model;
  ASSERT_EQ(m.nv, 6);  // one rigid body, floating
  const std::vector<RigidGroup> groups = rigidGroups(m);
  ASSERT_EQ(groups.size(), 1u);
  const RigidGroup& g = groups[0];
  EXPECT_EQ(m.body_names[g.body], "base_footprint");
  ASSERT_EQ(g.fixed.size(), 4u);
  EXPECT_EQ(m.body_names[g.fixed[0]], "base_link");

  // By hand, in base_footprint's frame: base_link's centre at (0.01, 0, 0.1),
  // the camera's at (0.1, 0, 0.1 + 0.3 + 0.05), the IMU's at (0.2, 0.05, 0.2).
  const double mass = 2 + 0.5 + 0.1;
  const Vec3 c_base(0.01, 0, 0.1), c_cam(0.1, 0, 0.45), c_imu(0.2, 0.05, 0.2);
  const Vec3 com = (2 * c_base + 0.5 * c_cam + 0.1 * c_imu) / mass;
  EXPECT_NEAR(g.inertia.mass, mass, 1e-15);
  EXPECT_LT((g.inertia.com - com).norm(), 1e-15);
  // Rotational inertia about the combined centre: parallel axes, the IMU's
  // tensor rotated by 90° about z (its x and y moments swap).
  auto shifted = [&](double mk, const Vec3& ck, const Vec3& diag) {
    const Vec3 d = ck - com;
    return Mat3(Mat3(diag.asDiagonal()) + mk * (d.squaredNorm() * Mat3::Identity() - d * d.transpose()));
  };
  const Mat3 J = shifted(2, c_base, Vec3(0.02, 0.03, 0.04)) + shifted(0.5, c_cam, Vec3::Zero()) +
                 shifted(0.1, c_imu, Vec3(0.002, 0.001, 0.0025));
  EXPECT_LT((g.inertia.inertia_com - J).norm(), 1e-15) << g.inertia.inertia_com;

  // The dynamics see one rigid body: ABA on the URDF tree equals ABA on a
  // single free body with the combined inertia, at a random spinning state.
  ModelBuilder one;
  one.addBody("merged", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(), g.inertia);
  const Model single = one.build();
  Data d1(m), d2(single);
  std::mt19937 rng(7);
  std::normal_distribution<double> n01;
  VecX q = neutralConfiguration(m), v(6), tau(6);
  for (int k = 0; k < 6; ++k) v[k] = n01(rng), tau[k] = n01(rng);
  q.tail<4>() = Quat(0.9, 0.1, -0.3, 0.2).normalized().coeffs();
  const VecX a1 = aba(m, d1, q, v, tau), a2 = aba(single, d2, q, v, tau);
  EXPECT_LT((a1 - a2).norm(), 1e-12 * a2.norm()) << a1.transpose() << "\n" << a2.transpose();
  // The frames stay available: the camera is where its joints put it.
  forwardKinematics(m, d1, neutralConfiguration(m));
  EXPECT_LT((d1.oMi[m.bodyIndex("camera")].p - Vec3(0.1, 0, 0.4)).norm(), 1e-15);
}

// A moving link whose own inertia is degenerate (a point mass on a wheel
// joint) loads when the links fixed to it make the group a rigid body; a
// group that is still not one is refused, naming the merged links, at the
// moving link's element.
TEST(FixedLinks, OnlyTheCombinedInertiaOfAMovingGroupIsJudged) {
  const std::string head = R"(<robot name="w">
  <link name="chassis"><inertial><mass value="5"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="axle" type="continuous"><parent link="chassis"/><child link="hub"/><axis xyz="0 1 0"/></joint>
  <link name="hub"><inertial><mass value="0.2"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>
  <joint name="tyre_joint" type="fixed"><parent link="hub"/><child link="tyre"/></joint>
)";
  const std::string good = head + R"(  <link name="tyre"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.01"/></inertial></link>
</robot>)";
  const Scene s = loadSceneFromString(good, ".", "wheel.urdf");
  EXPECT_EQ(s.model.nv, 7);
  // A flat disk-like tyre whose moments violate I1 + I2 >= I3 even with the
  // hub: no mass distribution, but positive definite — one warning naming the
  // merged links, at the moving link's element.
  const std::string bad = head + R"(  <link name="tyre"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.05" iyz="0" izz="0.01"/></inertial></link>
</robot>)";
  const Scene t = loadSceneFromString(bad, ".", "wheel.urdf");
  ASSERT_EQ(t.warnings.size(), 1u);
  for (const char* part : {"wheel.urdf:4: <link name=\"hub\">", "combined inertia with the fixed 'tyre'",
                           "violate the triangle inequality by 60 %"})
    EXPECT_NE(t.warnings[0].find(part), std::string::npos) << part << " in " << t.warnings[0];
  // Without the tyre the hub is a point mass on its own axle: nothing resists
  // the joint's motion — refused at its <inertia>, naming the joint.
  try {
    loadSceneFromString(head.substr(0, head.find("  <joint name=\"tyre_joint\"")) + "</robot>", ".",
                        "hub.urdf");
    ADD_FAILURE() << "a point mass on a revolute joint loaded";
  } catch (const SceneError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("hub.urdf:4: <inertia>"), std::string::npos) << msg;
    EXPECT_NE(msg.find("joint 'axle' (continuous) moves no inertia"), std::string::npos) << msg;
  }
}
