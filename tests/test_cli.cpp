// The `appell` command as a user meets it: exit codes, messages that name the
// problem, and a run whose summary reports conserved energy.
#include <appell/constrained_dynamics.hpp>
#include <appell/integrators.hpp>
#include <appell/trajectory_reader.hpp>

#include "run_command.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include <sys/stat.h>
#include <unistd.h>
#include <regex>
#include <string>

namespace {

const std::string kAppell = std::string(APPELL_BINARY_DIR) + "/cli/appell";
const std::string kDisk = std::string(APPELL_SOURCE_DIR) + "/examples/rolling_disk/rolling_disk.urdf";

using Result = appell::test::CommandResult;
Result sh(const std::string& args) { return appell::test::runAppell(args); }

double field(const std::string& text, const std::string& pattern) {
  std::smatch m;
  if (!std::regex_search(text, m, std::regex(pattern))) return std::nan("");
  return std::stod(m[1]);
}

}  // namespace

TEST(Cli, HelpAndUsage) {
  EXPECT_EQ(sh("--help").status, 0);
  for (const char* cmd : {"run", "info", "equilibria", "linearize", "view", "plot"}) {
    const Result r = sh(std::string(cmd) + " --help");
    EXPECT_EQ(r.status, 0) << cmd;
    EXPECT_NE(r.output.find("usage: appell " + std::string(cmd)), std::string::npos) << r.output;
  }
  const Result version = sh("--version");
  EXPECT_EQ(version.status, 0);
  EXPECT_EQ(version.output.rfind("appell 0.", 0), 0u) << version.output;
  EXPECT_EQ(sh("fly").status, 2);
  const Result bad = sh("run " + kDisk + " --formulation quantum");
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.output.find("quantum"), std::string::npos) << bad.output;
  EXPECT_EQ(sh("run " + kDisk + " --duration -1").status, 2);
  EXPECT_EQ(sh("run " + kDisk + " --bogus 3").status, 2);
}

// The help texts and the options read the integrator and formulation tables.
TEST(Cli, HelpAndOptionsFollowTheNameTables) {
  const Result run = sh("run --help"), lin = sh("linearize --help");
  for (const auto& e : appell::integratorTable())
    EXPECT_NE(run.output.find(e.name), std::string::npos) << e.name << "\n" << run.output;
  for (const auto& e : appell::formulationTable()) {
    EXPECT_NE(run.output.find(e.name), std::string::npos) << e.name << "\n" << run.output;
    EXPECT_NE(lin.output.find(e.name), std::string::npos) << e.name << "\n" << lin.output;
  }
  EXPECT_EQ(run.output.find("{integrators}"), std::string::npos) << run.output;
  // Aliases are accepted on the command line too.
  const Result r = sh("run " + kDisk + " --duration 0.05 --quiet --formulation multipliers "
                      "--integrator dormand-prince");
  EXPECT_EQ(r.status, 0) << r.output;
  const Result bad = sh("run " + kDisk + " --integrator adams_bashforth");
  EXPECT_EQ(bad.status, 2);
  for (const auto& e : appell::integratorTable())
    EXPECT_NE(bad.output.find(e.name), std::string::npos) << bad.output;
}

// μ belongs to the contact: `info` reads it back from the constraint.
TEST(Cli, InfoShowsTheContactsFrictionCoefficient) {
  const Result r = sh("info " + std::string(APPELL_SOURCE_DIR) + "/tests/data/io/scenes/ball_turntable.urdf");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("μ 0.6"), std::string::npos) << r.output;
}

TEST(Cli, BadSceneNamesTheFile) {
  const std::string path = std::string(APPELL_BINARY_DIR) + "/cli_bad_scene.urdf";
  std::ofstream(path) << "<robot name='x'><link name='a'></robot>";
  const Result r = sh("run " + path);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("cli_bad_scene.urdf"), std::string::npos) << r.output;
  const Result missing = sh("info /nonexistent/scene.urdf");
  EXPECT_EQ(missing.status, 1);
  EXPECT_NE(missing.output.find("/nonexistent/scene.urdf"), std::string::npos) << missing.output;
}

