// Friction problems island by island (engine/src/simulator/islands.cpp):
// balls that share a floor but no body are separate islands, so each one's
// sliding, sticking and impacts are decided as if it were alone — checked
// against the closed forms of a homogeneous ball (m, r, I = 2/5 m r²) and
// against the same ball simulated in a scene of its own.
#include <gtest/gtest.h>

#include <appell/appell.hpp>
#include <appell/run.hpp>
#include <appell/urdf.hpp>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

using namespace appell;

namespace {

constexpr double kG = 9.81, kM = 0.5, kR = 0.1;

struct Ball {
  std::string name;
  double mu;
  Vec3 position, velocity;  // centre, world frame
};

/// Balls on the floor z = 0 (each on a floating joint from the world), each
/// with its own μ; no spin at the start.
std::string ballsUrdf(const std::vector<Ball>& balls) {
  std::ostringstream u;
  u.precision(17);
  u << "<robot name=\"balls\">\n  <link name=\"world\"/>\n";
  const double i = 0.4 * kM * kR * kR;
  for (const Ball& b : balls) {
    u << "  <link name=\"" << b.name << "\"><inertial><mass value=\"" << kM
      << "\"/><inertia ixx=\"" << i << "\" iyy=\"" << i << "\" izz=\"" << i
      << "\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial></link>\n";
    u << "  <joint name=\"j_" << b.name << "\" type=\"floating\"><parent link=\"world\"/><child link=\""
      << b.name << "\"/></joint>\n";
  }
  u << "  <appell>\n    <gravity xyz=\"0 0 " << -kG << "\"/>\n"
    << "    <support name=\"floor\" type=\"plane\" normal=\"0 0 1\" offset=\"0\"/>\n";
  for (const Ball& b : balls)
    u << "    <contact name=\"c_" << b.name << "\" link=\"" << b.name
      << "\" kind=\"rolling\" shape=\"sphere\" radius=\"" << kR << "\" support=\"floor\" mu=\""
      << b.mu << "\"/>\n";
  u << "    <initial>\n";
  for (const Ball& b : balls)
    u << "      <joint name=\"j_" << b.name << "\" xyz=\"" << b.position.x() << " "
      << b.position.y() << " " << b.position.z() << "\" rpy=\"0 0 0\" velocity=\"0 0 0  "
      << b.velocity.x() << " " << b.velocity.y() << " " << b.velocity.z() << "\"/>\n";
  u << "    </initial>\n"
    << "    <simulation integrator=\"dopri5\" dt=\"0.01\" tol=\"1e-12\" duration=\"1\"/>\n"
    << "  </appell>\n</robot>\n";
  return u.str();
}

struct BallsRun {
  std::vector<ContactEvent> events;
  std::vector<std::string> names;  // of each event's constraint
  VecX q, v;
};

BallsRun simulate(const std::vector<Ball>& balls, double duration) {
  const Scene scene = loadSceneFromString(ballsUrdf(balls), ".");
  const auto sim = makeSimulator(scene, runOptions(scene.settings));
  BallsRun out;
  while (sim->time() < duration) {
    const StepStatus st = sim->step(std::min(1e-2, duration - sim->time()));
    EXPECT_TRUE(st.ok) << st.message;
    if (!st.ok) break;
    for (const ContactEvent& e : sim->events()) {
      out.events.push_back(e);
      out.names.push_back(sim->constraints()[e.constraint]->name());
    }
  }
  out.q = sim->q();
  out.v = sim->v();
  return out;
}

}  // namespace

// Protects the islands' independence: three balls on one floor — one
// launched sliding along x at μ 0.2, one along y at μ 0.3, one thrown down
// onto the floor while sliding (a friction impact) at μ 0.1 — each reaches
// its closed form (rolling at 5/7 of its speed from t* = 2v₀/(7μg); the
// thrown one's tangential impulse μ pₙ) and ends where it ends alone.
TEST(ContactIslands, BallsOnOneFloorSlideStickAndLandAsIfAlone) {
  const double hdrop = 0.2, vz = -1.0;
  const std::vector<Ball> balls = {
      {"a", 0.2, Vec3(0, 0, kR), Vec3(2, 0, 0)},
      {"b", 0.3, Vec3(0, 1, kR), Vec3(0, 1, 0)},
      {"c", 0.1, Vec3(0, 2, kR + hdrop), Vec3(2, 0, vz)},
  };
  const double T = 1.2;
  const BallsRun all = simulate(balls, T);
  // Rolling at 5/7 of the launch speed, from t*.
  const double ta = 2 * 2.0 / (7 * 0.2 * kG), tb = 2 * 1.0 / (7 * 0.3 * kG);
  int sticks_a = 0, sticks_b = 0, lands_c = 0;
  const double vn = std::sqrt(vz * vz + 2 * kG * hdrop), t1 = (vz + vn) / kG;
  for (size_t i = 0; i < all.events.size(); ++i) {
    const ContactEvent& e = all.events[i];
    const std::string& name = all.names[i];
    if (name == "c_a" && e.kind == ContactEventKind::Stick) {
      ++sticks_a;
      EXPECT_NEAR(e.t, ta, 1e-10);
    }
    if (name == "c_b" && e.kind == ContactEventKind::Stick) {
      ++sticks_b;
      EXPECT_NEAR(e.t, tb, 1e-10);
    }
    if (name == "c_c" && e.kind == ContactEventKind::Touchdown) {
      ++lands_c;
      EXPECT_NEAR(e.t, t1, 1e-10);
      EXPECT_NEAR(e.tangential_impulse, 0.1 * kM * vn, 1e-10) << "μ pₙ: it slides through";
    }
  }
  EXPECT_EQ(sticks_a, 1);
  EXPECT_EQ(sticks_b, 1);
  EXPECT_EQ(lands_c, 1);
  // Body-frame linear velocities of each floating joint: (ω; v), 6 each,
  // and the balls do not rotate about z, so v's x, y are the world's.
  EXPECT_NEAR(all.v.segment<3>(3).norm(), 5.0 / 7 * 2.0, 1e-9);
  EXPECT_NEAR(all.v.segment<3>(9).norm(), 5.0 / 7 * 1.0, 1e-9);
  // Each ball alone: the same state. Not bit for bit — together the three
  // share one step-size control and each one's events end everyone's steps
  // (measured differences ≤ 1.1e-11) — but a force leaking between islands
  // would show at the size of the forces.
  for (int i = 0; i < 3; ++i) {
    const BallsRun alone = simulate({balls[i]}, T);
    EXPECT_LT((alone.q - all.q.segment<7>(7 * i)).lpNorm<Eigen::Infinity>(), 1e-10) << balls[i].name;
    EXPECT_LT((alone.v - all.v.segment<6>(6 * i)).lpNorm<Eigen::Infinity>(), 1e-10) << balls[i].name;
  }
}
