// Robot descriptions as they are published (tests/data/published/README.md):
// each loads — with exactly the warnings its tolerated shapes earn — or is
// refused with a message saying what to write instead. Feet stand on their
// soles by one declaration, shape="collision"; a mesh is rolled on as a
// wheel only when it is round; a scene that predates a convention change is
// read as written when it says its format, and warned about when it does not.
#include <appell/appell.hpp>
#include <appell/run.hpp>
#include <appell/urdf.hpp>

#include "scene_helpers.hpp"
#include "simulation_helpers.hpp"
#include "scoped_env.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <numbers>
#include <set>
#include <string>

using namespace appell;

namespace {

constexpr double kG = 9.81;
const std::string kPublished = std::string(APPELL_SOURCE_DIR) + "/tests/data/published";
const std::string kBiped = kPublished + "/ros1/src/humanoids/biped/biped_description/urdf/biped.urdf";
const std::string kCartPrefix = kPublished + "/ament/install/cart_description";
const std::string kCart = kCartPrefix + "/share/cart_description/urdf/cart_description.urdf";

using test::ScopedEnv;

std::string readText(const std::string& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "no '" << from << "' to replace";
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

double normalForceSum(const Simulator& sim) {
  double sum = 0;
  const ConstraintData& cd = sim.constraintData();
  for (int c = 0; c < static_cast<int>(sim.constraints().size()); ++c)
    if (sim.isClosed(c)) sum += sim.lambda()[cd.offset[c] + sim.constraints()[c]->unilateralRow()];
  return sum;
}

}  // namespace

// xacro output of a ROS 1 package three folders below its ROS_PACKAGE_PATH
// entry: the namespaces on <robot> are no xacro; package:/// is read as
// package://; the <mimic> of a fixed gripper joint is ignored; the head's
// collision mesh the package does not ship is left out (no contact uses
// it). One line each, in the order the loader meets them, with the line.
TEST(Published, XacroOutputOfARos1PackageLoadsWithOneWarningPerTolerance) {
  ScopedEnv env("ROS_PACKAGE_PATH", kPublished + "/ros1/src");
  const Scene s = loadScene(kBiped);
  EXPECT_EQ(s.model.nv, 6 + 6);  // floating base, hips, knees, ankles
  ASSERT_EQ(s.warnings.size(), 3u);
  EXPECT_EQ(s.warnings[0], kBiped + ":106: <mimic>: a fixed joint moves nothing: its <mimic> of "
                                    "'gripper_joint' is ignored");
  EXPECT_EQ(s.warnings[1],
            kBiped + ":50: <mesh>: 'package:///biped_description/meshes/torso.stl' read as "
                     "'package://biped_description/meshes/torso.stl' (a package URI has two slashes "
                     "before the package name) (and 7 more mesh URIs like it)");
  EXPECT_TRUE(contains(s.warnings[2], kBiped + ":83: <mesh>: mesh "
                                               "'package:///biped_description/meshes/head_collision.stl': "
                                               "file not found: "))
      << s.warnings[2];
  EXPECT_TRUE(contains(s.warnings[2], "collision of link 'head_link', which no contact takes its shape "
                                      "from: left out"))
      << s.warnings[2];
  // The meshes the package ships were found through the 3-level layout.
  const LinkGeometry& torso = s.geometry[s.model.bodyIndex("torso_link")];
  ASSERT_EQ(torso.collision.size(), 1u);
  EXPECT_TRUE(contains(torso.collision[0].mesh_path, "humanoids/biped/biped_description/meshes/torso.stl"));
  EXPECT_TRUE(s.geometry[s.model.bodyIndex("head_link")].collision.empty());
  // Each foot on its sole, one line each: the box's 8 corners.
  ASSERT_EQ(s.vertex_groups.size(), 2u);
  for (const VertexGroup& g : s.vertex_groups) {
    EXPECT_EQ(g.count, 8);
    EXPECT_TRUE(std::holds_alternative<Box>(g.shape));
  }
  EXPECT_EQ(s.contact_origins[0].shape_source, "collision[0] (box), as a sole, vertex 0");
  // Standing: the four lower corners of each sole on the floor, closed.
  const std::unique_ptr<Simulator> sim = makeSimulator(s, runOptions(s.settings));
  EXPECT_EQ(sim->constraintData().m_active, 2 * 4 * 3) << "4 corners × 3 rows per sole";
}

// The same foot's mesh about its ankle is no wheel: a rolling contact on it
// is refused — its runout is most of its radius — with what to write; as a
// sole it touches with the 8 vertices of its hull.
TEST(Published, AnAnkleMeshIsNoWheelAndStandsAsASole) {
  ScopedEnv env("ROS_PACKAGE_PATH", kPublished + "/ros1/src");
  const std::string xml = readText(kBiped);
  const std::string base = kPublished + "/ros1/src/humanoids/biped/biped_description/urdf";
  const std::string as_wheel =
      replaced(xml, R"(link="left_sole_link" shape="collision")", R"(link="left_ankle_link")");
  const std::string e = test::loadMessage(as_wheel, "biped.urdf");
  EXPECT_TRUE(contains(e, "biped.urdf:305: <contact name=\"left_foot\">: collision[0] (mesh), fitted ")) << e;
  EXPECT_TRUE(contains(e, ": not a wheel — the runout of a wheel")) << e;
  EXPECT_TRUE(contains(e, "stay within 2 % of its radius")) << e;
  EXPECT_TRUE(contains(e, "A foot or a sole: write shape=\"collision\"")) << e;
  const std::string as_sole =
      replaced(xml, R"(link="left_sole_link" shape="collision")", R"(link="left_ankle_link" shape="collision")");
  LoadOptions o;
  o.check_initial_state = false;
  const Scene s = loadSceneFromString(as_sole, base, "biped.urdf", o);
  EXPECT_EQ(s.vertex_groups[0].count, 8) << "the boot's 8 hull vertices";
  EXPECT_TRUE(std::holds_alternative<Mesh>(s.vertex_groups[0].shape));
}

// A SolidWorks export under a ROS 2 install prefix: binary STL files named
// .STL whose header starts with "solid", <material name="">, mass-0 sensor
// frames, continuous joints with <limit effort="0" velocity="0">, inertias
// with 1e-20 off-diagonal noise. Nothing in it needs a tolerance: it loads
// without a warning, the STL wheels fit disks of the 0.08 m radius, and
// driven by 0.05 N·m per wheel it accelerates as the closed form says:
// a = (2τ/r) / (m + 2 I_w/r²) with m = 6.1 kg, I_w = 0.0016 kg m².
TEST(Published, ASolidWorksExportUnderAnAmentPrefixLoadsSilentlyAndDrives) {
  ScopedEnv env("AMENT_PREFIX_PATH", kCartPrefix);
  const Scene s = loadScene(kCart);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
  for (int k : {0, 1}) {
    const Disk* d = std::get_if<Disk>(&s.contacts[k]->spec().shape);
    ASSERT_NE(d, nullptr) << s.contact_origins[k].shape_source;
    EXPECT_NEAR(d->radius, 0.08, 1e-8);  // single-precision STL
    EXPECT_TRUE(contains(s.contact_origins[k].shape_source, "fitted disk about the joint axle"));
  }
  const std::vector<RigidGroup> groups = rigidGroups(s.model);
  double mass = 0;
  for (const RigidGroup& g : groups) mass += g.inertia.mass;
  EXPECT_NEAR(mass, 6.1, 1e-12);
  const RunOptions o = runOptions(s.settings);
  const std::unique_ptr<Simulator> sim = makeSimulator(s, o);
  ASSERT_TRUE(sim->advanceTo(1.0, o.dt).ok);
  const double a = (2 * 0.05 / 0.08) / (6.1 + 2 * 0.0016 / (0.08 * 0.08));
  EXPECT_NEAR(sim->q()[0], 0.5 * a, 1e-6) << "x after 1 s";
  // Straight: the exporter's rpy="-1.5708" tilts both axles by 3.7e-6 rad.
  EXPECT_LT(std::abs(sim->q()[1]), 1e-6) << "straight";
}

// shape="collision" on each kind of collision geometry: a box's 8 corners, a
// cylinder standing on an end (two rims of 16 vertices), a sphere itself.
// The standing cylinder dropped from 0.1 m lands on its 16 lower rim
// vertices at once at √(2h/g) and rests with their loads summing to m g.
TEST(Published, ASoleIsTheCollisionGeometryByOneDeclaration) {
  auto scene = [](const std::string& geometry, const std::string& contact) {
    return R"(<?xml version="1.0"?>
<robot name="foot">
  <link name="foot">
    <inertial><mass value="0.5"/><inertia ixx="0.002" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.003"/></inertial>
    )" + geometry + R"(
  </link>
  <appell format="2">
    <support name="floor" type="plane"/>
    )" + contact + R"(
    <initial><joint name="root_joint" xyz="0 0 0.12"/></initial>
  </appell>
</robot>)";
  };
  const std::string sole = R"(<contact name="sole" link="foot" shape="collision" kind="sliding" support="floor"/>)";
  const std::string box = R"(<collision><geometry><box size="0.2 0.1 0.04"/></geometry></collision>)";
  const std::string cylinder = R"(<collision><geometry><cylinder radius="0.1" length="0.04"/></geometry></collision>)";
  const std::string sphere = R"(<collision name="ball"><geometry><sphere radius="0.02"/></geometry></collision>)";
  EXPECT_EQ(loadSceneFromString(scene(box, sole), ".").contacts.size(), 8u);
  EXPECT_EQ(loadSceneFromString(scene(sphere, sole), ".").vertex_groups.size(), 0u);
  const Scene s = loadSceneFromString(scene(cylinder, sole), ".");
  ASSERT_EQ(s.contacts.size(), 32u);
  EXPECT_EQ(s.contact_origins[0].shape_source, "collision[0] (cylinder), as a sole, vertex 0");
  Simulator sim(s.model, s.constraints, makeSolver(Formulation::Multipliers, s.model, s.constraints),
                IntegratorType::DormandPrince54, test::tightIntegrator());
  ASSERT_TRUE(sim.setState(0, s.q0, s.v0)) << sim.lastStateError();
  const auto events = test::advanceCollecting(sim, 0.5);
  ASSERT_EQ(events.size(), 16u) << "the lower rim's 16 vertices";
  for (const ContactEvent& e : events) EXPECT_NEAR(e.t, std::sqrt(2 * 0.1 / kG), 1e-10);
  EXPECT_NEAR(sim.q()[2], 0.02, 1e-9);
  EXPECT_NEAR(normalForceSum(sim), 0.5 * kG, 1e-8);
  // rim_points still sets the polygons.
  EXPECT_EQ(loadSceneFromString(scene(cylinder, replaced(sole, "/>", R"( rim_points="6"/>)")), ".").contacts.size(),
            12u);
  // Two geometries: the sole is named; without a name the error lists them.
  const std::string two = box + "\n" + sphere;
  const std::string e = test::loadMessage(scene(two, sole), "foot.urdf");
  EXPECT_TRUE(contains(e, "foot.urdf:10: <contact name=\"sole\">: link 'foot' has 2 collision geometries: say "
                          "which one is the sole with collision=\"NAME\" or collision=\"INDEX\" "
                          "(collision[0] (box), collision[1] (sphere 'ball'))"))
      << e;
  EXPECT_EQ(loadSceneFromString(scene(two, replaced(sole, "/>", R"( collision="0"/>)")), ".").contacts.size(), 8u);
  // A wheel's attribute does not apply to a sole.
  EXPECT_TRUE(contains(test::loadMessage(scene(cylinder, replaced(sole, "/>", R"( tyre_radius="0.01"/>)")), "f"),
                       "attribute 'tyre_radius' does not apply to shape=\"collision\""));
}

