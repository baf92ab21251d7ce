// Bad input: every case gives a SceneError naming the file, the element
// (with its line where the XML parser knows it) and the reason — and no
// partial scene.
#include <appell/urdf.hpp>

#include <gtest/gtest.h>

#include <regex>

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
  expectError("zero_mass.urdf", 5, {"<mass>", "mass must be positive"});
  expectError("negative_mass.urdf", 5, {"<mass>", "mass must be positive, got -2"});
}

TEST(IoErrors, InertiaNotPositiveDefinite) {
  expectError("inertia_not_pd.urdf", 6, {"<inertia>", "not positive definite"});
}

TEST(IoErrors, InertiaViolatesTriangleInequality) {
  expectError("inertia_triangle.urdf", 6, {"<inertia>", "triangle inequality"});
}

TEST(IoErrors, MissingMeshFile) {
  expectError("missing_mesh.urdf", 6, {"<mesh>", "meshes/does_not_exist.stl", "file not found"});
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

TEST(IoErrors, ContactOnAShapeThatCannotRoll) {
  expectError("box_contact.urdf", 9, {"<contact name=\"bottom\">", "collision[0] (box)", "cannot roll"});
}

TEST(IoErrors, KnifeEdgeWithoutDirection) {
  expectError("knife_no_direction.urdf", 8, {"<contact name=\"blade\">", "needs a blade 'direction'"});
}

TEST(IoErrors, InitialStateViolatesTheConstraints) {
  // The ball touches the plane sliding at 1 m/s: the rolling rows' velocity
  // residual is 1. (A ball above the plane is fine: its contact starts open.)
  expectError("initial_violation.urdf", 0, {"initial state violates the constraints",
                                            "contact 'foot'", "project_initial_state"});
  const std::string msg = errorOf("initial_violation.urdf");
  EXPECT_NE(msg.find("velocity residual |A v + b| = 1 "), std::string::npos) << msg;
}

TEST(IoErrors, InitialPenetrationNamesTheContact) {
  // The ball's centre is 0.07 m above the plane, radius 0.1: 3 cm in the ground.
  expectError("initial_penetration.urdf", 0, {"contact 'foot' penetrates its support by 0.03",
                                              "project_initial_state"});
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
