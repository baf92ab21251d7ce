// appell sweep: a grid of two names and seeded random draws through `run`,
// the Whipple bicycle's speeds through `linearize`; every row equal bit for
// bit to the same case computed alone (the C++ API and single `appell run` /
// `appell linearize` commands), the table byte for byte the same on 1 and 2
// threads, and bad arguments named word for word.
#include <appell/overrides.hpp>
#include <appell/run.hpp>
#include <appell/urdf.hpp>

#include "run_command.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

using namespace appell;

namespace {

const std::string kDisk = std::string(APPELL_SOURCE_DIR) + "/examples/rolling_disk/rolling_disk.urdf";
const std::string kBike = std::string(APPELL_SOURCE_DIR) + "/examples/bicycle/bicycle.urdf";
const std::string kChain = std::string(APPELL_SOURCE_DIR) + "/tests/data/linearize/disk_chain.urdf";

using Row = std::map<std::string, std::string>;

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// A CSV whose text cells hold no comma (every cell of these sweeps' ok rows).
std::vector<Row> readCsv(const std::string& text) {
  std::vector<std::vector<std::string>> lines;
  std::stringstream in(text);
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> cells;
    std::stringstream l(line);
    for (std::string c; std::getline(l, c, ',');) cells.push_back(c);
    if (!line.empty() && line.back() == ',') cells.push_back("");
    lines.push_back(cells);
  }
  std::vector<Row> rows;
  for (std::size_t k = 1; k < lines.size(); ++k) {
    Row r;
    for (std::size_t i = 0; i < lines[0].size() && i < lines[k].size(); ++i) r[lines[0][i]] = lines[k][i];
    rows.push_back(r);
  }
  return rows;
}

// `appell ARGS --out FILE`: the table written to a file (stderr apart).
std::string sweepTable(const std::string& args, int expected_status = 0) {
  // A file per test and call: ctest runs the tests as parallel processes.
  static int calls = 0;
  const std::string out = ::testing::TempDir() + "sweep_" +
                          ::testing::UnitTest::GetInstance()->current_test_info()->name() + "_" +
                          std::to_string(++calls) + ".txt";
  std::remove(out.c_str());
  const auto r = test::runAppell("sweep " + args + " --out " + out);
  EXPECT_EQ(r.status, expected_status) << r.output;
  return slurp(out);
}

// A case run alone through the C++ API, as the sweep documents it: the
// scene as loaded, the overrides in order, the velocities completed once,
// the initial state checked.
struct Single {
  RunSummary summary;
  VecX q, v;
  double energy = 0;
  std::vector<std::string> qn, vn;
};
Single runAlone(const std::string& path, const std::vector<std::pair<std::string, double>>& overrides,
                double duration) {
  LoadOptions lo;
  lo.check_initial_state = false;
  Scene s = loadScene(path, lo);
  OverrideReport report;
  for (const auto& [name, value] : overrides) applyOverride(s, name, {value}, report);
  completeVelocities(s, report);
  checkInitialState(s, false, LoadOptions().initial_state_tolerance);
  RunOptions o = runOptions(s.settings);
  o.duration = duration;
  Single out;
  out.summary = runScene(s, o, [&](const Simulator& sim) {
    out.q = sim.q();
    out.v = sim.v();
    out.energy = sim.energy();
  });
  out.qn = coordinateNames(s.model, false);
  out.vn = coordinateNames(s.model, true);
  return out;
}

