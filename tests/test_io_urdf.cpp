// URDF → Model: joint types, axes, origins, limits, inertias (including a
// rotated inertial frame), the floating-base and `world` conventions, and
// meshes (STL, OBJ, Collada) with scale and package:// resolution.
#include <appell/kinematics.hpp>
#include <appell/urdf.hpp>

#include <gtest/gtest.h>

#include <cstdlib>
#include <unistd.h>
#include <filesystem>
#include <fstream>

using namespace appell;

namespace {

const std::string kData = std::string(APPELL_SOURCE_DIR) + "/tests/data/io/";

Mat3 Rz(double a) { return axisAngle(Vec3::UnitZ(), a); }

// Signed volume by the divergence theorem: exact for a closed, outward-
// oriented triangle mesh, so it checks the indices as well as the vertices.
double volume(const TriangleMesh& m) {
  double v = 0;
  for (const auto& t : m.triangles)
    v += m.vertices[t[0]].dot(m.vertices[t[1]].cross(m.vertices[t[2]])) / 6.0;
  return v;
}

Vec3 bboxMin(const TriangleMesh& m) {
  Vec3 b = Vec3::Constant(1e300);
  for (const auto& v : m.vertices) b = b.cwiseMin(v);
  return b;
}
Vec3 bboxMax(const TriangleMesh& m) {
  Vec3 b = Vec3::Constant(-1e300);
  for (const auto& v : m.vertices) b = b.cwiseMax(v);
  return b;
}

}  // namespace

TEST(IoUrdf, EveryJointTypeBelowAFloatingBase) {
  const Model m = loadUrdfModel(kData + "all_joints.urdf");
  ASSERT_EQ(m.nbodies, 7);
  // Depth-first from the root, children in document order.
  const std::vector<std::string> bodies = {"base",        "rev_link",   "cont_link",   "pris_link",
                                           "planar_link", "float_link", "sensor_mount"};
  const std::vector<std::string> joints = {"root_joint", "rev", "cont", "pris", "plan", "float", "fix"};
  const std::vector<int> parents = {-1, 0, 1, 0, 0, 4, 0};
  const std::vector<JointType> types = {JointType::Floating,  JointType::Revolute,
                                        JointType::Continuous, JointType::Prismatic,
                                        JointType::Planar,    JointType::Floating, JointType::Fixed};
  for (int i = 0; i < 7; ++i) {
    EXPECT_EQ(m.body_names[i], bodies[i]);
    EXPECT_EQ(m.joint_names[i], joints[i]);
    EXPECT_EQ(m.parent[i], parents[i]);
    EXPECT_EQ(m.joints[i].type, types[i]) << bodies[i];
  }
  EXPECT_EQ(m.nq, 7 + 1 + 1 + 1 + 3 + 7 + 0);
  EXPECT_EQ(m.nv, 6 + 1 + 1 + 1 + 3 + 6 + 0);

  const std::vector<double> masses = {2.0, 1.5, 1.0, 0.5, 0.7, 0.3, 0.0};
  for (int i = 0; i < 7; ++i) EXPECT_DOUBLE_EQ(m.inertias[i].mass, masses[i]) << bodies[i];
  EXPECT_NEAR(m.totalMass(), 6.0, 1e-15);
  EXPECT_TRUE(m.inertias[0].com.isApprox(Vec3(0, 0, 0.1)));

  // Inertial frame turned by 90° about z: ixx and iyy swap in the link frame.
  const Inertia& I = m.inertias[1];
  EXPECT_TRUE(I.com.isApprox(Vec3(0.2, 0, 0)));
  EXPECT_NEAR(I.inertia_com(0, 0), 0.02, 1e-15);
  EXPECT_NEAR(I.inertia_com(1, 1), 0.01, 1e-15);
  EXPECT_NEAR(I.inertia_com(2, 2), 0.025, 1e-15);
  EXPECT_NEAR(I.inertia_com(0, 1), 0.0, 1e-15);
  // Products of inertia are URDF tensor entries, kept as they are.
  EXPECT_DOUBLE_EQ(m.inertias[5].inertia_com(0, 1), 0.0005);
  EXPECT_DOUBLE_EQ(m.inertias[5].inertia_com(1, 0), 0.0005);

  // Axes (normalised), origins, limits.
  EXPECT_TRUE(m.joints[1].axis.isApprox(Vec3::UnitZ()));
  EXPECT_TRUE(m.joints[2].axis.isApprox(Vec3::UnitY()));
  EXPECT_TRUE(m.joints[3].axis.isApprox(Vec3::UnitX()));
  EXPECT_TRUE(m.joints[4].axis.isApprox(Vec3::UnitZ()));
  EXPECT_TRUE(m.placement[1].p.isApprox(Vec3(0.1, 0, 0.2)));
  EXPECT_TRUE(m.placement[1].R.isApprox(Rz(0.5)));
  const Mat3 rpy = Rz(0.3) * axisAngle(Vec3::UnitY(), 0.2) * axisAngle(Vec3::UnitX(), 0.1);
  EXPECT_TRUE(m.placement[6].R.isApprox(rpy, 1e-14));
  EXPECT_DOUBLE_EQ(m.joints[1].limits.lower, -1.0);
  EXPECT_DOUBLE_EQ(m.joints[1].limits.upper, 1.5);
  EXPECT_DOUBLE_EQ(m.joints[1].limits.effort, 10);
  EXPECT_DOUBLE_EQ(m.joints[1].limits.velocity, 2);
  EXPECT_TRUE(std::isinf(m.joints[2].limits.lower) && m.joints[2].limits.lower < 0);
  EXPECT_TRUE(std::isinf(m.joints[2].limits.upper) && m.joints[2].limits.upper > 0);
  EXPECT_DOUBLE_EQ(m.joints[2].limits.effort, 3);
  EXPECT_DOUBLE_EQ(m.joints[3].limits.lower, -0.5);
  EXPECT_DOUBLE_EQ(m.joints[3].limits.upper, 0.25);
  EXPECT_TRUE(std::isinf(m.joints[0].limits.upper));
}

