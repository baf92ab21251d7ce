// Bad input: every case gives a SceneError naming the file, the element
// (with its line where the XML parser knows it) and the reason — and no
// partial scene.
#include <appell/urdf.hpp>

#include "scene_helpers.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <regex>

#include <unistd.h>

using namespace appell;

namespace {

const std::string kBad = std::string(APPELL_SOURCE_DIR) + "/tests/data/io/bad/";

// Loads `file` and returns the SceneError message (fails if it loads).
std::string errorOf(const std::string& file, const LoadOptions& options = {}) {
  try {
    const Scene s = loadScene(kBad + file, options);
    ADD_FAILURE() << file << " loaded (" << s.model.nbodies << " bodies) but should not";
  } catch (const SceneError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << file << ": not a SceneError: " << e.what();
  }
  return "";
}

// The message starts with the file and, when `line` > 0, that line; it
// contains each of `parts`.
void expectError(const std::string& file, int line, const std::vector<std::string>& parts,
                 const LoadOptions& options = {}) {
  const std::string msg = errorOf(file, options);
  const std::string where = kBad + file + (line > 0 ? ":" + std::to_string(line) + ":" : ":");
  EXPECT_EQ(msg.rfind(where, 0), 0u) << "message does not start with " << where << ":\n  " << msg;
  for (const auto& p : parts)
    EXPECT_NE(msg.find(p), std::string::npos) << "missing \"" << p << "\" in:\n  " << msg;
}

std::string messageOf(const std::string& xml, const std::string& name) {
  return test::loadMessage(xml, name);
}

}  // namespace

TEST(IoErrors, MalformedXml) {
  expectError("malformed.urdf", 0, {"malformed XML"});
  // The parser's line and column follow the file name.
  EXPECT_TRUE(std::regex_search(errorOf("malformed.urdf"), std::regex("malformed\\.urdf:[0-9]+:[0-9]+: ")));
}

TEST(IoErrors, UnknownLinkInSceneBlock) {
  expectError("unknown_link.urdf", 6, {"<contact name=\"foot\">", "unknown link 'bal'"});
}

TEST(IoErrors, UnknownJointInSceneBlock) {
  expectError("unknown_joint.urdf", 6, {"<joint name=\"root_jiont\">", "unknown joint 'root_jiont'"});
}

TEST(IoErrors, ZeroAndNegativeMass) {
  // mass="0" is a massless link; a moving one that carries nothing is refused.
  expectError("zero_mass.urdf", 3, {"<link name=\"body\">", "joint 'root_joint' (floating) moves no inertia",
                                    "have zero mass"});
  expectError("negative_mass.urdf", 5, {"<mass>", "mass must not be negative, got -2"});
}

TEST(IoErrors, InertiaNotPositiveDefinite) {
  expectError("inertia_not_pd.urdf", 6, {"<inertia>", "not positive semi-definite"});
}

// Principal moments that break the triangle inequality (CAD rounding; here by
// 60 %) are no mass distribution, but the dynamics run: a warning, not an
// error (tests/test_io_inertia.cpp has the cases as published).
TEST(IoErrors, InertiaViolatingTheTriangleInequalityIsAWarning) {
  const Scene s = loadScene(kBad + "inertia_triangle.urdf");
  ASSERT_EQ(s.warnings.size(), 1u);
  for (const char* part : {"inertia_triangle.urdf:3: <link name=\"body\">",
                           "principal moments 0.1 0.1 0.5 violate the triangle inequality by 60 %"})
    EXPECT_NE(s.warnings[0].find(part), std::string::npos) << part << " in " << s.warnings[0];
}

// A collision mesh a contact takes its shape from must load.
TEST(IoErrors, MissingMeshFile) {
  expectError("missing_mesh.urdf", 6, {"<mesh>", "meshes/does_not_exist.stl", "file not found"});
}