// The shapes that only a collision geometry can give are refused in the
// block with what to write instead.
TEST(Published, ABoxDeclaredInTheBlockSaysToUseTheCollisionGeometry) {
  const std::string xml = R"(<robot name="r">
<link name="foot"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
<appell><support name="floor"/>
<contact name="sole" link="foot" shape="box" size="0.2 0.1 0.02" support="floor"/>
</appell></robot>)";
  EXPECT_EQ(test::loadMessage(xml, "r.urdf"),
            "r.urdf:4: <contact name=\"sole\">: shape 'box' is not declared in the <appell> block (a box "
            "cannot roll: its faces and edges give no unique smooth contact point): a box "
            "touches with its vertices, taken from the collision geometry of the link — give the link "
            "<collision><geometry><box …/></geometry></collision> and write shape=\"collision\" "
            "(collision=\"NAME\" picks one of several)");
}

namespace {

// A puck on a planar joint (normal z) with its in-plane position, velocity
// and push given in the block, in the format `format` ("" for none).
std::string planarPuck(const std::string& format) {
  return R"(<robot name="puck">
<link name="world"/>
<link name="puck"><inertial><mass value="2"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.02"/></inertial></link>
<joint name="slide" type="planar"><parent link="world"/><child link="puck"/><axis xyz="0 0 1"/></joint>
<appell)" + (format.empty() ? "" : " format=\"" + format + "\"") +
         R"(><gravity xyz="0 0 0"/>