TEST(IoUrdf, KinematicsFollowTheUrdfFrames) {
  // Turning `rev` by a moves cont_link's origin on a circle about the rev
  // axis: p = p_rev + Rz(0.5) Rz(a) (0.4, 0, 0) in the base frame.
  const Model m = loadUrdfModel(kData + "all_joints.urdf");
  Data data(m);
  VecX q = VecX::Zero(m.nq);
  q(6) = 1;             // root quaternion w
  q(m.joints[5].idx_q + 6) = 1;
  q(m.joints[1].idx_q) = 0.7;
  q(m.joints[3].idx_q) = 0.2;  // prismatic along x
  forwardKinematics(m, data, q);
  const Vec3 expected = Vec3(0.1, 0, 0.2) + Rz(0.5) * Rz(0.7) * Vec3(0.4, 0, 0);
  EXPECT_TRUE(data.oMi[2].p.isApprox(expected, 1e-14)) << data.oMi[2].p.transpose();
  EXPECT_TRUE(data.oMi[3].p.isApprox(Vec3(0.2, 0, 0), 1e-14));
  EXPECT_TRUE(data.oMi[6].p.isApprox(Vec3(0, 0, 0.3), 1e-14));
}

TEST(IoUrdf, WorldLinkFixesTheRoot) {
  const Model welded = loadUrdfModel(kData + "world_fixed.urdf");
  ASSERT_EQ(welded.nbodies, 2);
  EXPECT_EQ(welded.body_names[0], "base");
  EXPECT_EQ(welded.joints[0].type, JointType::Fixed);
  EXPECT_EQ(welded.parent[0], -1);
  EXPECT_TRUE(welded.placement[0].p.isApprox(Vec3(0, 0, 0.5)));
  EXPECT_EQ(welded.nq, 1);
  EXPECT_EQ(welded.nv, 1);
  EXPECT_EQ(welded.bodyIndex("world"), -1);

  const Model pendulum = loadUrdfModel(kData + "world_revolute.urdf");
  ASSERT_EQ(pendulum.nbodies, 1);
  EXPECT_EQ(pendulum.joints[0].type, JointType::Continuous);
  EXPECT_EQ(pendulum.joint_names[0], "hinge");
  EXPECT_EQ(pendulum.parent[0], -1);
  EXPECT_TRUE(pendulum.placement[0].p.isApprox(Vec3(0, 0, 2)));
  EXPECT_EQ(pendulum.nq, 1);
}