// A collision mesh no contact uses is never read by the dynamics: missing,
// it is left out with one warning for the file (the first, and the count),
// as urdfdom loads such a package; used by a contact, the same file is the
// error above. loadUrdfModel (no contacts) loads it too.
TEST(IoErrors, MissingCollisionMeshNoContactUsesIsAWarning) {
  const std::string bad = kBad + "missing_mesh.urdf";
  std::ifstream in(bad);
  std::string xml{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  const auto block = xml.find("  <!-- the contact");
  xml.erase(block, xml.find("</robot>") - block);
  xml.replace(xml.find("</link>"), 7,
              "<collision><geometry><mesh filename=\"meshes/also_absent.stl\"/></geometry></collision></link>");
  const Scene s = loadSceneFromString(xml, kBad, "unused.urdf");
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0].rfind("unused.urdf:6: <mesh>: mesh 'meshes/does_not_exist.stl': file not found: ", 0), 0u)
      << s.warnings[0];
  EXPECT_NE(s.warnings[0].find("collision of link 'body', which no contact takes its shape from: left out "
                               "(and 1 more collision meshes no contact uses)"),
            std::string::npos)
      << s.warnings[0];
  EXPECT_TRUE(s.geometry[0].collision.empty());
  EXPECT_EQ(loadUrdfModel(bad).nbodies, 1);
}

// A visual mesh only draws the link: when it is missing the scene loads,
// without it, and says so (file, line, element, path) in Scene::warnings.
TEST(IoErrors, MissingVisualMeshIsAWarning) {
  const std::string urdf = R"(<?xml version="1.0"?>
<robot name="r">
  <link name="body">
    <inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
    <visual><geometry><mesh filename="package://absent_pkg/meshes/body.dae"/></geometry></visual>
    <visual><geometry><box size="1 1 1"/></geometry></visual>
  </link>
</robot>)";
  LoadOptions opt;
  opt.use_ros_package_path = false;
  const Scene s = loadSceneFromString(urdf, ".", "visual.urdf", opt);
  ASSERT_EQ(s.warnings.size(), 1u);
  const std::string& w = s.warnings[0];
  for (const char* part : {"visual.urdf:5:", "<mesh>", "package 'absent_pkg' not found", "visual only"})
    EXPECT_NE(w.find(part), std::string::npos) << part << " in " << w;
  ASSERT_EQ(s.geometry.size(), 1u);
  ASSERT_EQ(s.geometry[0].visual.size(), 1u);  // the box is kept
  EXPECT_EQ(s.geometry[0].visual[0].type, GeometryType::Box);
  EXPECT_DOUBLE_EQ(s.model.totalMass(), 1.0);
}

TEST(IoErrors, MeshWithNoTriangles) {
  expectError("empty_mesh.urdf", 6, {"<mesh>", "lines_only.obj", "no triangles"});
}

TEST(IoErrors, NonFiniteAndUnparsableNumbers) {
  expectError("nan_number.urdf", 7, {"<origin>", "attribute 'xyz'", "\"nan\" is not finite"});
  expectError("inf_number.urdf", 4, {"<mass>", "\"inf\" is not finite"});
  expectError("unparsable_number.urdf", 7, {"<axis>", "\"zero\" is not a number"});
}

TEST(IoErrors, DisconnectedLinksAndTwoParents) {
  expectError("disconnected.urdf", 4, {"<link name=\"b\">", "disconnected", "'a' and 'b'"});
  expectError("two_parents.urdf", 8, {"<joint name=\"bc\">", "link 'c' has two parents", "'ac'"});
  expectError("cycle.urdf", 4, {"<link name=\"b\">", "not connected to the root 'root'"});
}

TEST(IoErrors, UnsupportedJointType) {
  expectError("unsupported_joint.urdf", 5, {"<joint name=\"shoulder\">", "unsupported joint type 'spherical'"});
}

TEST(IoErrors, UrdfVersionOtherThan1_0) {
  // URDF 1.0 is the only version; a malformed or other version is rejected
  // (as urdfdom, the ROS parser, rejects it), with the line of <robot>.
  expectError("bad_version.urdf", 2, {"<robot name=\"r\">", "version \"1.x\"", "<major>.<minor>"});
}

