// `appell plot`, `appell run --plot` and `appell view` without a browser: the
// PNGs exist and are PNGs, the numbers gnuplot draws are the CSV's own (to the
// last bit: both are written in the shortest round-trip form), and the page
// carries the run. The page's pixels are tested in headless Chromium
// (tests/viewer/test_viewer.mjs).
#include <appell/trajectory_reader.hpp>

#include "run_command.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

const std::string kAppell = std::string(APPELL_BINARY_DIR) + "/cli/appell";
const std::string kDisk = std::string(APPELL_SOURCE_DIR) + "/examples/rolling_disk/rolling_disk.urdf";
// One folder per process: ctest runs each test of this file as its own process, in parallel.
const fs::path kWork = fs::path(APPELL_BINARY_DIR) / ("test_cli_plot_" + std::to_string(getpid()));

using Result = appell::test::CommandResult;
Result sh(const std::string& args) { return appell::test::runAppell(args); }

std::string slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A PNG: the signature, an IHDR with a nonzero size first, an IEND last.
void expectPng(const fs::path& path) {
  const std::string png = slurp(path);
  ASSERT_GT(png.size(), 1000u) << path;
  EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8)) << path;
  EXPECT_EQ(png.substr(12, 4), "IHDR") << path;
  auto be32 = [&](size_t at) {
    return (uint32_t(uint8_t(png[at])) << 24) | (uint32_t(uint8_t(png[at + 1])) << 16) |
           (uint32_t(uint8_t(png[at + 2])) << 8) | uint32_t(uint8_t(png[at + 3]));
  };
  EXPECT_GT(be32(16), 100u) << path << ": width";
  EXPECT_GT(be32(20), 100u) << path << ": height";
  EXPECT_EQ(png.substr(png.size() - 8, 4), "IEND") << path;
}

/// The numbers of a gnuplot data file (comment lines skipped), row by row.
std::vector<std::vector<double>> readDat(const fs::path& path) {
  std::ifstream in(path);
  std::vector<std::vector<double>> rows;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    std::vector<double> row;
    std::string field;
    while (s >> field) row.push_back(field == "NaN" ? std::nan("") : std::stod(field));
    rows.push_back(row);
  }
  return rows;
}

class CliPlot : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    fs::remove_all(kWork);
    fs::create_directories(kWork);
    run_ = sh("run " + kDisk + " --duration 1 --quiet --plot --out " + (kWork / "disk.csv").string());
  }
  static void TearDownTestSuite() { fs::remove_all(kWork); }
  static Result run_;
};
Result CliPlot::run_;

TEST_F(CliPlot, RunPlotWritesFourPngs) {
  ASSERT_EQ(run_.status, 0) << run_.output;
  for (const char* name : {"energy", "residuals", "contacts", "path"}) {
    expectPng(kWork / "disk_plots" / (std::string(name) + ".png"));
    EXPECT_NE(run_.output.find("disk_plots/" + std::string(name) + ".png"), std::string::npos);
  }
}

TEST_F(CliPlot, DataFilesHoldTheCsvNumbers) {
  ASSERT_EQ(run_.status, 0) << run_.output;
  const appell::TrajectoryTable csv = appell::readTrajectory((kWork / "disk.csv").string());
  const fs::path dir = kWork / "disk_plots";
  const auto energy = readDat(dir / "energy.dat");
  const auto contacts = readDat(dir / "contacts.dat");
  const auto path = readDat(dir / "path.dat");
  const auto residuals = readDat(dir / "residuals.dat");
  ASSERT_EQ(energy.size(), csv.rows.size());
  ASSERT_EQ(contacts.size(), csv.rows.size());
  ASSERT_EQ(path.size(), csv.rows.size());
  ASSERT_EQ(residuals.size(), csv.rows.size());
  const int E = csv.require("energy"), res = csv.require("residual");
  const int fn = csv.require("lambda:rim.normal"), t1 = csv.require("lambda:rim.tangent1"),
            t2 = csv.require("lambda:rim.tangent2");
  const int x = csv.require("q:root_joint.x"), y = csv.require("q:root_joint.y");
  const int px = csv.require("point:rim.x"), py = csv.require("point:rim.y");
  const double E0 = csv.rows[0][E];
  for (size_t i = 0; i < csv.rows.size(); ++i) {
    const auto& r = csv.rows[i];
    ASSERT_EQ(energy[i].size(), 3u);
    EXPECT_EQ(energy[i][0], r[0]);
    EXPECT_EQ(energy[i][1], r[E]);
    EXPECT_EQ(energy[i][2], r[E] - E0);
    EXPECT_EQ(residuals[i][1], r[res]);
    ASSERT_EQ(contacts[i].size(), 3u);  // t, rim normal load, rim friction demand
    EXPECT_EQ(contacts[i][1], r[fn]);
    EXPECT_NEAR(contacts[i][2], std::hypot(r[t1], r[t2]) / r[fn], 1e-14);
    ASSERT_EQ(path[i].size(), 5u);      // t, root_joint x y, contact rim x y
    EXPECT_EQ(path[i][1], r[x]);
    EXPECT_EQ(path[i][2], r[y]);
    EXPECT_EQ(path[i][3], r[px]);
    EXPECT_EQ(path[i][4], r[py]);
  }
  // The rolling disk's upright start: the normal load is about its weight, and
  // the demand stays far below the scene's μ = 0.8, which the plot draws.
  EXPECT_NEAR(contacts[0][1], 9.81, 0.2);
  EXPECT_NE(slurp(dir / "contacts.gp").find("μ rim = 0.8"), std::string::npos);
}

