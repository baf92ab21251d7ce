// A robot as a ROS 2 package installs it (examples/ros2_ws/install/rover,
// walked through in docs/ros-package.md): found through AMENT_PREFIX_PATH,
// its massless and mass="0" fixed links merged with exact combined inertia,
// its CAD tyre meshes fitted as tori, its URDF effort limits bounding the
// wheel servos — and it drives the manoeuvre the servos command.
#include <appell/appell.hpp>
#include <appell/run.hpp>
#include <appell/urdf.hpp>

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

using namespace appell;

namespace {

const std::string kPrefix = std::string(APPELL_SOURCE_DIR) + "/examples/ros2_ws/install/rover";
const std::string kUrdf = kPrefix + "/share/rover/urdf/rover.urdf";

// AMENT_PREFIX_PATH as `source install/setup.bash` sets it (one prefix per
// package in colcon's default isolated layout), for the test's duration.
struct AmentPrefix {
  AmentPrefix() { ::setenv("AMENT_PREFIX_PATH", kPrefix.c_str(), 1); }
  ~AmentPrefix() { ::unsetenv("AMENT_PREFIX_PATH"); }
};

}  // namespace

TEST(RosPackage, RoverLoadsThroughAmentPrefixPathWithExactMergedInertia) {
  {
    // Without the prefix, package://rover is not found, and the error says where it looked.
    try {
      loadScene(kUrdf);
      FAIL() << "loaded without AMENT_PREFIX_PATH";
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find("package 'rover' not found"), std::string::npos) << e.what();
    }
  }
  AmentPrefix env;
  const Scene s = loadScene(kUrdf);
  const Model& m = s.model;
  EXPECT_EQ(m.nv, 8);  // floating base + two wheels
  const std::vector<RigidGroup> groups = rigidGroups(m);
  const RigidGroup* base = nullptr;
  for (const RigidGroup& g : groups)
    if (m.body_names[g.body] == "base_footprint") base = &g;
  ASSERT_NE(base, nullptr);
  EXPECT_EQ(base->fixed.size(), 4u);  // base_link, laser_link, imu_link, caster_link
  // By hand, in base_footprint's frame: base_link's 4 kg at (−0.05, 0, 0.15),
  // the caster's 0.1 kg at (−0.25, 0, 0.05); the laser and IMU carry nothing.
  EXPECT_NEAR(base->inertia.mass, 4.1, 1e-14);
  EXPECT_NEAR(base->inertia.com.x(), (4 * -0.05 + 0.1 * -0.25) / 4.1, 1e-14);
  EXPECT_NEAR(base->inertia.com.z(), (4 * 0.15 + 0.1 * 0.05) / 4.1, 1e-14);
  // Parallel axes about the combined centre: I_yy = Σ (I_yy,i + m_i (dx² + dz²)).
  const Vec3 c = base->inertia.com;
  auto shifted = [&](double mass, double x, double z) {
    return mass * ((x - c.x()) * (x - c.x()) + (z - c.z()) * (z - c.z()));
  };
  EXPECT_NEAR(base->inertia.inertia_com(1, 1),
              0.0566666666666667 + shifted(4, -0.05, 0.15) + 0.0001 + shifted(0.1, -0.25, 0.05), 1e-14);
  for (int k : {0, 1}) {
    const Torus* t = std::get_if<Torus>(&s.contacts[k]->spec().shape);
    ASSERT_NE(t, nullptr) << s.contact_origins[k].shape_source;
    EXPECT_NEAR(t->major + t->minor, 0.1, 1e-7);
    EXPECT_NEAR(t->minor, 0.02, 1e-7);
  }
  ASSERT_EQ(s.actuators.size(), 2u);
  EXPECT_EQ(s.actuators[0].effort_limit, 0.5);  // the URDF's <limit effort="0.5">
}

// The servos' schedule: 0.5 m/s straight for 3 s, then a left turn held to
// t = 8 s. Straight: heading and lateral offset zero, speed 0.5 to 1e-8.
// Turning: a steady circle whose speed and yaw rate follow the wheel rates
// by rolling, about the commanded radius 0.36 m (the servos' steady error
// makes the yaw moment the offset centre of mass needs, as in
// test_actuators.cpp).
TEST(RosPackage, RoverDrivesTheCommandedStraightLineAndCircle) {
  AmentPrefix env;
  const Scene s = loadScene(kUrdf);
  const RunOptions o = runOptions(s.settings);
  auto sim = makeSimulator(s, o);
  const Model& m = s.model;
  Data data(m);
  const int base = m.bodyIndex("base_footprint");
  const int wl = m.joints[m.jointIndex("left_wheel_joint")].idx_v;
  const int wr = m.joints[m.jointIndex("right_wheel_joint")].idx_v;
  auto state = [&]() {
    forwardKinematics(m, data, sim->q(), sim->v());
    const double yaw = (data.oMi[base].R * data.v[base].head<3>()).z();
    return std::array<double, 4>{data.v[base].tail<3>().norm(), yaw, sim->v()[wl], sim->v()[wr]};
  };
  ASSERT_TRUE(sim->advanceTo(3.0, o.dt).ok);
  const auto s3 = state();
  EXPECT_NEAR(s3[0], 0.5, 1e-8);  // the fitted radius is the float mesh's, 0.1 to 5e-9
  EXPECT_NEAR(s3[1], 0, 1e-11);
  EXPECT_NEAR(sim->q()[1], 0, 1e-11);
  EXPECT_GT(sim->q()[0], 1.3);  // ~1.5 m less the spin-up
  ASSERT_TRUE(sim->advanceTo(8.0, o.dt).ok);
  const auto s8 = state();
  const double r = 0.1, b = 0.18;
  EXPECT_NEAR(s8[0], r * (s8[2] + s8[3]) / 2, 1e-8);  // rolling (radius fitted to 5e-9)
  EXPECT_NEAR(s8[1], r * (s8[3] - s8[2]) / (2 * b), 1e-7);
  EXPECT_NEAR(s8[0] / s8[1], 0.36, 0.02 * 0.36);
}