TEST(IoErrors, ElementsTheModelIgnoresAreStillChecked) {
  // A URDF this loader accepts is a URDF ROS tools accept: <limit> needs
  // effort and velocity, <dynamics> damping or friction, a material a colour.
  expectError("limit_no_effort.urdf", 8, {"<limit>", "missing attribute 'effort'"});
  expectError("dynamics_empty.urdf", 9, {"<dynamics>", "needs 'damping' or 'friction'"});
  expectError("material_undefined.urdf", 3, {"<material name=\"grey\">", "<color rgba>"});
}

TEST(IoErrors, KnifeEdgeOnABox) {
  // A box touches with its corners (points): sliding or sticking, no blade.
  expectError("box_contact.urdf", 9, {"<contact name=\"bottom\">", "collision[0] (box)",
                                      "a box touches with its vertices", "not 'knife_edge'"});
}

TEST(IoErrors, KnifeEdgeWithoutDirection) {
  expectError("knife_no_direction.urdf", 8, {"<contact name=\"blade\">", "needs a blade 'direction'"});
}

TEST(IoErrors, InitialStateViolatesTheConstraints) {
  // The ball touches the plane sliding at 1 m/s: the rolling rows' velocity
  // residual is 1. (A ball above the plane is fine: its contact starts open.)
  expectError("initial_violation.urdf", 0, {"initial state violates the constraints",
                                            "contact 'foot'", "appell --project-initial"});
  const std::string msg = errorOf("initial_violation.urdf");
  EXPECT_NE(msg.find("velocity residual |A v + b| = 1 "), std::string::npos) << msg;
}

TEST(IoErrors, InitialPenetrationNamesTheContact) {
  // The ball's centre is 0.07 m above the plane, radius 0.1: 3 cm in the ground.
  expectError("initial_penetration.urdf", 0, {"contact 'foot' penetrates its support by 0.03",
                                              "appell --project-initial"});
}

TEST(IoErrors, TerrainMeshWithADegenerateTriangle) {
  // Terrains load now (tests/test_contact_terrain.cpp); a bad mesh names its triangle.
  expectError("../../terrain/degenerate.urdf", 5,
              {"<support name=\"hills\">", "triangle 1", "is degenerate", "degenerate.obj"});
}

TEST(IoErrors, MissingFile) {
  EXPECT_THROW(loadScene(kBad + "no_such_file.urdf"), SceneError);
}

TEST(IoErrors, MisspeltAttributeInSceneBlock) {
  // A misspelt attribute would otherwise be ignored (here: a sphere of radius 0).
  expectError("unknown_attribute.urdf", 6, {"<contact name=\"foot\">", "attribute 'raduis' does not apply to shape=\"sphere\""});
}

TEST(IoErrors, RestitutionOutsideZeroOneNamesTheContact) {
  expectError("restitution_range.urdf", 6, {"<contact name=\"foot\">", "restitution must lie in [0, 1]"});
}

TEST(IoErrors, UnilateralMustBeTrueOrFalse) {
  expectError("unilateral_value.urdf", 6, {"<contact name=\"foot\">", "'unilateral' must be \"true\""});
}

// Bounded reading (issue 17): what is not a scene file is named as such,
// never read until memory runs out or parsed into "document empty".
TEST(IoErrors, DevicesDirectoriesAndUtf16AreNamed) {
  auto message = [](const std::string& path) {
    try {
      loadScene(path);
    } catch (const SceneError& e) {
      return std::string(e.what());
    }
    return std::string("(loaded)");
  };
  if (std::filesystem::exists("/dev/zero")) {
    EXPECT_NE(message("/dev/zero").find("/dev/zero: not a regular file"), std::string::npos);
  }
  const std::filesystem::path dir = std::filesystem::temp_directory_path();
  EXPECT_NE(message(dir.string()).find("is a directory"), std::string::npos);
  const std::string u16 = (dir / ("appell_u16_" + std::to_string(::getpid()) + ".urdf")).string();
  {
    std::ofstream out(u16, std::ios::binary);
    const char bytes[] = {'\xff', '\xfe', '<', 0, 'r', 0, 'o', 0};
    out.write(bytes, sizeof bytes);
  }
  EXPECT_NE(message(u16).find("UTF-16"), std::string::npos) << message(u16);
  std::filesystem::remove(u16);
}