TEST_F(CliPlot, PlotCommandWithoutSceneDrawsNoMu) {
  ASSERT_EQ(run_.status, 0) << run_.output;
  const fs::path dir = kWork / "again";
  const Result r = sh("plot " + (kWork / "disk.csv").string() + " --out " + dir.string());
  ASSERT_EQ(r.status, 0) << r.output;
  for (const char* name : {"energy", "residuals", "contacts", "path"})
    expectPng(dir / (std::string(name) + ".png"));
  EXPECT_EQ(slurp(dir / "contacts.gp").find("μ"), std::string::npos);
  EXPECT_EQ(slurp(dir / "energy.dat"), slurp(kWork / "disk_plots" / "energy.dat"));
}

TEST_F(CliPlot, BadInputIsNamed) {
  const Result missing = sh("plot " + (kWork / "nothing.csv").string());
  EXPECT_EQ(missing.status, 1);
  EXPECT_NE(missing.output.find("nothing.csv"), std::string::npos) << missing.output;
  const fs::path bad = kWork / "bad.csv";
  std::ofstream(bad) << "time,energy,residual\n0,1,0\n0.5,oops,0\n";
  const Result r = sh("plot " + bad.string());
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("bad.csv:3"), std::string::npos) << r.output;
  EXPECT_EQ(sh("run " + kDisk + " --plot").status, 2);  // nothing to plot without --out
}

TEST_F(CliPlot, ViewPageCarriesTheRun) {
  ASSERT_EQ(run_.status, 0) << run_.output;
  const fs::path page = kWork / "disk.html";
  const Result r = sh("view " + kDisk + " --trajectory " + (kWork / "disk.csv").string() +
                      " --out " + page.string());
  ASSERT_EQ(r.status, 0) << r.output;
  const std::string html = slurp(page);
  const appell::TrajectoryTable csv = appell::readTrajectory((kWork / "disk.csv").string());
  EXPECT_NE(r.output.find(std::to_string(csv.rows.size()) + " samples"), std::string::npos) << r.output;
  EXPECT_NE(html.find("\"times\":[0,"), std::string::npos);
  EXPECT_NE(html.find("\"type\":\"cylinder\",\"radius\":0.3,\"length\":0.01"), std::string::npos);
  EXPECT_GT(html.size(), 300000u);  // three.js is in the page
  EXPECT_EQ(html.find("@SCRIPT@"), std::string::npos);
  // The initial state alone, and a trajectory of another scene, named.
  EXPECT_EQ(sh("view " + kDisk + " --out " + (kWork / "initial.html").string()).status, 0);
  const fs::path other = kWork / "other.csv";
  std::ofstream(other) << "time,q:wheel,energy,residual\n0,0,0,0\n";
  const Result wrong = sh("view " + kDisk + " --trajectory " + other.string());
  EXPECT_EQ(wrong.status, 1);
  EXPECT_NE(wrong.output.find("no column 'q:root_joint.x'"), std::string::npos) << wrong.output;
}

