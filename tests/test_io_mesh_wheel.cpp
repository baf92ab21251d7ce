// Mesh wheels (wheel_fit.hpp): a rolling contact on a link whose collision is
// a mesh rolls on the smooth shape fitted about the wheel joint's axle — the
// example's CAD-style tyre (examples/make_meshes.cpp: outer radius 0.1 m,
// tube 0.02 m) fits that torus and drives exactly as the analytic tyre does;
// a flat-treaded wheel fits a disk; an off-centre mesh shows its
// eccentricity as the deviation; appell info reports the fit.
#include <appell/appell.hpp>
#include <appell/run.hpp>
#include <appell/urdf.hpp>
#include <appell/wheel_fit.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <string>

using namespace appell;

namespace {

const std::string kDiffDrive = std::string(APPELL_SOURCE_DIR) + "/examples/diff_drive";

std::string readText(const std::string& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// diff_drive.urdf with both wheels' collision cylinders replaced by the
// visual meshes (STL left, Collada right, the axle along the mesh's y) and
// the contacts' tyre_radius removed: the tyre comes from the mesh.
std::string meshWheeledDiffDrive() {
  std::string xml = readText(kDiffDrive + "/diff_drive.urdf");
  const std::string cylinder = R"(<collision>
      <origin xyz="0 0 0" rpy="1.5707963267948966 0 0"/>
      <geometry><cylinder radius="0.1" length="0.04"/></geometry>
    </collision>)";
  for (const char* mesh : {"meshes/wheel.stl", "meshes/wheel.dae"}) {
    const auto at = xml.find(cylinder);
    if (at == std::string::npos) return "";
    xml.replace(at, cylinder.size(),
                std::string("<collision><geometry><mesh filename=\"") + mesh + "\"/></geometry></collision>");
  }
  for (std::string::size_type at; (at = xml.find(R"( tyre_radius="0.02")")) != std::string::npos;)
    xml.erase(at, std::string(R"( tyre_radius="0.02")").size());
  return xml;
}

}  // namespace

TEST(MeshWheel, TheExampleTyreFitsItsTorusAndDrivesAsTheAnalyticTyre) {
  const std::string xml = meshWheeledDiffDrive();
  ASSERT_FALSE(xml.empty());
  const Scene mesh = loadSceneFromString(xml, kDiffDrive, "mesh_wheels.urdf");
  const Scene analytic = loadScene(kDiffDrive + "/diff_drive.urdf");
  for (int k : {0, 1}) {
    const Torus* t = std::get_if<Torus>(&mesh.contacts[k]->spec().shape);
    ASSERT_NE(t, nullptr) << mesh.contact_origins[k].shape_source;
    // STL and Collada store single-precision floats: the fit is exact to that.
    EXPECT_NEAR(t->major, 0.08, 1e-7);
    EXPECT_NEAR(t->minor, 0.02, 1e-7);
    EXPECT_LT(t->centre.norm(), 1e-8);
    EXPECT_NEAR(std::abs(t->axis.y()), 1, 1e-15);
    const std::string& source = mesh.contact_origins[k].shape_source;
    EXPECT_NE(source.find("fitted torus about the joint axle: radius 0.1"), std::string::npos) << source;
    EXPECT_NE(source.find("tread vertices"), std::string::npos) << source;
  }
  RunOptions o = runOptions(analytic.settings);
  auto a = makeSimulator(analytic, o), m = makeSimulator(mesh, o);
  ASSERT_TRUE(a->advanceTo(3.0, o.dt).ok);
  ASSERT_TRUE(m->advanceTo(3.0, o.dt).ok);
  // The mesh's radii are float-rounded (5e-9 m): positions agree to ~1e-8 m,
  // the wheel angles (≈ 15 rad) to ~1e-7.
  EXPECT_LT((a->q() - m->q()).head<3>().cwiseAbs().maxCoeff(), 1e-7);
  EXPECT_LT((a->q() - m->q()).cwiseAbs().maxCoeff(), 1e-5);
  EXPECT_GT(a->q()[0], 0.1);  // and it drove
}