TEST(IoErrors, DeepNestingLongValuesAndHugeNumbersAreNamed) {
  auto message = [](const std::string& xml) { return messageOf(xml, "gen.urdf"); };
  // 10⁵ levels: refused before the (recursive) parser sees them.
  std::string deep = "<robot name=\"r\">";
  for (int i = 0; i < 100000; ++i) deep += "<a>";
  for (int i = 0; i < 100000; ++i) deep += "</a>";
  deep += "</robot>";
  EXPECT_NE(message(deep).find("nested more than 256 deep"), std::string::npos);
  // A 2 MB link name is clipped in the message.
  const std::string base = std::string(APPELL_SOURCE_DIR) + "/tests/data/io/bad/initial_violation.urdf";
  std::ifstream in(base);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::string long_name = text;
  long_name.replace(long_name.find("link=\"ball\" kind"), 11, "link=\"" + std::string(2000000, 'x') + "\"");
  const std::string m = message(long_name);
  EXPECT_LT(m.size(), 1000u) << "the message is short";
  EXPECT_NE(m.find("(2000000 characters)"), std::string::npos) << m.substr(0, 300);
  // 1e309 is out of the doubles' range, and said so.
  std::string huge = text;
  huge.replace(huge.find("<mass value=\"1\""), 15, "<mass value=\"1e309\"");
  EXPECT_NE(message(huge).find("\"1e309\" is not finite (out of the range of doubles"), std::string::npos)
      << message(huge);
  // A file ending inside a UTF-8 sequence is malformed, nothing worse.
  EXPECT_NE(message(text + "\xC3").find("gen.urdf"), std::string::npos);
}

// Meshes are untrusted input: a face naming a vertex the mesh does not have
// is an error naming the file and the face (it used to index out of bounds).
// An axis whose norm overflows is still a direction.
TEST(IoErrors, MeshFaceIndexBeyondTheVerticesAndHugeAxes) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("appell_mesh_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "bad.ply") << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                                    "property float y\nproperty float z\nelement face 1\n"
                                    "property list uchar int vertex_indices\nend_header\n"
                                    "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n";
  const std::string urdf = R"(<?xml version="1.0"?>
<robot name="r"><link name="world"/>
  <link name="a"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
    <collision><geometry><mesh filename="bad.ply"/></geometry></collision></link>
  <joint name="j" type="revolute"><parent link="world"/><child link="a"/><axis xyz="1e308 1e308 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>)";
  // A contact takes its shape from the mesh, so the mesh must load.
  std::string used = urdf;
  used.replace(used.find("</robot>"), 8,
               R"(<appell><support name="g"/><contact name="c" link="a" kind="sliding" support="g"/></appell></robot>)");
  try {
    loadSceneFromString(used, dir.string(), "mesh.urdf");
    ADD_FAILURE() << "a face beyond the vertices loaded";
  } catch (const SceneError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("bad.ply: face 0 names vertex 7 but the mesh has 3 vertices"), std::string::npos) << m;
  }
  std::string ok = urdf;
  ok.replace(ok.find("<collision>"), ok.find("</collision>") + 12 - ok.find("<collision>"), "");
  const Scene s = loadSceneFromString(ok, dir.string(), "axis.urdf");
  EXPECT_TRUE(s.model.joints[0].axis.isApprox(Vec3(1, 1, 0).normalized())) << s.model.joints[0].axis.transpose();
  std::filesystem::remove_all(dir);
}

