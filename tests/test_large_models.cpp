// Models of 10⁵ bodies: loading, a simulator and a step cost O(n) memory
// (no nv × nv mass matrix, no m × nv rows on the tree path, no stored paths),
// and the step is right: a chain falling freely from rest keeps its shape.
//
// Memory is read from glibc's allocator (mallinfo2: bytes in use), so the
// test asserts the growth from 10⁴ to 10⁵ links — linear, not quadratic —
// rather than any time (speed belongs to the benchmarks).
#include <appell/appell.hpp>
#include <appell/run.hpp>
#include <appell/urdf.hpp>

#include <gtest/gtest.h>

#include <malloc.h>

#include <sstream>

using namespace appell;

namespace {

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif
#else
constexpr bool kSanitized = false;
#endif

/// A chain of n links on continuous joints about y, each hanging 0.1 m
/// below its parent; the first link's joint to the world is floating. With
/// `limits`, revolute joints limited to [0, 1] rad: every joint starts at its
/// lower limit, so all 2n limits are declared and n of them start closed.
std::string chainUrdf(int n, bool limits = false) {
  std::ostringstream u;
  u << "<robot name=\"chain\">\n";
  const char* inertial =
      "<inertial><mass value=\"1\"/><inertia ixx=\"0.01\" iyy=\"0.01\" izz=\"0.01\" ixy=\"0\" "
      "ixz=\"0\" iyz=\"0\"/></inertial>";
  for (int i = 0; i <= n; ++i) u << "<link name=\"l" << i << "\">" << inertial << "</link>\n";
  for (int i = 0; i < n; ++i)
    u << "<joint name=\"j" << i << "\" type=\"" << (limits ? "revolute" : "continuous")
      << "\"><parent link=\"l" << i << "\"/><child link=\"l" << i + 1
      << "\"/><origin xyz=\"0 0 -0.1\"/><axis xyz=\"0 1 0\"/>"
      << (limits ? "<limit lower=\"0\" upper=\"1\" effort=\"10\" velocity=\"1\"/>" : "")
      << "</joint>\n";
  u << "</robot>\n";
  return u.str();
}

std::size_t bytesInUse() {
  const struct mallinfo2 mi = mallinfo2();
  return mi.uordblks + mi.hblkhd;
}

struct Measured {
  std::size_t bytes = 0;  ///< held by the scene and the simulator after one step
  double max_joint_rate = 0, root_speed_error = 0;
};

Measured loadAndStep(int n, bool limits = false) {
  Measured out;
  const std::string xml = chainUrdf(n, limits);
  const std::size_t before = bytesInUse();
  {
    const Scene scene = loadSceneFromString(xml, ".");
    EXPECT_EQ(scene.model.nbodies, n + 1);
    EXPECT_EQ(static_cast<int>(scene.joint_limits.size()), limits ? 2 * n : 0);
    RunOptions options = runOptions(scene.settings);
    options.formulation = Formulation::Tree;
    options.integrator = IntegratorType::RK4;
    const auto sim = makeSimulator(scene, options);
    const double h = 1e-3;
    const StepStatus st = sim->step(h);
    EXPECT_TRUE(st.ok) << st.message;
    out.bytes = bytesInUse() - before;
    // Free fall from rest in a uniform field: no relative motion, and the
    // floating root's linear velocity (body frame = world frame here) is g h.
    const Model& m = scene.model;
    const VecX& v = sim->v();
    out.max_joint_rate = v.tail(m.nv - 6).lpNorm<Eigen::Infinity>();
    out.root_speed_error = (v.segment<3>(3) - m.gravity * h).norm();
  }
  return out;
}

/// Loads and steps chains of 10⁴ and 10⁵ links: both fall as one body, and
/// 10× the links take ~10× the memory (a dense nv × nv matrix would be 100×).
void expectLinearMemory(bool limits) {
  const Measured small = loadAndStep(10000, limits), large = loadAndStep(100000, limits);
  for (const Measured* r : {&small, &large}) {
    EXPECT_LT(r->max_joint_rate, 1e-9);
    EXPECT_LT(r->root_speed_error, 1e-12);
  }
  ASSERT_GT(small.bytes, 0u);
  const double growth = static_cast<double>(large.bytes) / static_cast<double>(small.bytes);
  ::testing::Test::RecordProperty("bytes_per_body", static_cast<int>(large.bytes / 100000));
  EXPECT_LT(growth, 12.0) << small.bytes << " → " << large.bytes << " bytes";
  EXPECT_LT(large.bytes / 100000.0, 64.0 * 1024) << "bytes per body";
}

/// n balls (radius 0.1 m, 1 kg) at rest on a floor, each on a floating
/// joint from the world, each touching with μ = 0.5: n islands of one
/// frictional contact (engine/src/simulator/islands.cpp).
std::string ballsUrdf(int n) {
  std::ostringstream u;
  u << "<robot name=\"balls\">\n<link name=\"world\"/>\n";
  for (int i = 0; i < n; ++i)
    u << "<link name=\"b" << i << "\"><inertial><mass value=\"1\"/><inertia ixx=\"0.004\" "
      << "iyy=\"0.004\" izz=\"0.004\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial></link>\n"
      << "<joint name=\"j" << i << "\" type=\"floating\"><parent link=\"world\"/><child link=\"b" << i
      << "\"/><origin xyz=\"" << 0.3 * (i % 60) << " " << 0.3 * (i / 60) << " 0.1\"/></joint>\n";
  u << "<appell><gravity xyz=\"0 0 -9.81\"/>"
    << "<support name=\"floor\" type=\"plane\" normal=\"0 0 1\" offset=\"0\"/>\n";
  for (int i = 0; i < n; ++i)
    u << "<contact name=\"c" << i << "\" link=\"b" << i
      << "\" kind=\"rolling\" shape=\"sphere\" radius=\"0.1\" support=\"floor\" mu=\"0.5\"/>\n";
  u << "</appell></robot>\n";
  return u.str();
}

/// Bytes held by n balls' scene and simulator after one step; the balls
/// stay at rest (each sticking, its normal load m g).
std::size_t ballsBytes(int n) {
  const std::size_t before = bytesInUse();
  std::size_t bytes = 0;
  {
    const Scene scene = loadSceneFromString(ballsUrdf(n), ".");
    const auto sim = makeSimulator(scene, runOptions(scene.settings));
    const StepStatus st = sim->step(1e-3);
    EXPECT_TRUE(st.ok) << st.message;
    bytes = bytesInUse() - before;
    EXPECT_LT(sim->v().lpNorm<Eigen::Infinity>(), 1e-12) << "at rest";
    EXPECT_NEAR(sim->lambda()[2], 9.81, 1e-9) << "the first ball's normal load";
  }
  return bytes;
}

}  // namespace