TEST(IoMesh, StlObjDaeWithScale) {
  const TriangleMesh tetra = loadMesh(kData + "meshes/tetra.stl");
  EXPECT_EQ(tetra.vertices.size(), 4u);  // shared corners joined
  EXPECT_EQ(tetra.triangles.size(), 4u);
  EXPECT_NEAR(volume(tetra), 1.0, 1e-6);  // 1·2·3 / 6 (STL stores floats)

  const TriangleMesh big = loadMesh(kData + "meshes/tetra.stl", Vec3(2, 2, 2));
  EXPECT_NEAR(volume(big), 8.0, 1e-5);
  EXPECT_TRUE(bboxMax(big).isApprox(Vec3(2, 4, 6)));

  const TriangleMesh cube = loadMesh(kData + "meshes/cube.obj", Vec3(0.5, 1, 2));
  EXPECT_EQ(cube.vertices.size(), 8u);
  EXPECT_EQ(cube.triangles.size(), 12u);  // six quads, triangulated
  EXPECT_NEAR(volume(cube), 1.0, 1e-12);
  EXPECT_TRUE(bboxMax(cube).isApprox(Vec3(0.5, 1, 2)));

  // Collada: the node transform lifts the quad to z = 0.5; Z_UP coordinates kept.
  const TriangleMesh quad = loadMesh(kData + "meshes/quad.dae");
  EXPECT_EQ(quad.vertices.size(), 4u);
  EXPECT_EQ(quad.triangles.size(), 2u);
  EXPECT_TRUE(bboxMin(quad).isApprox(Vec3(0, 0, 0.5)));
  EXPECT_TRUE(bboxMax(quad).isApprox(Vec3(2, 1, 0.5)));
}

TEST(IoMesh, PackageUrisThroughSearchPathAndEnvironment) {
  const std::string root = kData + "pkgroot";
  LoadOptions opt;
  opt.use_ros_package_path = false;
  opt.package_paths = {"/nonexistent/folder", root};
  // By folder name, and by a package.xml naming the package.
  EXPECT_EQ(findPackage("my_meshes", opt),
            std::filesystem::absolute(root + "/my_meshes").lexically_normal().string());
  EXPECT_EQ(findPackage("other_pkg", opt),
            std::filesystem::absolute(root + "/nested/other").lexically_normal().string());
  EXPECT_EQ(findPackage("absent_pkg", opt), "");
  const std::string p = resolveMeshPath("package://other_pkg/meshes/cube.obj", "/", opt);
  EXPECT_TRUE(std::filesystem::is_regular_file(p));
  EXPECT_TRUE(std::filesystem::path(p).is_absolute());

  // The environment variable, colon-separated.
  LoadOptions env;
  ::setenv("ROS_PACKAGE_PATH", ("/nonexistent:" + root).c_str(), 1);
  EXPECT_NO_THROW(resolveMeshPath("package://my_meshes/meshes/tetra.stl", "/", env));
  env.use_ros_package_path = false;
  try {
    resolveMeshPath("package://my_meshes/meshes/tetra.stl", "/", env);
    ADD_FAILURE() << "package found without a search path";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("package 'my_meshes' not found"), std::string::npos) << e.what();
  }
  ::unsetenv("ROS_PACKAGE_PATH");
}

