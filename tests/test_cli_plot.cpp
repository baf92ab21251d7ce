// `appell plot`, `appell run --plot` and `appell view` without a browser: the
// PNGs exist and are PNGs, the numbers gnuplot draws are the CSV's own (to the
// last bit: both are written in the shortest round-trip form), and the page
// carries the run. The page's pixels are tested in headless Chromium
// (tests/viewer/test_viewer.mjs).
#include <appell/trajectory_reader.hpp>

#include "run_command.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
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

}  // namespace