// A cylinder as a CAD mesh (a 24-gon prism about the axle x): the tread is
// flat, the fit a disk of the circumradius in the mid-plane; shifted 1 mm off
// the axle, the same mesh reports ~1 mm of deviation (its eccentricity).
TEST(MeshWheel, FlatTreadFitsADiskAndEccentricityShowsAsDeviation) {
  std::vector<Vec3> v;
  const double R = 0.3, w = 0.1;
  for (int s = 0; s < 24; ++s) {
    const double th = 2 * std::numbers::pi * s / 24;
    for (double x : {0.2, 0.2 + w}) v.emplace_back(x, R * std::cos(th), R * std::sin(th));
  }
  v.emplace_back(0.2, 0, 0);
  v.emplace_back(0.2 + w, 0, 0);
  const WheelFit f = fitWheel(v, Vec3::Zero(), Vec3::UnitX());
  ASSERT_FALSE(f.torus);
  const Disk& d = std::get<Disk>(f.shape);
  EXPECT_NEAR(d.radius, R, 1e-15);
  EXPECT_NEAR(d.centre.x(), 0.25, 1e-15);
  EXPECT_LT(d.centre.tail<2>().norm(), 1e-15);
  EXPECT_LT(f.max_deviation, 1e-15);
  EXPECT_EQ(f.tread_vertices, 48);
  for (Vec3& p : v) p.y() += 1e-3;
  const WheelFit off = fitWheel(v, Vec3::Zero(), Vec3::UnitX());
  EXPECT_GT(off.max_deviation, 1.9e-3);  // 2 mm between the near and far sides
  EXPECT_LT(off.max_deviation, 2.1e-3);
  EXPECT_THROW(fitWheel({Vec3(1, 0, 0), Vec3(2, 0, 0), Vec3(3, 0, 0)}, Vec3::Zero(), Vec3::UnitX()),
               std::invalid_argument);  // on the axle
}

namespace {

// A regular N-gon prism about the axle x (radius R, width w), moved by `offset`.
std::vector<Vec3> prism(int sides, double R, double w, const Vec3& offset = Vec3::Zero()) {
  std::vector<Vec3> v;
  for (int s = 0; s < sides; ++s) {
    const double th = 2 * std::numbers::pi * s / sides;
    for (double x : {-w / 2, w / 2}) v.push_back(Vec3(x, R * std::cos(th), R * std::sin(th)) + offset);
  }
  return v;
}

}  // namespace

// The wheel rule (wheel_fit.hpp): the runout of a regular N-gon is its chord
// sag R(1 − cos π/N) exactly; 2 % of R admits 16 sides (1.92 %) and refuses
// 12 (3.41 %); an axle off centre adds about twice its eccentricity; a boot
// about its ankle (the corpus's foot) is far out of round.
TEST(MeshWheel, AWheelIsRoundToTwoPercentOfItsRadius) {
  const double R = 0.1;
  for (int n : {12, 16, 24, 48}) {
    const WheelFit f = fitWheel(prism(n, R, 0.03), Vec3::Zero(), Vec3::UnitX());
    EXPECT_NEAR(f.runout, R * (1 - std::cos(std::numbers::pi / n)), 1e-15) << n << " sides";
    EXPECT_EQ(isWheel(f), n >= 16) << n << " sides";
  }
  // Off centre by e: the far vertex is at R + e, the nearest edge at
  // (R − e) cos(π/48) — the runout is the sag plus e (1 + cos π/48) ≈ 2e,
  // an engineer's total runout. e = 0.5 % of R is a wheel, 1 % is not.
  const double c48 = std::cos(std::numbers::pi / 48);
  for (double e : {0.005 * R, 0.01 * R}) {
    const WheelFit off = fitWheel(prism(48, R, 0.03, Vec3(0, e, 0)), Vec3::Zero(), Vec3::UnitX());
    EXPECT_NEAR(off.runout, R * (1 - c48) + e * (1 + c48), 1e-15) << e;
    EXPECT_EQ(isWheel(off), e < 0.01 * R) << e;
  }
  // The boot of tests/data/published (make_meshes.py) about its ankle axis y.
  const std::vector<Vec3> boot = {{-0.08, -0.05, -0.1}, {0.14, -0.05, -0.1}, {0.14, 0.05, -0.1},
                                  {-0.08, 0.05, -0.1},  {-0.04, -0.04, 0.03}, {0.04, -0.04, 0.03},
                                  {0.04, 0.04, 0.03},   {-0.04, 0.04, 0.03}};
  const WheelFit foot = fitWheel(boot, Vec3::Zero(), Vec3::UnitY());
  EXPECT_GT(foot.runout, 0.5 * foot.outer_radius);
  EXPECT_FALSE(isWheel(foot));
}

// A sliding contact on a mesh is not a wheel: it touches with the vertices.
TEST(MeshWheel, OnlyRollingContactsOnRevoluteJointsAreFitted) {
  std::string xml = meshWheeledDiffDrive();
  const std::string rolling = R"(name="left_tyre" link="left_wheel" kind="rolling")";
  xml.replace(xml.find(rolling), rolling.size(), R"(name="left_tyre" link="left_wheel" kind="sliding")");
  LoadOptions o;
  o.check_initial_state = false;
  const Scene s = loadSceneFromString(xml, kDiffDrive, "mesh_wheels.urdf", o);
  EXPECT_FALSE(s.vertex_groups.empty());
  EXPECT_EQ(s.vertex_groups[0].name, "left_tyre");
}