// A .urdf.xacro given as it is gets one error, at the first xacro construct,
// saying to run xacro — not a cascade of "not a number" and unknown elements.
TEST(IoErrors, UnexpandedXacroIsNamedOnce) {
  auto message = [](const std::string& xml) { return messageOf(xml, "robot.urdf.xacro"); };
  const std::string link =
      "<link name=\"a\"><inertial><mass value=\"1\"/><inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" "
      "iyy=\"1\" iyz=\"0\" izz=\"1\"/></inertial></link>\n";
  const std::string substitution = "<robot name=\"r\">\n" + link +
                                   "<link name=\"b\"><inertial><mass value=\"${wheel_mass}\"/>"
                                   "</inertial></link>\n</robot>\n";
  const std::string m1 = message(substitution);
  EXPECT_NE(m1.find("robot.urdf.xacro:3:"), std::string::npos) << m1;
  EXPECT_NE(m1.find("value=\"${wheel_mass}\""), std::string::npos) << m1;
  EXPECT_NE(m1.find("unexpanded xacro"), std::string::npos) << m1;
  EXPECT_NE(m1.find("xacro FILE.urdf.xacro > FILE.urdf"), std::string::npos) << m1;

  const std::string macro = "<robot name=\"r\">\n" + link +
                            "<xacro:property name=\"r\" value=\"0.1\"/>\n"
                            "<mesh filename=\"$(find pkg)/a.stl\"/>\n</robot>\n";
  const std::string m2 = message(macro);
  EXPECT_NE(m2.find("robot.urdf.xacro:3: <xacro:property"), std::string::npos) << m2;
  EXPECT_NE(m2.find("element <xacro:property>"), std::string::npos) << m2;

  // The namespace declared on <robot> is no xacro: the first xacro element
  // under it is what is named.
  const std::string declared = "<robot name=\"r\" xmlns:xacro=\"http://www.ros.org/wiki/xacro\">\n" +
                               link + "<xacro:include filename=\"wheel.xacro\"/>\n</robot>\n";
  EXPECT_NE(message(declared).find("robot.urdf.xacro:3: <xacro:include"), std::string::npos)
      << message(declared);
  // A plain URDF with a '$' in a name is not xacro.
  EXPECT_EQ(message("<robot name=\"r\">\n" + link + "<link name=\"cost$1\"/></robot>").find("unexpanded"),
            std::string::npos);
}

// Issue 41, reproducer 1: TinyXML reads `<1 " >` as an unknown node ending
// at its first '>', but the depth pre-scan used to skip the quote as an
// attribute value's and see `<1 " >` + 70 000 × `<x>` + `<2 " >` as one tag:
// the parser then recursed 70 000 deep (stack overflow). The pre-scan now
// classifies every '<' as the parser does and refuses such junk by its line.
TEST(IoErrors, JunkNodesTheParserWouldSkipAreRefusedBeforeItNests) {
  auto message = [](const std::string& xml) { return messageOf(xml, "junk.urdf"); };
  std::string deep = "<robot name=\"r\">\n<1 \" >";
  for (int i = 0; i < 70000; ++i) deep += "<x>";
  deep += "<2 \" >";
  for (int i = 0; i < 70000; ++i) deep += "</x>";
  deep += "</robot>";
  EXPECT_EQ(message(deep).rfind("junk.urdf:2: malformed XML: '<1 \" >' is not an element, an end tag, "
                                "a comment or a declaration", 0),
            0u)
      << message(deep).substr(0, 200);
  // The small junk node that used to load silently.
  const std::string link =
      "<link name=\"a\"><inertial><mass value=\"1\"/><inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" "
      "iyy=\"1\" iyz=\"0\" izz=\"1\"/></inertial></link>\n";
  const std::string small = "<robot name=\"r\">\n" + link + "  <1 \" >\n</robot>\n";
  EXPECT_NE(message(small).find("junk.urdf:3: malformed XML: '<1 \" >'"), std::string::npos) << message(small);
  // End tags with nothing open are unknown nodes to TinyXML: they must not
  // lower the count of the 70 000 elements that follow them.
  std::string unbalanced;
  for (int i = 0; i < 70000; ++i) unbalanced += "</x>";
  unbalanced += "<robot name=\"r\">";
  for (int i = 0; i < 70000; ++i) unbalanced += "<x>";
  EXPECT_NE(message(unbalanced).find("junk.urdf:1: malformed XML: '</x>' closes no open element"),
            std::string::npos)
      << message(unbalanced).substr(0, 200);
  // What the parser accepts stays accepted: a declaration, a DOCTYPE, a
  // processing instruction, comments with '<' and quotes in them, a quoted
  // '>' inside an attribute.
  const std::string fine = "<?xml version=\"1.0\"?>\n<!DOCTYPE robot>\n<?xml-stylesheet href=\"a\"?>\n"
                           "<robot name=\"a>b\">\n<!-- <1 \" > -->\n" + link + "</robot>\n";
  EXPECT_EQ(message(fine), "(loaded)");
}