TEST(Cli, InfoReportsRowsAndRank) {
  const Result r = sh("info " + kDisk);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("nq = 7, nv = 6"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("3 of 3 rows closed, rank 3 (0 redundant)"), std::string::npos) << r.output;
}

// A CAD-style base: long link names stay in their columns, the links on
// fixed joints are listed as merged with the combined mass and centre of mass.
TEST(Cli, InfoAlignsLongNamesAndListsMergedLinks) {
  const std::string path = std::string(APPELL_BINARY_DIR) + "/cli_merged.urdf";
  std::ofstream(path) << R"(<robot name="cad">
  <link name="base_footprint"/>
  <joint name="base_footprint_to_chassis_link_joint" type="fixed"><parent link="base_footprint"/>
    <child link="chassis_link_exported_from_solidworks"/><origin xyz="0 0 0.1"/></joint>
  <link name="chassis_link_exported_from_solidworks"><inertial><mass value="4"/>
    <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="lidar_joint" type="fixed"><parent link="chassis_link_exported_from_solidworks"/>
    <child link="lidar"/><origin xyz="0.5 0 0.1"/></joint>
  <link name="lidar"><inertial><mass value="1"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>
</robot>)";
  const Result r = sh("info " + path);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("base_footprint + chassis_link_exported_from_solidworks, lidar: mass 5 kg, "
                          "centre of mass (0.1, 0, 0.12) in base_footprint"),
            std::string::npos) << r.output;
  // Every row of the body table starts its joint column at the same place.
  std::istringstream lines(r.output);
  std::string line;
  std::vector<std::size_t> joint_column;
  for (bool table = false; std::getline(lines, line);) {
    if (line.rfind("body ", 0) == 0) table = true;
    else if (line.empty()) table = false;
    if (!table) continue;
    const auto end_of_name = line.find(' ');
    joint_column.push_back(line.find_first_not_of(' ', end_of_name));
  }
  ASSERT_EQ(joint_column.size(), 4u) << r.output;
  for (std::size_t c : joint_column) EXPECT_EQ(c, joint_column[0]) << r.output;
}

TEST(Cli, RunConservesEnergyAndWritesTheTrajectory) {
  const std::string csv = std::string(APPELL_BINARY_DIR) + "/cli_disk.csv";
  for (const char* f : {"tree", "kkt", "appell"}) {
    const Result r = sh("run " + kDisk + " --duration 1 --quiet --formulation " + f + " --out " + csv);
    ASSERT_EQ(r.status, 0) << r.output;
    // A rolling disk is passive and time-independent: the reactions do no work.
    EXPECT_LT(field(r.output, R"(\(([-+0-9.e]+) relative\))"), 1e-8) << r.output;
    EXPECT_LT(field(r.output, R"(max \|Av\+b\| = ([-+0-9.e]+))"), 1e-10) << r.output;
    EXPECT_LT(field(r.output, R"(max \|gap\| = ([-+0-9.e]+))"), 1e-10) << r.output;
    std::ifstream in(csv);
    std::string header, row;
    std::getline(in, header);
    EXPECT_EQ(header.rfind("time,q:root_joint.x", 0), 0u) << header;
    EXPECT_NE(header.find("lambda:rim.normal"), std::string::npos) << header;
    int rows = 0;
    while (std::getline(in, row)) ++rows;
    EXPECT_GT(rows, 10);
  }
}