<initial><joint name="slide" position="1 0.5 0.3" velocity="2 0 0.1"/></initial>
<effort joint="slide" value="0 3 0"/>
</appell></robot>)";
}

}  // namespace

// Format 1 → 2 (commit 44be170): the planar joint's in-plane axes were
// t₁ = −y, t₂ = x (normal z) and are now x, y. Format 1 reads its numbers
// as they were meant: the state and force turned by C = [0 1; −1 0]
// (x_new = C x_old) — the same physical scene as format 2's numbers turned
// by hand; no format is read as format 2 with a warning giving both meanings.
TEST(Published, APlanarSceneSaysItsFormatOrIsWarnedWithBothMeanings) {
  const Scene v2 = loadSceneFromString(planarPuck("2"), ".", "puck.urdf");
  EXPECT_TRUE(v2.warnings.empty());
  EXPECT_TRUE(v2.q0.isApprox(Eigen::Vector3d(1, 0.5, 0.3)));
  const Scene none = loadSceneFromString(planarPuck(""), ".", "puck.urdf");
  EXPECT_EQ(none.q0, v2.q0);
  ASSERT_EQ(none.warnings.size(), 1u);
  EXPECT_EQ(none.warnings[0],
            "puck.urdf:5: <appell>: no format given, read as format=\"2\": planar joint 'slide' moves along "
            "t1 = (1 0 0), t2 = (0 1 0) of its joint frame (<initial>, <effort> and the CSV columns .x .y, .vx .vy); "
            "scenes written before format 2 meant t1 = (0 -1 0), t2 = (1 0 0) — write <appell format=\"2\"> "
            "to keep the new meaning, format=\"1\" to read the old one");
  const Scene v1 = loadSceneFromString(planarPuck("1"), ".", "puck.urdf");
  EXPECT_TRUE(v1.warnings.empty());
  EXPECT_NEAR(v1.q0[0], 0.5, 1e-15);   // 1 along −y and 0.5 along x
  EXPECT_NEAR(v1.q0[1], -1, 1e-15);
  EXPECT_NEAR(v1.q0[2], 0.3, 1e-15);   // the angle is the same
  EXPECT_NEAR(v1.v0[0], 0, 1e-15);
  EXPECT_NEAR(v1.v0[1], -2, 1e-15);
  EXPECT_NEAR(v1.tau[0], 3, 1e-15);
  EXPECT_NEAR(v1.tau[1], 0, 1e-15);
  EXPECT_TRUE(contains(test::loadMessage(planarPuck("3"), "puck.urdf"),
                       "puck.urdf:5: <appell>: format \"3\" is not known"));
}
