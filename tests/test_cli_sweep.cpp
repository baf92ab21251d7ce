// appell linearize with overrides and sweeps: the rolling disk's classical
// stability threshold found by one command, full-precision JSON and CSV
// equal to the C++ API's results to round-off, and bad overrides named.
#include <appell/appell.hpp>
#include <appell/linearization.hpp>
#include <appell/run.hpp>
#include <appell/urdf.hpp>

#include "run_command.hpp"
#include "scene.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <filesystem>
#include <regex>
#include <sstream>
#include <string>

using namespace appell;

namespace {

const std::string kChain = std::string(APPELL_SOURCE_DIR) + "/tests/data/linearize/disk_chain.urdf";
const std::string kCyclic = " --cyclic plane.x,plane.y,plane.theta,spin";

test::CommandResult sh(const std::string& args) { return test::runAppell(args); }

std::vector<double> numbersAfter(const std::string& text, const std::string& key) {
  std::vector<double> out;
  const auto at = text.find(key);
  if (at == std::string::npos) return out;
  const auto end = text.find("]]", at);  // the nested list of [re, im] pairs ends at "]]"
  const std::string tail = text.substr(at + key.size(), end - at - key.size());
  std::regex num(R"([-+]?[0-9.]+(e[-+]?[0-9]+)?)");
  for (auto it = std::sregex_iterator(tail.begin(), tail.end(), num); it != std::sregex_iterator(); ++it)
    out.push_back(std::stod(it->str()));
  return out;
}

}  // namespace

// The upright thin disk rolling straight is stable exactly above
// ω = √(g/(3R)) (speed √(gR/3)); one command sweeps the spin rate, finds the
// change by bisection and draws the diagram.
TEST(CliSweep, RollingDiskStabilityThresholdIsFoundByOneCommand) {
  const std::string png = ::testing::TempDir() + "disk_stability.png";
  std::filesystem::remove(png);
  const auto r = sh("linearize " + kChain + " --sweep spin.velocity=1:6:11" + kCyclic + " --plot " + png);
  ASSERT_EQ(r.status, 0) << r.output;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.output, m, std::regex(R"(stability changes at spin.velocity ≈ ([0-9.]+))")))
      << r.output;
  EXPECT_NEAR(std::stod(m[1]), std::sqrt(9.81 / (3 * 0.3)), 1e-6) << r.output;
  EXPECT_NE(r.output.find("               1          4.874423  unstable"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("no growing mode"), std::string::npos) << r.output;
  EXPECT_GT(std::filesystem::file_size(png), 1000u);  // gnuplot drew it
}

// --set spin.velocity=5 --format json: the eigenvalues equal those of the C++
// API on the same state (spin kept, the planar rates completed) to round-off.
TEST(CliSweep, JsonAndCsvCarryTheCppApiResultsAtFullPrecision) {
  const auto r = sh("linearize " + kChain + " --set spin.velocity=5" + kCyclic + " --format json");
  ASSERT_EQ(r.status, 0) << r.output;
  const std::vector<double> cli = numbersAfter(r.output, "\"eigenvalues\": [");
  Scene s = loadScene(kChain);
  const int spin = s.model.joints[s.model.jointIndex("spin")].idx_v;
  s.v0[spin] = 5;
  std::vector<int> dependent;
  for (int j = 0; j < s.model.nv; ++j)
    if (j != spin) dependent.push_back(j);
  scenes::completeVelocity(s.model, s.constraints, s.q0, s.v0, dependent);
  LinearizationOptions lo;
  lo.cyclic = {0, 1, 2, spin};
  const LinearizationResult lin =
      linearize(s.model, s.constraints, *makeSolver(Formulation::Tree, s.model, s.constraints), s.q0, s.v0, lo);
  std::vector<std::complex<double>> ev(lin.eigenvalues.data(), lin.eigenvalues.data() + lin.eigenvalues.size());
  std::sort(ev.begin(), ev.end(), [](auto x, auto y) {
    return x.real() != y.real() ? x.real() > y.real() : x.imag() > y.imag();
  });
  ASSERT_EQ(cli.size(), 2 * ev.size()) << r.output;
  for (std::size_t k = 0; k < ev.size(); ++k) {
    EXPECT_NEAR(cli[2 * k], ev[k].real(), 1e-14 * (1 + std::abs(ev[k]))) << k;
    EXPECT_NEAR(cli[2 * k + 1], ev[k].imag(), 1e-14 * (1 + std::abs(ev[k]))) << k;
  }
  // The oscillation of the stable disk: a purely imaginary pair.
  EXPECT_GT(std::abs(ev[0].imag()) + std::abs(ev[1].imag()), 1.0);
  auto csv = sh("linearize " + kChain + " --sweep spin.velocity=5:5:1" + kCyclic + " --format csv");
  ASSERT_EQ(csv.status, 0) << csv.output;
  // The CSV is stdout; sh() also holds stderr, where the load says that the
  // chain's virtual links (heading, lean_frame) are massless, carried by the disk.
  for (auto at = csv.output.find("appell: warning: "); at == 0; at = csv.output.find("appell: warning: "))
    csv.output.erase(0, csv.output.find('\n') + 1);
  EXPECT_EQ(csv.output.rfind("spin.velocity,verdict,max_real,re0,im0", 0), 0u) << csv.output;
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", ev[0].real());
  EXPECT_NE(csv.output.find(std::string("5,stable,") + buf), std::string::npos) << csv.output << buf;
}