namespace {

// A binary STL of the triangles `corners` (three per facet).
void writeBinaryStl(const std::filesystem::path& path, const std::vector<std::array<float, 3>>& corners) {
  std::ofstream out(path, std::ios::binary);
  const char header[80] = "binary STL written by test_io_errors";
  out.write(header, 80);
  const auto facets = static_cast<std::uint32_t>(corners.size() / 3);
  out.write(reinterpret_cast<const char*>(&facets), 4);
  for (std::uint32_t f = 0; f < facets; ++f) {
    const float normal[3] = {0, 0, 1};
    out.write(reinterpret_cast<const char*>(normal), 12);
    for (int c = 0; c < 3; ++c) out.write(reinterpret_cast<const char*>(corners[3 * f + c].data()), 12);
    const std::uint16_t attributes = 0;
    out.write(reinterpret_cast<const char*>(&attributes), 2);
  }
}

std::string meshMessage(const std::filesystem::path& path) {
  try {
    const TriangleMesh m = loadMesh(path.string());
    return "(loaded " + std::to_string(m.vertices.size()) + " vertices)";
  } catch (const SceneError& e) {
    return e.what();
  }
}

}  // namespace

// Issue 41, reproducer 11: a NaN vertex used to be welded before the
// finiteness check (NaN compares equal to every key of the weld's map), so
// a terrain with one NaN corner loaded with a flipped copy of a triangle
// and a bogus penetration; ASCII files with nan, inf or 1e300 (infinite as
// a float) were refused as "mesh has no triangles". Now every vertex is
// checked as it is read, and the error names it.
TEST(IoErrors, NonFiniteMeshVerticesAreNamedBeforeAnyWeld) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("appell_nanmesh_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  writeBinaryStl(dir / "terrain.stl", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 0, 0}, {1, 1, 0}, {nan, 1, 0}});
  const std::string m = meshMessage(dir / "terrain.stl");
  EXPECT_EQ(m.rfind((dir / "terrain.stl").string() + ": vertex 5 of mesh '", 0), 0u) << m;
  EXPECT_NE(m.find("' is (nan, 1, 0): a mesh vertex must be finite"), std::string::npos) << m;

  std::ofstream(dir / "ascii.stl") << "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n"
                                      "vertex 1 0 0\nvertex 0 1e300 0\nendloop\nendfacet\nendsolid t\n";
  EXPECT_NE(meshMessage(dir / "ascii.stl").find("vertex 2 of mesh '"), std::string::npos)
      << meshMessage(dir / "ascii.stl");
  EXPECT_NE(meshMessage(dir / "ascii.stl").find("is (0, inf, 0): a mesh vertex must be finite"),
            std::string::npos)
      << meshMessage(dir / "ascii.stl");
  std::ofstream(dir / "nan.obj") << "v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n";
  EXPECT_NE(meshMessage(dir / "nan.obj").find("a mesh vertex must be finite"), std::string::npos)
      << meshMessage(dir / "nan.obj");
  // A finite vertex placed out of range by the scale is named with both values.
  writeBinaryStl(dir / "big.stl", {{0, 0, 0}, {1, 0, 0}, {0, 3e38f, 0}});
  try {
    loadMesh((dir / "big.stl").string(), Vec3(1, 1e300, 1));
    ADD_FAILURE() << "an infinite scaled vertex loaded";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("once placed and scaled: a mesh vertex must be finite"),
              std::string::npos)
        << e.what();
  }
  // The same terrain without the NaN loads with its 4 distinct corners.
  writeBinaryStl(dir / "good.stl", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}});
  EXPECT_EQ(meshMessage(dir / "good.stl"), "(loaded 4 vertices)");
  std::filesystem::remove_all(dir);
}