// Every number of the row equals the single run's, bit for bit (the table's
// numbers are the shortest text of each double; strtod reads them back exactly).
void expectRowEqualsSingle(const Row& row, const Single& s) {
  auto num = [&](const std::string& key) { return std::stod(row.at(key)); };
  EXPECT_EQ(row.at("status"), "ok");
  EXPECT_EQ(num("time"), s.summary.time);
  EXPECT_EQ(std::stol(row.at("steps")), s.summary.counters.steps);
  EXPECT_EQ(num("energy"), s.energy);
  EXPECT_EQ(num("energy0"), s.summary.energy0);
  EXPECT_EQ(num("friction_work"), s.summary.friction_work);
  EXPECT_EQ(num("max_energy_deviation"), s.summary.max_energy_deviation);
  EXPECT_EQ(num("max_velocity_residual"), s.summary.max_velocity_residual);
  EXPECT_EQ(num("max_gap_residual"), s.summary.max_gap_residual);
  EXPECT_EQ(std::stoul(row.at("events")), s.summary.events.size());
  for (int i = 0; i < s.q.size(); ++i) EXPECT_EQ(num("q:" + s.qn[i]), s.q[i]) << s.qn[i];
  for (int i = 0; i < s.v.size(); ++i) EXPECT_EQ(num("v:" + s.vn[i]), s.v[i]) << s.vn[i];
}

}  // namespace

// Two grid axes: every combination, the last name fastest, each row the
// single run's numbers — through the C++ API and through `appell run --set
// … --out`, whose last trajectory row is the same final state.
TEST(CliSweepCommand, GridOfTwoNamesEqualsSingleRunsBitForBit) {
  const std::string table =
      sweepTable(kDisk + " --vary speed=1:2:3 --vary root_joint.wx=0.2:0.5:2 --duration 0.4 -j2");
  const std::vector<Row> rows = readCsv(table);
  ASSERT_EQ(rows.size(), 6u) << table;
  const double speeds[] = {1, 1.5, 2}, lean_rates[] = {0.2, 0.5};
  for (int k = 0; k < 6; ++k) {
    const double speed = speeds[k / 2], lean_rate = lean_rates[k % 2];
    EXPECT_EQ(std::stod(rows[k].at("speed")), speed);
    EXPECT_EQ(std::stod(rows[k].at("root_joint.wx")), lean_rate);
    expectRowEqualsSingle(rows[k], runAlone(kDisk, {{"speed", speed}, {"root_joint.wx", lean_rate}}, 0.4));
  }
  const std::string traj = ::testing::TempDir() + "sweep_command_single_run.csv";
  const auto single = test::runAppell("run " + kDisk + " --set speed=1.5 --set root_joint.wx=0.5 --duration 0.4 --quiet --out " + traj);
  ASSERT_EQ(single.status, 0) << single.output;
  const std::vector<Row> steps = readCsv(slurp(traj));
  ASSERT_FALSE(steps.empty());
  int compared = 0;
  for (const auto& [key, value] : steps.back())
    if (key.rfind("q:", 0) == 0 || key.rfind("v:", 0) == 0) {
      EXPECT_EQ(rows[3].at(key), value) << key;
      ++compared;
    }
  EXPECT_EQ(compared, 13);  // nq 7 + nv 6 of the free disk
}

// uniform(LOW,HIGH) with --samples and --seed: the values are the
// documented draws (mt19937_64 from the seed, LOW + (HIGH − LOW)·k·2⁻⁵³ from
// its top 53 bits), each row equals its single run, and the seed decides.
TEST(CliSweepCommand, SeededRandomDrawsAreTheDocumentedOnesAndEqualSingleRuns) {
  const std::string args = kDisk + " --vary 'speed=uniform(1,3)' --samples 4 --duration 0.3";
  const std::vector<Row> rows = readCsv(sweepTable(args + " --seed 7"));
  ASSERT_EQ(rows.size(), 4u);
  std::mt19937_64 engine(7);
  for (const Row& row : rows) {
    const double speed = 1 + 2 * (static_cast<double>(engine() >> 11) * 0x1.0p-53);
    EXPECT_EQ(std::stod(row.at("speed")), speed);
    expectRowEqualsSingle(row, runAlone(kDisk, {{"speed", speed}}, 0.3));
  }
  EXPECT_EQ(readCsv(sweepTable(args + " --seed 7"))[2].at("speed"), rows[2].at("speed"));
  EXPECT_NE(readCsv(sweepTable(args + " --seed 8"))[2].at("speed"), rows[2].at("speed"));
}