// The page carries the contact events for its time line and the contact
// modes (an open contact is not drawn): the bouncing ball's first bounce at
// t* = √(2·1/g) is there, with the contact open while in flight.
TEST_F(CliPlot, ViewPageMarksContactEvents) {
  const std::string ball = std::string(APPELL_SOURCE_DIR) + "/examples/bouncing_ball/bouncing_ball.urdf";
  const fs::path csv = kWork / "ball.csv", page = kWork / "ball.html";
  ASSERT_EQ(sh("run " + ball + " --duration 1 --quiet --every 50 --out " + csv.string()).status, 0);
  const Result r = sh("view " + ball + " --trajectory " + csv.string() + " --out " + page.string());
  ASSERT_EQ(r.status, 0) << r.output;
  const std::string html = slurp(page);
  EXPECT_NE(html.find("\"events\":[[0.45152364"), std::string::npos) << "first bounce on the time line";
  EXPECT_NE(html.find(",0,\"bounce\"]"), std::string::npos);
  EXPECT_NE(html.find("\"closed\":[[0],"), std::string::npos) << "in flight at t = 0";
}

/// The colours "lc rgb '#rrggbb'" of one line of a gnuplot script, in order.
std::vector<std::string> lineColours(const std::string& line) {
  std::vector<std::string> colours;
  for (size_t at = line.find("lc rgb '#"); at != std::string::npos; at = line.find("lc rgb '#", at + 1))
    colours.push_back(line.substr(at + 8, 7));
  return colours;
}

/// The line of `script` that starts with "plot " and mentions `what`.
std::string plotLine(const std::string& script, const std::string& what) {
  std::istringstream in(script);
  for (std::string line; std::getline(in, line);)
    if (line.rfind("plot ", 0) == 0 && line.find(what) != std::string::npos) return line;
  return "";
}

// joints.png: q and v of the wheels as the CSV has them, and the servos'
// torque τ = clamp(k_v (q̇* − q̇), ±0.5 N·m) with k_v = 2 N·m·s/rad and
// q̇* = 5 rad/s before t = 3 s (examples/diff_drive/diff_drive_servo.urdf).
TEST_F(CliPlot, JointPlotHasQVAndServoTorque) {
  const std::string robot = std::string(APPELL_SOURCE_DIR) + "/examples/diff_drive/diff_drive_servo.urdf";
  const fs::path csv = kWork / "servo.csv";
  const Result r = sh("run " + robot + " --duration 1 --every 10 --quiet --plot --out " + csv.string());
  ASSERT_EQ(r.status, 0) << r.output;
  const fs::path dir = kWork / "servo_plots";
  expectPng(dir / "joints.png");
  const appell::TrajectoryTable table = appell::readTrajectory(csv.string());
  const auto dat = readDat(dir / "joints.dat");
  ASSERT_EQ(dat.size(), table.rows.size());
  const std::string data = slurp(dir / "joints.dat");
  EXPECT_EQ(data.substr(0, data.find('\n')),
            "# t q:left_wheel_joint v:left_wheel_joint q:right_wheel_joint v:right_wheel_joint "
            "tau:left_wheel_joint tau:right_wheel_joint");
  const int ql = table.require("q:left_wheel_joint"), vl = table.require("v:left_wheel_joint");
  const int qr = table.require("q:right_wheel_joint"), vr = table.require("v:right_wheel_joint");
  int saturated = 0;
  for (size_t i = 0; i < dat.size(); ++i) {
    const auto& row = table.rows[i];
    ASSERT_EQ(dat[i].size(), 7u);
    EXPECT_EQ(dat[i][1], row[ql]);
    EXPECT_EQ(dat[i][2], row[vl]);
    EXPECT_EQ(dat[i][3], row[qr]);
    EXPECT_EQ(dat[i][4], row[vr]);
    for (const auto& [col, v] : {std::pair{5, row[vl]}, std::pair{6, row[vr]}}) {
      const double demand = 2 * (5 - v);
      EXPECT_NEAR(dat[i][col], std::clamp(demand, -0.5, 0.5), 1e-15) << "t = " << row[0];
      saturated += std::abs(demand) > 0.5;
    }
  }
  EXPECT_GT(saturated, 0) << "the servos start saturated (the wheels at rest, 10 N·m demanded)";
  const std::string gp = slurp(dir / "joints.gp");
  EXPECT_NE(gp.find("multiplot layout 3,1"), std::string::npos) << gp;
  EXPECT_NE(gp.find("set ylabel 'τ [N·m or N]'"), std::string::npos) << gp;
  // Without the scene there is no τ: q and v only.
  const Result bare = sh("plot " + csv.string() + " --out " + (kWork / "servo_bare").string());
  ASSERT_EQ(bare.status, 0) << bare.output;
  EXPECT_NE(slurp(kWork / "servo_bare" / "joints.gp").find("multiplot layout 2,1"), std::string::npos);
  EXPECT_EQ(readDat(kWork / "servo_bare" / "joints.dat").at(0).size(), 5u);
}