// Issue 41, item 3: the scene's <simulation> numbers are checked where they
// are read, by attribute and line — a NaN or negative tolerance never reaches
// the integrator (where a NaN once hung dopri5).
TEST(IoErrors, SimulationSettingsAreFiniteAndPositive) {
  const std::string head =
      "<robot name=\"r\">\n<link name=\"a\"><inertial><mass value=\"1\"/><inertia ixx=\"1\" ixy=\"0\" "
      "ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/></inertial></link>\n<appell>\n";
  for (const char* bad : {"tol=\"nan\"", "tol=\"-1\"", "tol=\"inf\"", "dt=\"0\"", "duration=\"-5\""}) {
    const std::string m = messageOf(head + "<simulation " + bad + "/>\n</appell></robot>", "sim.urdf");
    EXPECT_EQ(m.rfind("sim.urdf:4: <simulation", 0), 0u) << bad << ": " << m;
    const std::string attr = std::string(bad).substr(0, std::string(bad).find('='));
    EXPECT_NE(m.find(attr), std::string::npos) << bad << ": " << m;
  }
}

// xacro's output as `xacro robot.urdf.xacro > robot.urdf` writes it: the
// banner comment, the namespace declarations left on <robot> (xacro's own
// and Gazebo's old ones), comments holding "${…}" and "$(find …)" as their
// authors wrote them, and no xacro element — a URDF, loaded as urdfdom,
// Pinocchio, MuJoCo and Drake load it.
TEST(IoErrors, XacroOutputWithItsNamespaceLoads) {
  const std::string xml =
      "<?xml version=\"1.0\" ?>\n"
      "<!-- =================================================================== -->\n"
      "<!-- |    This document was autogenerated by xacro from robot.urdf.xacro | -->\n"
      "<!-- |    EDITING THIS FILE BY HAND IS NOT RECOMMENDED                 | -->\n"
      "<!-- =================================================================== -->\n"
      "<robot name=\"r\" xmlns:xacro=\"http://www.ros.org/wiki/xacro\"\n"
      "       xmlns:sensor=\"http://playerstage.sourceforge.net/gazebo/xmlschema/#sensor\">\n"
      "  <!-- mass is ${base_mass}, from $(find robot_description)/config/masses.yaml -->\n"
      "  <link name=\"base_link\">\n"
      "    <inertial><origin rpy=\"0 0 0\" xyz=\"0 0 0\"/><mass value=\"2.0\"/>\n"
      "      <inertia ixx=\"0.02\" ixy=\"0.0\" ixz=\"0.0\" iyy=\"0.02\" iyz=\"0.0\" izz=\"0.03\"/>\n"
      "    </inertial>\n"
      "  </link>\n"
      "</robot>\n";
  const Scene s = loadSceneFromString(xml, ".", "robot.urdf");
  EXPECT_EQ(s.model.nbodies, 1);
  EXPECT_EQ(s.model.body_names[0], "base_link");
  EXPECT_TRUE(s.warnings.empty());
  // The same through loadUrdfModel (the model-only entry point).
  const auto dir = std::filesystem::temp_directory_path() / ("appell_xacro_out_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "robot.urdf") << xml;
  EXPECT_EQ(loadUrdfModel((dir / "robot.urdf").string()).nbodies, 1);
  std::filesystem::remove_all(dir);
}