// The Whipple bicycle (examples/bicycle): running straight is steady at any
// speed, so its own direction is a null vector of L and the zero tolerance
// would hide where the capsize eigenvalue crosses 0. With --family that
// direction is removed and one sweep finds Meijaard et al. (2007)'s weave
// and capsize speeds (§5: 4.29238253634111 and 6.02426201538837 m/s) by
// bisection on the sign of the largest real part. Measured: 2e-9 and 3e-8
// m/s, the finite-difference L's accuracy (tests/test_linearization_bicycle.cpp).
TEST(CliSweep, BicycleWeaveAndCapsizeSpeedsByOneSweepOfAFamily) {
  const std::string bike = std::string(APPELL_SOURCE_DIR) + "/examples/bicycle/bicycle.urdf";
  const std::string cyclic = " --cyclic plane.x,plane.y,plane.theta,rear_spin,front_spin";
  const auto r = sh("linearize " + bike + cyclic + " --sweep plane.vx=3:7:5 --family --format json");
  ASSERT_EQ(r.status, 0) << r.output;
  const std::vector<double> changes = numbersAfter(r.output, "\"stability_changes\": [");
  ASSERT_EQ(changes.size(), 2u) << r.output;
  EXPECT_NEAR(changes[0], 4.29238253634111, 1e-7) << r.output;
  EXPECT_NEAR(changes[1], 6.02426201538837, 1e-7) << r.output;
  // Without --family the speed's own zero eigenvalue sits at the threshold:
  // the capsize change is found only to the zero tolerance, if at all.
  const auto coarse = sh("linearize " + bike + cyclic + " --sweep plane.vx=3:7:5 --format json");
  ASSERT_EQ(coarse.status, 0) << coarse.output;
  const std::vector<double> rough = numbersAfter(coarse.output, "\"stability_changes\": [");
  bool capsize_to_1e7 = false;
  for (double c : rough) capsize_to_1e7 = capsize_to_1e7 || std::abs(c - 6.02426201538837) < 1e-7;
  EXPECT_FALSE(capsize_to_1e7) << coarse.output;
  // At rest there is no family to remove; an equilibrium has none either.
  const auto rest = sh("linearize " + bike + cyclic + " --set plane.vx=0 --family");
  EXPECT_EQ(rest.status, 2) << rest.output;
  EXPECT_NE(rest.output.find("--family: the reference velocity is zero"), std::string::npos) << rest.output;
  const auto eq = sh("linearize " + bike + " --equilibrium --family");
  EXPECT_EQ(eq.status, 2) << eq.output;
  EXPECT_NE(eq.output.find("an equilibrium (v = 0) has none"), std::string::npos) << eq.output;
}

// Overrides that cannot be applied say why: an unknown name, a vector of the
// wrong size, a velocity the constraints forbid, speed without a floating base.
TEST(CliSweep, BadOverridesAreNamed) {
  auto err = [](const std::string& args) { return sh("linearize " + kChain + " " + args); };
  EXPECT_NE(err("--set wobble=1").output.find("--set wobble: not gravity, speed"), std::string::npos);
  EXPECT_NE(err("--set gravity=0,0").output.find("--set gravity: needs gx,gy,gz"), std::string::npos);
  EXPECT_NE(err("--set speed=1").output.find("not a floating base"), std::string::npos);
  EXPECT_NE(err("--set plane.vy=1 --set spin.velocity=2").output.find("the constraints do not allow"),
            std::string::npos);
  EXPECT_NE(err("--sweep spin.velocity=1:2").output.find("START:STOP:COUNT"), std::string::npos);
  EXPECT_EQ(err("--set spin.velocity=x").status, 2);
}

// appell run --sweep speed=…: one run per value, each on the C++ API's
// numbers — the car rolls straight at the commanded speed (x = V T), and the
// final state in the CSV is runScene's on the same state to round-off.
TEST(CliSweep, RunSweepOfTheCarsSpeedMatchesTheCppApi) {
  const std::string car = std::string(APPELL_SOURCE_DIR) + "/examples/car/car.urdf";
  const auto r = sh("run " + car + " --sweep speed=1:3:3 --duration 1 --format csv");
  ASSERT_EQ(r.status, 0) << r.output;
  std::vector<std::vector<std::string>> table;
  std::stringstream in(r.output);
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> cells;
    std::stringstream l(line);
    for (std::string c; std::getline(l, c, ',');) cells.push_back(c);
    table.push_back(cells);
  }
  ASSERT_EQ(table.size(), 4u) << r.output;
  const auto& head = table[0];
  const auto col = [&](const std::string& name) {
    return static_cast<std::size_t>(std::find(head.begin(), head.end(), name) - head.begin());
  };
  const std::size_t x = col("q:root_joint.x"), wheel = col("q:front_left_joint");
  ASSERT_LT(x, head.size());
  for (int k = 1; k <= 3; ++k) {
    EXPECT_EQ(table[k][1], "ok");
    EXPECT_NEAR(std::stod(table[k][x]), k * 1.0, 1e-9);  // V T, V = 1, 2, 3
  }
  // The C++ API on the same state: root vx = 2, the rest completed.
  Scene s = loadScene(car);
  const int vx = s.model.joints[0].idx_v + 3;
  s.v0.setZero();
  s.v0[vx] = 2;
  std::vector<int> dependent;
  for (int j = 0; j < s.model.nv; ++j)
    if (j != vx) dependent.push_back(j);
  scenes::completeVelocity(s.model, s.constraints, s.q0, s.v0, dependent);
  RunOptions o = runOptions(s.settings);
  o.duration = 1;
  VecX q;
  runScene(s, o, [&](const Simulator& sim) { q = sim.q(); });
  EXPECT_NEAR(std::stod(table[2][x]), q[0], 1e-12);
  EXPECT_NEAR(std::stod(table[2][wheel]), q[s.model.joints[s.model.jointIndex("front_left_joint")].idx_q], 1e-10);
}