// Twelve contacts (a puck's two rim hexagons) get twelve colours on
// contacts.png; gnuplot's own cycle would repeat after eight.
TEST_F(CliPlot, ManyContactsGetDistinctColours) {
  const fs::path scene = kWork / "puck.urdf", csv = kWork / "puck.csv";
  std::ofstream(scene) << R"(<?xml version="1.0"?>
<robot name="puck">
  <link name="puck">
    <inertial><mass value="0.5"/><inertia ixx="0.002" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.003"/></inertial>
    <collision><geometry><cylinder radius="0.1" length="0.04"/></geometry></collision>
  </link>
  <appell>
    <support name="floor" type="plane"/>
    <contact name="base" link="puck" kind="sliding" support="floor" rim_points="6"/>
    <initial><joint name="root_joint" xyz="0 0 0.02"/></initial>
  </appell>
</robot>)";
  const Result r = sh("run " + scene.string() + " --duration 0.1 --quiet --plot --out " + csv.string());
  ASSERT_EQ(r.status, 0) << r.output;
  const std::string gp = slurp(kWork / "puck_plots" / "contacts.gp");
  const std::vector<std::string> load = lineColours(plotLine(gp, "contacts.dat' using 1:2 "));
  ASSERT_EQ(load.size(), 12u) << gp;
  EXPECT_EQ(std::set<std::string>(load.begin(), load.end()).size(), 12u) << gp;
  const std::vector<std::string> path = lineColours(plotLine(slurp(kWork / "puck_plots" / "path.gp"), "path.dat"));
  ASSERT_EQ(path.size(), 13u) << "the root joint and 12 contact points";
  EXPECT_EQ(std::set<std::string>(path.begin(), path.end()).size(), 13u);
}

