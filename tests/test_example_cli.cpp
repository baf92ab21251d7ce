// Smoke tests of the example scenes through the built programs: `appell run`
// and `appell info` on every example (exit status 0, the summary's residual,
// energy and redundancy lines), and the two generators (make_ntrailer,
// make_meshes) reproducing the committed files. Needs the `appell` command
// and the example programs built in the same build tree.
#include <appell/urdf.hpp>
#include <appell/trajectory_reader.hpp>

#include "run_command.hpp"

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

namespace appell {
namespace {

namespace fs = std::filesystem;

const std::string kSource = APPELL_SOURCE_DIR;
const std::string kBinary = APPELL_BINARY_DIR;

std::string example(const std::string& rel) { return kSource + "/examples/" + rel; }

using Output = appell::test::CommandResult;
using appell::test::runCommand;

std::string program(const std::string& rel) {
  const std::string path = kBinary + "/" + rel;
  EXPECT_TRUE(fs::exists(path)) << path << " is not built (build the target first)";
  return path;
}

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

double number(const std::string& text, const std::string& pattern) {
  std::smatch m;
  const std::regex re(pattern);
  if (!std::regex_search(text, m, re)) {
    ADD_FAILURE() << "no match for /" << pattern << "/ in:\n" << text;
    return std::nan("");
  }
  return std::stod(m[1].str());
}

class TempDir {
 public:
  TempDir() : path_(fs::temp_directory_path() / ("appell_examples_" + std::to_string(getpid()))) {
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  std::string operator/(const std::string& name) const { return (path_ / name).string(); }

 private:
  fs::path path_;
};

struct RunCase {
  const char* file;
  int redundant;
  bool passive;
};

class ExampleRun : public ::testing::TestWithParam<RunCase> {};

TEST_P(ExampleRun, RunsWithTheExpectedSummary) {
  const RunCase c = GetParam();
  const Output o = runCommand(program("cli/appell") + " run " + example(c.file) +
                              " --duration 1 --quiet");
  ASSERT_EQ(o.status, 0) << o.output;
  EXPECT_LT(number(o.output, R"(max \|Av\+b\| = ([0-9.eE+-]+))"), 1e-10) << o.output;
  EXPECT_LT(number(o.output, R"(max \|gap\| = ([0-9.eE+-]+))"), 1e-10) << o.output;
  EXPECT_EQ(number(o.output, R"(redundant\s+([0-9]+) rows)"), c.redundant) << o.output;
  EXPECT_NE(o.output.find("events       none"), std::string::npos) << o.output;
  EXPECT_EQ(o.output.find("would lift off"), std::string::npos) << o.output;
  // Passive: E is conserved. Driven (joint forces, a turntable): the work
  // balance E − work in − E₀ holds instead, the work integrated with the
  // state by dopri5's own weights (tests/test_work_balance.cpp).
  EXPECT_LT(number(o.output, R"(\(([0-9.eE+-]+) relative\))"), 1e-8) << o.output;
  if (!c.passive) {
    EXPECT_NE(o.output.find("− work in − E0|"), std::string::npos) << o.output;
    const double in = number(o.output, R"(joint forces ([0-9.eE+-]+) J)") +
                      number(o.output, R"(moving supports ([0-9.eE+-]+) J in)");
    EXPECT_GT(std::abs(in), 1e-6) << "a driven scene puts work in\n" << o.output;
  }
  // info: the same rows and redundancy at the initial state.
  const Output info = runCommand(program("cli/appell") + " info " + example(c.file));
  ASSERT_EQ(info.status, 0) << info.output;
  EXPECT_EQ(number(info.output, R"(\(([0-9]+) redundant\))"), c.redundant) << info.output;
}

INSTANTIATE_TEST_SUITE_P(
    AllExamples, ExampleRun,
    ::testing::Values(RunCase{"rolling_disk/rolling_disk.urdf", 0, true},
                      RunCase{"ball_turntable/ball_turntable.urdf", 0, false},
                      RunCase{"sleigh/sleigh.urdf", 0, true},
                      RunCase{"hemisphere_bowl/hemisphere_bowl.urdf", 0, true},
                      RunCase{"ellipsoid/ellipsoid.urdf", 0, true},
                      RunCase{"diff_drive/diff_drive.urdf", 1, false},
                      RunCase{"diff_drive/diff_drive_turn.urdf", 1, false},
                      RunCase{"diff_drive/diff_drive_servo.urdf", 1, false},
                      RunCase{"car/car.urdf", 3, true},
                      RunCase{"ntrailer/ntrailer3.urdf", 0, false}),
    [](const ::testing::TestParamInfo<RunCase>& p) {
      std::string n = p.param.file;
      n = n.substr(n.find('/') + 1);
      return n.substr(0, n.find('.'));
    });

TEST(ExampleCli, CarInfoReportsRankAndRedundancy) {
  const Output o = runCommand(program("cli/appell") + " info " + example("car/car.urdf"));
  ASSERT_EQ(o.status, 0) << o.output;
  EXPECT_NE(o.output.find("12 of 12 rows closed, rank 9 (3 redundant)"), std::string::npos) << o.output;
  EXPECT_NE(o.output.find("1 independent velocities"), std::string::npos) << o.output;
}

// examples/steered_car as a user runs it ("drive, then turn"): one event,
// the outer front tyre starting to scrub as the hand wheel starts to turn at
// t = 2 s; it slides from there (fewer samples than the run's, at most
// 3·10⁻⁴ of the 1 m/s), the others roll, and the work balance — friction
// included — closes.
TEST(ExampleCli, SteeredCarRunReportsTheOuterTyresScrub) {
  const Output o = runCommand(program("cli/appell") + " run " +
                              example("steered_car/steered_car.urdf") + " --quiet");
  ASSERT_EQ(o.status, 0) << o.output;
  EXPECT_NE(o.output.find("contact events (1;"), std::string::npos) << o.output;
  const double slip_t = number(o.output, R"(\n  t = ([0-9.]+) +slip  fr\n)");
  EXPECT_GT(slip_t, 2.0) << o.output;
  EXPECT_LT(slip_t, 2.005) << o.output;
  const double samples = number(o.output, R"(contacts \(over ([0-9]+) samples\))");
  const double sliding = number(o.output, R"(\n  fr .*sliding in ([0-9]+) samples)");
  EXPECT_GT(sliding, 0.5 * samples) << o.output;
  EXPECT_LT(sliding, samples) << o.output;
  EXPECT_LT(number(o.output, R"(\n  fr .*slip speed max ([0-9.eE+-]+) m/s)"), 3.2e-4) << o.output;
  EXPECT_LT(number(o.output, R"(\n  rl .*demand max ([0-9.eE+-]+))"), 0.9) << o.output;
  EXPECT_FALSE(std::regex_search(o.output, std::regex(R"(\n  r[lr] [^\n]*sliding)"))) << o.output;
  EXPECT_LT(number(o.output, R"(\(([0-9.eE+-]+) relative\))"), 1e-10) << o.output;
  EXPECT_GT(number(o.output, R"(friction ([0-9.eE+-]+) J out)"), 0.05) << o.output;
}

TEST(ExampleCli, CarRunWritesLoadsOnAllFourWheels) {
  TempDir dir;
  const std::string csv = dir / "car.csv";
  const Output o = runCommand(program("cli/appell") + " run " + example("car/car.urdf") +
                              " --duration 0.5 --quiet --out " + csv);
  ASSERT_EQ(o.status, 0) << o.output;
  for (const char* w : {"front_left", "front_right", "rear_left", "rear_right"}) {
    // "  front_left_tyre    normal load 71.12 … 71.12 N"
    const double load = number(o.output, std::string(w) + R"(_tyre\s+normal load ([0-9.]+))");
    EXPECT_NEAR(load, w[0] == 'f' ? 71.1225 : 46.5975, 0.01) << o.output;
  }
  const std::string header = readFile(csv).substr(0, readFile(csv).find('\n'));
  EXPECT_NE(header.find("lambda:rear_right_tyre.normal"), std::string::npos) << header;
}

// ---------------------------------------------------------------------------
// Generators.

TEST(ExampleGenerators, MakeNTrailerReproducesTheCommittedFile) {
  TempDir dir;
  const std::string out = dir / "ntrailer3.urdf";
  const Output o = runCommand(program("examples/example_make_ntrailer") + " 3 " + out);
  ASSERT_EQ(o.status, 0) << o.output;
  EXPECT_EQ(readFile(out), readFile(example("ntrailer/ntrailer3.urdf")))
      << "examples/ntrailer/ntrailer3.urdf is stale: regenerate it (docs/examples.md)";
}

TEST(ExampleGenerators, MakeNTrailerScalesToTenTrailers) {
  TempDir dir;
  const std::string out = dir / "ntrailer10.urdf";
  const Output o = runCommand(program("examples/example_make_ntrailer") + " 10 " + out);
  ASSERT_EQ(o.status, 0) << o.output;
  const Scene s = loadScene(out);
  EXPECT_EQ(s.model.nv, 6 + 2 * 10);
  EXPECT_EQ(s.constraintRows(), 4 + 2 * 10);
  const Output run = runCommand(program("cli/appell") + " run " + out + " --duration 1 --quiet");
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_EQ(number(run.output, R"(redundant\s+([0-9]+) rows)"), 0) << run.output;
  EXPECT_LT(number(run.output, R"(max \|Av\+b\| = ([0-9.eE+-]+))"), 1e-10) << run.output;
}

TEST(ExampleGenerators, MakeNTrailerRejectsBadArguments) {
  for (const char* args : {"", " 0", " -2", " 3x", " abc"}) {
    const Output o = runCommand(program("examples/example_make_ntrailer") + args);
    EXPECT_EQ(o.status, 2) << "args '" << args << "': " << o.output;
    EXPECT_FALSE(o.output.empty());
  }
}

TEST(ExampleGenerators, MakeMeshesReproducesTheCommittedMeshes) {
  TempDir dir;
  const std::string out = dir / "examples";
  const Output o = runCommand(program("examples/example_make_meshes") + " " + out);
  ASSERT_EQ(o.status, 0) << o.output;
  EXPECT_NE(o.output.find("2176 triangles"), std::string::npos) << o.output;  // the wheel
  EXPECT_NE(o.output.find("sole.stl: 56 vertices, 108 triangles"), std::string::npos) << o.output;
  for (const char* f : {"diff_drive/meshes/wheel.stl", "diff_drive/meshes/wheel.dae", "biped/meshes/sole.stl"}) {
    const std::string made = readFile(out + "/" + f), committed = readFile(example(f));
    EXPECT_FALSE(made.empty()) << f;
    EXPECT_LT(made.size(), 200u * 1024) << f;
    EXPECT_TRUE(made == committed) << "examples/" << f << " is stale: regenerate it (docs/examples.md)";
  }
}

// The examples whose contacts make and break (docs/contacts.md §7): they run
// to the end, list their events, write a CSV row per event with the closed:
// and event: columns, and (passive) keep E + impact losses constant.
struct EventCase {
  const char* file;
  const char* contact;  ///< a contact whose columns are checked
  int min_events;
  int min_event_times;  ///< distinct times with events (several contacts may switch at once)
};

class ExampleEvents : public ::testing::TestWithParam<EventCase> {};

TEST_P(ExampleEvents, RunListsTheEventsAndWritesARowForEach) {
  const EventCase c = GetParam();
  TempDir dir;
  const std::string csv = dir / "events.csv";
  const Output o = runCommand(program("cli/appell") + " run " + example(c.file) +
                              " --duration 3 --quiet --every 1000 --out " + csv);
  ASSERT_EQ(o.status, 0) << o.output;
  EXPECT_GE(number(o.output, R"(contact events \(([0-9]+);)"), c.min_events) << o.output;
  EXPECT_LT(number(o.output, R"(\(([0-9.eE+-]+) relative\))"), 1e-8) << o.output;
  EXPECT_LT(number(o.output, R"(max \|Av\+b\| = ([0-9.eE+-]+))"), 1e-10) << o.output;
  const TrajectoryTable t = readTrajectory(csv);
  const int closed = t.require(std::string("closed:") + c.contact);
  const int event = t.require(std::string("event:") + c.contact);
  std::vector<int> events;
  for (int k = 0; k < static_cast<int>(t.columns.size()); ++k)
    if (t.columns[k].rfind("event:", 0) == 0) events.push_back(k);
  int rows_with_events = 0, open_rows = 0;
  for (const auto& row : t.rows) {
    bool any = false;
    for (int k : events) {
      any = any || row[k] != 0;
      EXPECT_GE(row[k], 0);
      EXPECT_LE(row[k], 5);
    }
    rows_with_events += any ? 1 : 0;
    open_rows += row[closed] == 0 ? 1 : 0;
    EXPECT_TRUE(row[event] == 0 || row[closed] == (row[event] == 2 || row[event] == 3 ? 0 : 1))
        << "after a bounce or lift-off open; after a touchdown, slip or stick closed";
  }
  // --every 1000 keeps few ordinary rows, but every event has its row.
  EXPECT_GE(rows_with_events, c.min_event_times);
  EXPECT_LT(static_cast<long>(t.rows.size()), rows_with_events + 10);
  EXPECT_GT(open_rows, 0);
}

INSTANTIATE_TEST_SUITE_P(
    EventExamples, ExampleEvents,
    ::testing::Values(EventCase{"bouncing_ball/bouncing_ball.urdf", "floor_contact", 18, 18},
                      EventCase{"rimless_wheel/rimless_wheel.urdf", "foot1_l", 28, 7},
                      EventCase{"ball_gutter/ball_gutter.urdf", "walls/p0", 6, 3}),
    [](const ::testing::TestParamInfo<EventCase>& p) {
      std::string n = p.param.file;
      n = n.substr(n.find('/') + 1);
      return n.substr(0, n.find('.'));
    });

}  // namespace
}  // namespace appell