// The rows and every number in them do not depend on the threads: with
// --no-timing the CSV and the JSON are byte for byte the same for -j1 and -j2.
TEST(CliSweepCommand, OneAndTwoThreadsWriteTheSameBytes) {
  const std::string args = kDisk + " --vary speed=0.5:3:6 --vary 'rim.mu=normal(0.6,0.1)' --seed 3 --duration 0.3 --no-timing";
  const std::string csv1 = sweepTable(args + " -j1"), csv2 = sweepTable(args + " -j 2");
  EXPECT_EQ(csv1, csv2);
  EXPECT_EQ(readCsv(csv1).size(), 6u);
  EXPECT_EQ(csv1.find("wall_seconds"), std::string::npos);
  const std::string json1 = sweepTable(args + " --json --jobs 1"), json2 = sweepTable(args + " --json --jobs=2");
  EXPECT_EQ(json1, json2);
  EXPECT_EQ(json1.rfind("{\"scene\": \"" + kDisk + "\", \"analysis\": \"run\", \"seed\": 3, \"cases\": [", 0), 0u)
      << json1.substr(0, 200);
  // With the timing column, every other column is still the same.
  std::vector<Row> a = readCsv(sweepTable(kDisk + " --vary speed=0.5:3:6 --duration 0.3 -j1"));
  std::vector<Row> b = readCsv(sweepTable(kDisk + " --vary speed=0.5:3:6 --duration 0.3 -j2"));
  ASSERT_EQ(a.size(), 6u);
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_GT(std::stod(a[k].at("wall_seconds")), 0);
    a[k].erase("wall_seconds");
    b[k].erase("wall_seconds");
    EXPECT_EQ(a[k], b[k]) << k;
  }
}

// The bicycle through linearize: each row's eigenvalues are those of
// `appell linearize --set plane.vx=V --family`, bit for bit; the verdicts
// are Meijaard et al. (2007)'s at 3, 4, 5, 6, 7 m/s — weave-unstable below 4.29 m/s, stable up
// to the capsize speed 6.02 m/s, capsize-unstable above.
TEST(CliSweepCommand, BicycleSpeedsThroughLinearizeEqualSingleLinearizations) {
  const std::string opts = " --cyclic plane.x,plane.y,plane.theta,rear_spin,front_spin --family";
  const std::vector<Row> rows =
      readCsv(sweepTable(kBike + " --analysis linearize --vary plane.vx=3:7:5" + opts + " -j2"));
  ASSERT_EQ(rows.size(), 5u);
  const char* verdicts[] = {"unstable", "unstable", "not growing", "not growing", "unstable"};
  for (int k = 0; k < 5; ++k) {
    const Row& row = rows[k];
    EXPECT_EQ(row.at("status"), "ok");
    EXPECT_EQ(row.at("verdict"), verdicts[k]) << row.at("plane.vx");
    const auto one = test::runAppell("linearize " + kBike + opts + " --set plane.vx=" + row.at("plane.vx") +
                                     " --format csv");
    ASSERT_EQ(one.status, 0) << one.output;
    std::stringstream in(one.output);
    int i = 0;
    for (std::string line; std::getline(in, line);) {
      if (line.rfind("appell: warning", 0) == 0 || line == "real,imag") continue;  // stderr is merged
      const auto comma = line.find(',');
      EXPECT_EQ(std::stod(row.at("re" + std::to_string(i))), std::stod(line.substr(0, comma))) << k << " " << i;
      EXPECT_EQ(std::stod(row.at("im" + std::to_string(i))), std::stod(line.substr(comma + 1))) << k << " " << i;
      ++i;
    }
    EXPECT_EQ(i, 4);  // the reduced state's 5 dimensions less the family's direction
    EXPECT_EQ(row.at("dimension"), "5");
    EXPECT_EQ(row.count("re4"), 0u);
  }
}