// A run with --no-joint-limits writes no columns for the limits; `view`
// takes its CSV all the same (with a note), with or without the flag.
TEST_F(CliPlot, ViewTakesARunWithoutJointLimits) {
  const std::string car = std::string(APPELL_SOURCE_DIR) + "/examples/steered_car/steered_car.urdf";
  const fs::path csv = kWork / "free.csv", page = kWork / "free.html";
  ASSERT_EQ(sh("run " + car + " --no-joint-limits --duration 0.2 --quiet --out " + csv.string()).status, 0);
  const appell::TrajectoryTable table = appell::readTrajectory(csv.string());
  for (const std::string& c : table.columns) ASSERT_EQ(c.find("_limit"), std::string::npos) << c;
  const Result r = sh("view " + car + " --trajectory " + csv.string() + " --out " + page.string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("has no columns for the scene's"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("(a run with --no-joint-limits): shown without them"), std::string::npos) << r.output;
  EXPECT_EQ(slurp(page).find("\"name\":\"steer_left_lower_limit\""), std::string::npos) << "no limit";
  const Result flag = sh("view " + car + " --no-joint-limits --trajectory " + csv.string() + " --out " +
                         page.string());
  ASSERT_EQ(flag.status, 0) << flag.output;
  EXPECT_EQ(flag.output.find("shown without them"), std::string::npos) << flag.output;
  // A run with the limits is shown with them: their columns are read.
  const fs::path limited = kWork / "limited.csv";
  ASSERT_EQ(sh("run " + car + " --duration 0.2 --quiet --out " + limited.string()).status, 0);
  const Result with = sh("view " + car + " --trajectory " + limited.string() + " --out " + page.string());
  ASSERT_EQ(with.status, 0) << with.output;
  EXPECT_EQ(with.output.find("shown without them"), std::string::npos) << with.output;
  EXPECT_NE(slurp(page).find("\"name\":\"steer_left_lower_limit\""), std::string::npos) << "the limits are there";
}

/// The numbers of the JSON array that follows `key` in `text` (from `from` on).
std::vector<double> jsonArray(const std::string& text, const std::string& key, size_t from = 0) {
  const size_t at = text.find("\"" + key + "\":[", from);
  if (at == std::string::npos) return {};
  std::vector<double> out;
  std::istringstream in(text.substr(at + key.size() + 4, text.find(']', at) - at - key.size() - 4));
  for (std::string field; std::getline(in, field, ',');) out.push_back(std::stod(field));
  return out;
}

// A terrain support's triangles are in the page, in its support frame: those
// of examples/car_bump/bump.obj — 10 triangles with the OBJ's corners in the
// OBJ's winding (assimp may renumber the vertices and reads them in single
// precision: 0.05 comes back as 0.0500000007).
TEST_F(CliPlot, ViewPageCarriesTheTerrain) {
  const std::string dir = std::string(APPELL_SOURCE_DIR) + "/examples/car_bump/";
  const fs::path page = kWork / "bump.html";
  const Result r = sh("view " + dir + "car_bump.urdf --out " + page.string());
  ASSERT_EQ(r.status, 0) << r.output;
  const std::string html = slurp(page);
  const size_t terrain = html.find("{\"name\":\"ground\",\"type\":\"terrain\",");
  ASSERT_NE(terrain, std::string::npos);
  const std::vector<double> xyz = jsonArray(html, "vertices", terrain), tri = jsonArray(html, "triangles", terrain);
  std::vector<std::vector<double>> obj_v;
  std::vector<std::string> want, got;
  std::ifstream obj(dir + "bump.obj");
  for (std::string line; std::getline(obj, line);) {
    std::istringstream in(line.substr(std::min<size_t>(2, line.size())));
    if (line.rfind("v ", 0) == 0) obj_v.push_back({0, 0, 0}), in >> obj_v.back()[0] >> obj_v.back()[1] >> obj_v.back()[2];
    if (line.rfind("f ", 0) != 0) continue;
    int a, b, c;
    in >> a >> b >> c;
    std::ostringstream t;
    for (int k : {a, b, c}) t << obj_v[k - 1][0] << ' ' << obj_v[k - 1][1] << ' ' << obj_v[k - 1][2] << "; ";
    want.push_back(t.str());
  }
  ASSERT_EQ(tri.size(), 3 * want.size());
  for (size_t i = 0; i < tri.size(); i += 3) {
    std::ostringstream t;
    for (size_t k = 0; k < 3; ++k) {
      const size_t v = 3 * static_cast<size_t>(tri[i + k]);
      ASSERT_LT(v + 2, xyz.size());
      for (size_t d = 0; d < 3; ++d) t << std::round(xyz[v + d] * 1e6) / 1e6 << (d < 2 ? " " : "; ");
    }
    got.push_back(t.str());
  }
  // The same triangles, each starting at the same corner (winding kept), in order.
  EXPECT_EQ(got, want);
}

// URDF materials: a visual's own <color rgba>, a robot-level material named by
// a visual, and a name defined nowhere (a warning; the default colour).
TEST_F(CliPlot, ViewPageCarriesMaterialColours) {
  std::string urdf = slurp(kDisk);
  const std::string cylinder = "<cylinder radius=\"0.3\" length=\"0.01\"/>";
  ASSERT_NE(urdf.find(cylinder), std::string::npos);
  const fs::path scene = kWork / "painted_disk.urdf", page = kWork / "painted.html";
  auto painted = [&](const std::string& robot_level, const std::string& visual) {
    std::string u = urdf;
    u.replace(u.find("<link"), 0, robot_level + "\n  ");
    const size_t end = u.find("</visual>");
    u.replace(end, 0, visual + "\n    ");
    std::ofstream(scene) << u;
    return sh("view " + scene.string() + " --out " + page.string());
  };
  Result r = painted("", "<material name=\"own\"><color rgba=\"0.25 0.5 0.75 1\"/></material>");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(slurp(page).find("\"rgba\":[0.25,0.5,0.75,1]"), std::string::npos);
  r = painted("<material name=\"steel\"><color rgba=\"0.6 0.6 0.62 0.5\"/></material>",
              "<material name=\"steel\"/>");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(slurp(page).find("\"rgba\":[0.6,0.6,0.62,0.5]"), std::string::npos);
  r = painted("", "<material name=\"nowhere\"/>");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("painted_disk.urdf:"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("<material name=\"nowhere\">: material 'nowhere' is not defined at the robot "
                          "level: drawn in the default colour"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(slurp(page).find("\"rgba\":["), std::string::npos);
}

}  // namespace