TEST(IoMesh, UrdfMeshGeometryIsResolvedAndScaled) {
  LoadOptions opt;
  opt.package_paths = {kData + "pkgroot"};
  opt.check_initial_state = false;
  const Scene s = loadScene(kData + "meshes.urdf", opt);
  ASSERT_EQ(s.geometry.size(), 1u);
  const LinkGeometry& g = s.geometry[0];
  ASSERT_EQ(g.visual.size(), 2u);
  ASSERT_EQ(g.collision.size(), 2u);
  EXPECT_EQ(g.visual[0].name, "tetra_rel");
  EXPECT_EQ(g.visual[0].type, GeometryType::Mesh);
  ASSERT_TRUE(g.visual[0].mesh);
  EXPECT_NEAR(volume(*g.visual[0].mesh), 8.0, 1e-5);
  EXPECT_TRUE(g.visual[1].mesh_scale.isApprox(Vec3(0.5, 1, 2)));
  EXPECT_TRUE(g.visual[1].origin.p.isApprox(Vec3(0, 0, 1)));
  EXPECT_EQ(g.visual[1].mesh->triangles.size(), 12u);
  EXPECT_EQ(g.collision[0].mesh_uri, "package://my_meshes/meshes/tetra.stl");
  EXPECT_NEAR(volume(*g.collision[0].mesh), 1.0, 1e-6);
  // Negative scale mirrors: z = 0.5 becomes −0.5.
  EXPECT_NEAR(bboxMax(*g.collision[1].mesh).z(), -0.5, 1e-12);

  // Without loading meshes, the paths are still resolved.
  opt.load_meshes = false;
  const Scene light = loadScene(kData + "meshes.urdf", opt);
  EXPECT_FALSE(light.geometry[0].visual[0].mesh);
  EXPECT_TRUE(std::filesystem::is_regular_file(light.geometry[0].visual[0].mesh_path));
}

// ROS 2 installs a package under <prefix>/share/<package>; AMENT_PREFIX_PATH
// lists the prefixes.
TEST(IoMesh, PackageUrisThroughAmentPrefixPath) {
  namespace fs = std::filesystem;
  const fs::path prefix = fs::temp_directory_path() / ("appell_ament_" + std::to_string(::getpid()));
  fs::remove_all(prefix);
  fs::create_directories(prefix / "share" / "demo_description" / "meshes");
  fs::copy_file(kData + "meshes/tetra.stl", prefix / "share/demo_description/meshes/tetra.stl");
  LoadOptions opt;
  ::setenv("AMENT_PREFIX_PATH", ("/nonexistent/prefix:" + prefix.string()).c_str(), 1);
  ::unsetenv("ROS_PACKAGE_PATH");
  EXPECT_EQ(findPackage("demo_description", opt), (prefix / "share/demo_description").string());
  const std::string p = resolveMeshPath("package://demo_description/meshes/tetra.stl", "/", opt);
  EXPECT_EQ(p, (prefix / "share/demo_description/meshes/tetra.stl").string());
  try {
    resolveMeshPath("package://absent_description/meshes/tetra.stl", "/", opt);
    ADD_FAILURE() << "an absent package was found";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("AMENT_PREFIX_PATH prefixes [/nonexistent/prefix:" + prefix.string()),
              std::string::npos) << e.what();
  }
  ::unsetenv("AMENT_PREFIX_PATH");
  fs::remove_all(prefix);
}

// A symbolic link back up the tree is a cycle: without care a bounded-depth
// walk revisits the loop's folders exponentially often. Each folder is
// entered once, so the search for a missing package ends, and a package
// reachable through a link is still found.
TEST(IoMesh, PackageSearchSurvivesSymlinkCycles) {
  namespace fs = std::filesystem;
  const fs::path root = fs::temp_directory_path() / ("appell_cycle_" + std::to_string(::getpid()));
  fs::remove_all(root);
  // 24 folders a0 … a23, each linking to every other: a walk that does not
  // remember where it has been visits 23⁶ ≈ 1.5·10⁸ folders (beyond the
  // test's time limit); this one visits 25.
  const int n = 24;
  for (int i = 0; i < n; ++i) fs::create_directories(root / ("a" + std::to_string(i)));
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      if (i != j)
        fs::create_directory_symlink(root / ("a" + std::to_string(j)),
                                     root / ("a" + std::to_string(i)) / ("to" + std::to_string(j)));
  fs::create_directories(root / "a7" / "pkg_dir");
  {
    std::ofstream(root / "a7/pkg_dir/package.xml") << "<package><name>linked_pkg</name></package>\n";
  }
  LoadOptions opt;
  opt.use_ros_package_path = false;
  opt.package_paths = {(root / "a0").string()};
  EXPECT_EQ(findPackage("absent_pkg", opt), "");
  const std::string found = findPackage("linked_pkg", opt);
  ASSERT_FALSE(found.empty());
  EXPECT_TRUE(fs::equivalent(found, root / "a7/pkg_dir")) << found;
  fs::remove_all(root);
}