// A case that cannot be computed is a row with its error, the others are
// computed, and the exit status says that not all were: the disk chain's
// lateral velocity is forbidden by its rolling constraints once the spin is
// fixed, so plane.vy = 0 runs and plane.vy = 1 is an error.
TEST(CliSweepCommand, AFailingCaseIsARowWithItsError) {
  const std::string table = sweepTable(kChain + " --analysis linearize --set spin.velocity=5 --vary plane.vy=0:1:2"
                                       " --cyclic plane.x,plane.y,plane.theta,spin --no-timing", 3);
  const std::vector<Row> rows = readCsv(table);
  ASSERT_EQ(rows.size(), 2u) << table;
  EXPECT_EQ(rows[0].at("status"), "ok") << table;
  EXPECT_EQ(rows[1].at("status"), "error") << table;
  EXPECT_NE(table.find("the constraints do not allow"), std::string::npos) << table;
  // A run that the watch stops is "failed", with the reason, not an error.
  const std::vector<Row> failed =
      readCsv(sweepTable(kDisk + " --vary speed=1:2:2 --duration 0.3 --max-residual 1e-300", 3));
  ASSERT_EQ(failed.size(), 2u);
  EXPECT_EQ(failed[0].at("status"), "failed");
  EXPECT_FALSE(failed[0].at("message").empty());
}

// Bad arguments: the message names the argument and says what is wrong.
TEST(CliSweepCommand, BadArgumentsAreNamedWordForWord) {
  auto err = [](const std::string& args) {
    const auto r = test::runAppell("sweep " + kDisk + " " + args);
    EXPECT_EQ(r.status, 2) << r.output;
    return r.output;
  };
  EXPECT_EQ(err("--vary speed=1:1:3"),
            "appell sweep: --vary speed: empty range: START equals STOP, so the 3 values would be one (give COUNT 1 "
            "for a single value) (see appell sweep --help)\n");
  EXPECT_EQ(err("--vary speed=1:2:0"),
            "appell sweep: --vary speed: COUNT must be a whole number from 1 to 100000, got 0 (see appell sweep --help)\n");
  EXPECT_EQ(err("--vary speed=1:2"),
            "appell sweep: --vary speed: expects START:STOP:COUNT, got '1:2' (see appell sweep --help)\n");
  EXPECT_EQ(err("--vary 'speed=uniform(3,1)'"),
            "appell sweep: --vary speed: empty range: HIGH must exceed LOW, got uniform(3,1) (see appell sweep --help)\n");
  EXPECT_EQ(err("--vary 'speed=gauss(1,2)'"),
            "appell sweep: --vary speed: unknown law 'gauss' (uniform(LOW,HIGH) or normal(MEAN,SD)) (see appell sweep "
            "--help)\n");
  EXPECT_EQ(err("--vary speed=1:x:3"),
            "appell sweep: --vary speed: STOP 'x' is not a finite number (see appell sweep --help)\n");
  EXPECT_EQ(err("--vary speed=1:2:3 -j0"), "appell sweep: -j/--jobs must be at least 1, not 0 (see appell sweep --help)\n");
  EXPECT_EQ(err("--vary speed=1:2:3 --samples 4"),
            "appell sweep: --samples draws random values: give a --vary NAME=uniform(LOW,HIGH) or normal(MEAN,SD) (see "
            "appell sweep --help)\n");
  EXPECT_EQ(err("--vary speed=1:2:3 --cyclic plane.x"),
            "appell sweep: --cyclic applies to --analysis linearize (see appell sweep --help)\n");
  EXPECT_EQ(err(""),
            "appell sweep: give at least one --vary NAME=START:STOP:COUNT (or NAME=uniform(LOW,HIGH)) (see appell sweep "
            "--help)\n");
  EXPECT_EQ(err("--vary wobble=1:2:3"),
            "appell sweep: --vary wobble: not gravity, speed, <joint>.position, <joint>.velocity, <joint>.effort, "
            "<contact>.mu or a coordinate's name as the CSV's q: and v: columns give it (see appell sweep --help)\n");
}