TEST(Cli, EquilibriumOfTheUprightDisk) {
  // An upright disk at rest is an equilibrium: its centre of mass is above the
  // contact, the normal load is m g = 9.81 N and nothing else pushes. The set of
  // such states is 4-dimensional: position (x, y), heading and spin angle are free.
  // The guesses: q0 and q0 turned half a turn about the vertical — two
  // distinct equilibria on one set (turning the heading stays on it), both
  // of the first kind (the normal force alone holds the disk).
  const Result r = sh("equilibria " + kDisk + " --starts 1");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("2 distinct equilibria found on 1 equilibrium set"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("on set 1 with equilibrium 1"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("first kind"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("second kind"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("local dimension of the equilibrium set: 4"), std::string::npos) << r.output;
  EXPECT_NEAR(field(r.output, R"(rim/normal\s+([-+0-9.e]+))"), 9.81, 1e-9) << r.output;
}

// Output that fails loudly: a trajectory that cannot be written is an error
// naming the file (exit 1), never "trajectory … (N rows)" and status 0.
TEST(Cli, UnwritableTrajectoryIsAnError) {
  if (!std::filesystem::exists("/dev/full")) GTEST_SKIP() << "no /dev/full on this system";
  const Result r = sh("run " + kDisk + " --duration 0.5 --quiet --out /dev/full");
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("writing the trajectory '/dev/full' failed"), std::string::npos) << r.output;
}

// SIGINT stops a run cleanly: the summary so far is printed, the trajectory
// ends with a whole row at the state reached, and the status is 130.
TEST(Cli, SigintFinishesTheRowPrintsTheSummaryAndExits130) {
  const std::string csv = std::string(APPELL_BINARY_DIR) + "/cli_sigint_" + std::to_string(getpid()) + ".csv";
  const appell::test::CommandResult r = appell::test::runCommand(
      "timeout --preserve-status -s INT 1 " + std::string(APPELL_BINARY_DIR) + "/cli/appell run " + kDisk +
      " --duration 100000 --quiet --out " + csv);
  EXPECT_EQ(r.status, 130) << r.output;
  EXPECT_NE(r.output.find("interrupted  at t = "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("energy       E0 = "), std::string::npos) << "the summary so far";
  std::ifstream in(csv);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(text.size(), 100u);
  EXPECT_EQ(text.back(), '\n') << "the last row is whole";
  const appell::TrajectoryTable t = appell::readTrajectory(csv);  // every row parses
  EXPECT_GT(t.rows.size(), 10u);
  std::filesystem::remove(csv);
}

// Divergence is caught (issue 17, item 4): symplectic Euler at dt = 1e-2 on
// the rolling disk lets the energy of this passive scene wander beyond 5 %;
// the run stops there with status 3 naming the cause, keeping the last state
// within the bound, instead of running on into nonsense.
TEST(Cli, DivergingIntegrationStopsAtTheEnergyBound) {
  const Result r = sh("run " + kDisk + " --integrator euler --dt 1e-2 --duration 10 --quiet");
  EXPECT_EQ(r.status, 3) << r.output;
  EXPECT_NE(r.output.find("the integration is diverging"), std::string::npos) << r.output;
  const std::smatch m = [&] {
    std::smatch mm;
    std::regex_search(r.output, mm, std::regex(R"(max \|E[^=]*= [0-9.eE+-]+ J \(([0-9.eE+-]+) relative\))"));
    return mm;
  }();
  ASSERT_EQ(m.size(), 2u) << r.output;
  EXPECT_LE(std::stod(m[1]), 0.05) << "the summary covers only the states within the bound";
  // Switched off, the same run goes on (and is not stopped by this watch).
  const Result off = sh("run " + kDisk + " --integrator euler --dt 1e-2 --duration 0.5 --quiet --max-energy-error inf");
  EXPECT_EQ(off.output.find("diverging"), std::string::npos) << off.output;
}

// Protects the verdict on a vehicle that cannot move: the example car has one
// free velocity (rolling straight ahead); with one rear wheel's axle turned
// 1e-3 rad out of line its no-slip rows become independent, nothing can move,
// and the run says so (summary line and a warning on stderr) instead of
// quietly showing a car at rest.
TEST(Cli, RunWarnsWhenTheConstraintsLeaveNoFreedom) {
  const std::string car = std::string(APPELL_SOURCE_DIR) + "/examples/car/car.urdf";
  const Result good = sh("run " + car + " --duration 0.1 --quiet");
  ASSERT_EQ(good.status, 0) << good.output;
  EXPECT_NE(good.output.find("freedom      1 independent velocities at t = 0"), std::string::npos)
      << good.output;
  EXPECT_EQ(good.output.find("nothing can move"), std::string::npos) << good.output;

  std::ifstream in(car);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string joint = "<joint name=\"rear_left_joint\" type=\"continuous\">";
  const auto at = text.find(joint);
  ASSERT_NE(at, std::string::npos);
  const auto axis = text.find("<axis xyz=\"0 1 0\"/>", at);
  ASSERT_NE(axis, std::string::npos);
  text.replace(axis, 19, "<axis xyz=\"0.001 1 0\"/>");
  // Ideal tyres (no μ): nothing can give way. (With μ the summary says
  // instead that it moves only by slipping — tests/test_friction_vehicles.cpp.)
  for (auto at_mu = text.find(" mu=\"0.9\""); at_mu != std::string::npos; at_mu = text.find(" mu=\"0.9\""))
    text.erase(at_mu, 9);
  const std::string bad = std::string(APPELL_BINARY_DIR) + "/cli_misaligned_car.urdf";
  std::ofstream(bad) << text;
  // Its initial speed violates the misaligned rows: projected (to rest).
  const Result r = sh("run " + bad + " --duration 0.1 --quiet --project-initial");
  EXPECT_NE(r.output.find("freedom      0 independent velocities at t = 0"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("warning: " + bad + ": the constraints leave 0 independent velocities"),
            std::string::npos)
      << r.output;
  // appell info says so too (and not for the good car).
  const Result info = sh("info " + bad + " --project-initial");
  EXPECT_NE(info.output.find("appell info: warning: " + bad + ": the constraints leave 0 independent velocities"),
            std::string::npos)
      << info.output;
  EXPECT_EQ(sh("info " + car).output.find("warning"), std::string::npos);
}

// --cyclic takes a coordinate by its position name as well as by its
// velocity's (the floating base's world x is root_joint.x or root_joint.vx):
// the same linearization either way; a quaternion component is refused
// saying what to name instead.
TEST(Cli, CyclicCoordinatesByPositionOrVelocityName) {
  const Result by_pos = sh("linearize " + kDisk + " --cyclic root_joint.x,root_joint.y,root_joint.wz");
  const Result by_vel = sh("linearize " + kDisk + " --cyclic root_joint.vx,root_joint.vy,root_joint.wz");
  EXPECT_EQ(by_pos.status, by_vel.status) << by_pos.output;
  EXPECT_NE(by_pos.output.find("eigenvalues"), std::string::npos) << by_pos.output;
  EXPECT_EQ(by_pos.output, by_vel.output);
  const Result bad = sh("linearize " + kDisk + " --cyclic root_joint.qz");
  EXPECT_EQ(bad.status, 2) << bad.output;
  EXPECT_NE(bad.output.find("quaternion component"), std::string::npos) << bad.output;
  EXPECT_NE(bad.output.find("root_joint.wx"), std::string::npos) << bad.output;
}

// appell info lists every mesh with its size (the diff drive's wheels: the
// same 2176-triangle tyre as STL and as Collada).
TEST(Cli, InfoListsMeshesWithTriangleCounts) {
  const Result r = sh("info " + std::string(APPELL_SOURCE_DIR) + "/examples/diff_drive/diff_drive.urdf");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("meshes:"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("meshes/wheel.stl: 2176 triangles"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("meshes/wheel.dae: 2176 triangles"), std::string::npos) << r.output;
}

// The Chaplygin sleigh on the incline with its centre of mass over the blade
// (examples/sleigh/sleigh.urdf with a = 0): it rests wherever it stands with
// its blade across the slope — held by the blade's lateral reaction, an
// equilibrium of the second kind (Emelyanova & Fufaev) — on a 2-dimensional
// set (any position on the plane), one set per blade orientation. Many
// starting points, two sets.
TEST(Cli, SleighOverItsBladeRestsOnTwoSetsOfTheSecondKind) {
  std::ifstream in(std::string(APPELL_SOURCE_DIR) + "/examples/sleigh/sleigh.urdf");
  std::string xml((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (std::string::size_type at; (at = xml.find(R"(xyz="0.3 0 0.1")")) != std::string::npos;)
    xml.replace(at, 15, R"(xyz="0 0 0.1")");
  const std::string path = ::testing::TempDir() + "sleigh_over_blade.urdf";
  std::ofstream(path) << xml;
  const Result r = sh("equilibria " + path + " --starts 6");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("on 2 equilibrium sets"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("second kind: held only with nonholonomic reactions"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("first kind"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("local dimension of the equilibrium set: 2"), std::string::npos) << r.output;
}

// A sleigh on a planar joint: the joint holds its height, so the blade's
// normal row moves nothing (redundant by construction) and carries λ = 0.
// That is not a normal that pulls: no "would lift off" warning, no flag.
TEST(Cli, ANormalRowTheJointsHoldIsNotReportedAsPulling) {
  const std::string path = ::testing::TempDir() + "planar_sleigh.urdf";
  std::ofstream(path) << R"(<robot name="psleigh"><link name="world"/>
  <link name="sleigh"><inertial><origin xyz="0.3 0 0"/><mass value="2"/>
    <inertia ixx="0.08" ixy="0" ixz="0" iyy="0.12" iyz="0" izz="0.18"/></inertial></link>
  <joint name="plane" type="planar"><parent link="world"/><child link="sleigh"/><axis xyz="0 0 1"/></joint>
  <appell><gravity xyz="0 -1 -9.81"/><support name="ground" type="plane" normal="0 0 1" offset="0"/>
    <contact name="blade" link="sleigh" kind="knife_edge" support="ground" point="0 0 0" direction="1 0 0"/>
    <initial><joint name="plane" position="0 0 0" velocity="1 0 0.5"/></initial>
    <simulation integrator="dopri5" duration="3"/></appell></robot>)";
  const Result r = sh("run " + path);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("blade                    normal held by the joints"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("would lift off"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("flagged"), std::string::npos) << r.output;
}

// Issue 41, reproducer 14: `--out` naming the scene overwrote it (exit 0).
// The output is compared with every input as a file (device and inode), so
// another spelling of the same path is caught too; the scene is untouched.
TEST(Cli, OutNamingAnInputIsRefused) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("appell_out_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const std::filesystem::path scene = dir / "disk.urdf";
  std::filesystem::copy_file(kDisk, scene);
  const std::string before = [&] {
    std::ifstream in(scene);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  }();
  const std::string other_spelling = (dir / "." / "disk.urdf").string();
  const Result r = sh("run " + scene.string() + " --duration 0.01 --quiet --out " + other_spelling);
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("--out '" + other_spelling + "' is an input of this command"), std::string::npos)
      << r.output;
  std::ifstream in(scene);
  EXPECT_EQ(std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>()), before);
  std::filesystem::remove_all(dir);
}

// Issue 41, reproducer 14: a full standard output lost the summary with exit
// status 0; it is an error now, said on stderr.
TEST(Cli, AnUnwritableStandardOutputIsAFailure) {
  if (!std::filesystem::exists("/dev/full")) GTEST_SKIP() << "no /dev/full on this system";
  const Result r = appell::test::runCommand("( " + kAppell + " info " + kDisk + " > /dev/full )");
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("appell info: error: cannot write to standard output"), std::string::npos) << r.output;
  const Result run = appell::test::runCommand("( " + kAppell + " run " + kDisk + " --duration 0.01 --quiet > /dev/full )");
  EXPECT_EQ(run.status, 1) << run.output;
}

// Issue 41, reproducer 14: SIGINT during a sweep printed nothing of the
// finished runs. Now the runs in progress stop after their step, no new one
// starts, and the table lists every value: the finished ones with their
// results, the others as "interrupted" or "not run"; the status is 130.
TEST(Cli, SigintDuringASweepKeepsTheFinishedRuns) {
  const std::string car = std::string(APPELL_SOURCE_DIR) + "/examples/car/car.urdf";
  const Result r = appell::test::runCommand("timeout --preserve-status -s INT 4 " + kAppell + " run " + car +
                                            " --sweep speed=1:2:20000 --duration 20 --format csv");
  EXPECT_EQ(r.status, 130) << r.output.substr(0, 2000);
  std::istringstream in(r.output);
  std::string line;
  int ok = 0, not_run = 0, rows = 0;
  while (std::getline(in, line)) {
    if (line.rfind("speed,status", 0) == 0 || line.find(',') == std::string::npos) continue;
    ++rows;
    ok += line.find(",ok,") != std::string::npos;
    not_run += line.find(",not run,") != std::string::npos;
  }
  EXPECT_EQ(rows, 20000) << "every value has its row";
  EXPECT_GE(ok, 1) << "the runs finished before SIGINT are kept";
  // 20 000 runs of 20 s of a car: hours of CPU, so most are never started.
  EXPECT_GE(not_run, 1) << "20000 runs do not finish in 4 s";
  EXPECT_NE(r.output.find("interrupted (SIGINT)"), std::string::npos);
}

// Issue 41, reproducer 10: `appell plot` and `view` read a trajectory with no
// bound (/dev/zero grew at 250 MB/s until memory ran out; a FIFO blocked for
// ever). Only regular files are read, up to a size limit.
TEST(Cli, TrajectoryReadersRefuseDevicesPipesAndDirectories) {
  if (std::filesystem::exists("/dev/zero")) {
    const Result r = sh("plot /dev/zero");
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.output.find("/dev/zero: not a regular file"), std::string::npos) << r.output;
  }
  const std::string fifo = std::string(APPELL_BINARY_DIR) + "/cli_fifo_" + std::to_string(getpid());
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const Result f = appell::test::runCommand("timeout 20 " + kAppell + " plot " + fifo);
  EXPECT_EQ(f.status, 1) << f.output;  // refused, not blocked (timeout's 124)
  EXPECT_NE(f.output.find(fifo + ": not a regular file"), std::string::npos) << f.output;
  std::filesystem::remove(fifo);
  try {
    appell::readTrajectory(std::filesystem::temp_directory_path().string());
    ADD_FAILURE() << "a directory read as a trajectory";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("not a regular file"), std::string::npos) << e.what();
  }
}

// Issue 41, reproducer 15: a name with a line break is written quoted, and
// read back whole (it once split the header into two records).
TEST(Cli, AHeaderNameWithALineBreakReadsBack) {
  const std::string csv = std::string(APPELL_BINARY_DIR) + "/cli_newline_" + std::to_string(getpid()) + ".csv";
  std::ofstream(csv) << "time,\"odd\nname\",x\n0,1,2\n0.5,3,4\n";
  const appell::TrajectoryTable t = appell::readTrajectory(csv);
  ASSERT_EQ(t.columns.size(), 3u);
  EXPECT_EQ(t.columns[1], "odd\nname");
  ASSERT_EQ(t.rows.size(), 2u);
  EXPECT_EQ(t.rows[1][2], 4.0);
  std::filesystem::remove(csv);
}

// Inertias as published (tests/data/io/inertia): every command that loads a
// scene prints the one warning of a defective link on stderr, `run` counts it
// in its summary, and the repair flags change it into what they did.
TEST(Cli, InertiaWarningsAndRepairFlags) {
  const std::string arm = std::string(APPELL_SOURCE_DIR) + "/tests/data/io/inertia/arm_triangle.urdf";
  const Result info = sh("info " + arm);
  EXPECT_EQ(info.status, 0) << info.output;
  EXPECT_NE(info.output.find("appell: warning: " + arm + ":20: <link name=\"arm_left_1_link\">: body "
                             "'arm_left_1_link': principal moments 0.00155679 0.00597627 0.00777394 "
                             "violate the triangle inequality by 3.09853 %"),
            std::string::npos)
      << info.output;
  const Result run = sh("run " + arm + " --duration 0.01 --quiet");
  EXPECT_EQ(run.status, 0) << run.output;
  EXPECT_NE(run.output.find("warnings     1 at load, printed before the run"), std::string::npos) << run.output;
  const Result balanced = sh("info " + arm + " --balance-inertia --bound-mass 0.5");
  EXPECT_EQ(balanced.status, 0) << balanced.output;
  EXPECT_NE(balanced.output.find("body 'arm_left_1_link': repaired: smallest principal moment 0.00155679 "
                                 "raised to 0.00179767 = I₃ − I₂"),
            std::string::npos)
      << balanced.output;
  EXPECT_EQ(balanced.output.find("violate"), std::string::npos) << balanced.output;
  const Result negative = sh("info " + arm + " --bound-inertia -1");
  EXPECT_EQ(negative.status, 2);
  EXPECT_NE(negative.output.find("option --bound-inertia must be ≥ 0"), std::string::npos) << negative.output;
  const Result leaf = sh("info " + std::string(APPELL_SOURCE_DIR) + "/tests/data/io/inertia/massless_leaf.urdf");
  EXPECT_EQ(leaf.status, 1);
  EXPECT_NE(leaf.output.find("joint 'palm_joint' (revolute) moves no inertia"), std::string::npos) << leaf.output;
}