// Protects: friction-contact bookkeeping O(contacts) (docs/hardening.md,
// "Memory"). The friction problems' storage is sized for the largest island,
// not for every contact: 3 000 balls with friction once took 5.1 GB (a
// 6 000 × 6 000 friction operator and its kin), and 1 000 → 3 000 balls
// grew it 9×.
TEST(LargeModels, ThreeThousandBallsWithFrictionTakeLinearMemory) {
  if (kSanitized) GTEST_SKIP() << "mallinfo2 does not see a sanitizer's allocator";
  const std::size_t small = ballsBytes(1000), large = ballsBytes(3000);
  ASSERT_GT(small, 0u);
  ::testing::Test::RecordProperty("bytes_3000_balls", static_cast<int>(large));
  EXPECT_LT(static_cast<double>(large) / static_cast<double>(small), 3.6) << small << " → " << large;
  EXPECT_LT(large, 200u << 20) << "bytes for 3 000 balls";
}

TEST(LargeModels, ChainOf100000LinksLoadsAndStepsInLinearMemory) {
  if (kSanitized) GTEST_SKIP() << "mallinfo2 does not see a sanitizer's allocator";
  expectLinearMemory(false);
}

// Protects: joint limits keep it O(n) — the rows are sparse (one column
// each), a closed limit locks its joint inside the tree solver's passes
// (no loop rows, no k × n workspace), and the position projection's Newton
// step is the tree solver's, not a dense factorization. 2·10⁵ limits, 10⁵ of
// them closed at the start; the chain falls as one body.
TEST(LargeModels, ChainOf100000LimitedJointsLoadsAndStepsInLinearMemory) {
  if (kSanitized) GTEST_SKIP() << "mallinfo2 does not see a sanitizer's allocator";
  expectLinearMemory(true);
}
