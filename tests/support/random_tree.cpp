// The functions declared in random_tree.hpp, compiled once (see there for what they build).
#include "random_tree.hpp"
#include "random_draws.hpp"

namespace appell::test {

namespace {

Mat3 randomRotation(std::normal_distribution<double>& g, std::mt19937& rng) {
  const double c3 = g(rng);
  const double c2 = g(rng);
  const double c1 = g(rng);
  const double c0 = g(rng);
  return Quat(Eigen::Vector4d(c0, c1, c2, c3).normalized()).toRotationMatrix();
}

}  // namespace

Inertia randomInertia(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.2, 2.0), c(-0.3, 0.3);
  // Principal moments from a random box (always satisfies the triangle inequality).
  const double m = u(rng), a = u(rng), b = u(rng), d = u(rng);
  Vec3 moments(m * (b * b + d * d) / 12, m * (a * a + d * d) / 12, m * (a * a + b * b) / 12);
  // From rng, not Quat::UnitRandom() (std::rand): a test's draws must not
  // depend on which tests ran before it in the same process.
  std::normal_distribution<double> g;
  const Mat3 R = randomRotation(g, rng);
  return {m, drawVec3(c, rng), R * moments.asDiagonal() * R.transpose()};
}

SE3 randomPlacement(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  std::normal_distribution<double> g;
  SE3 X;
  X.R = randomRotation(g, rng);
  X.p = drawVec3(u, rng);
  return X;
}

Vec3 randomUnit(std::mt19937& rng) {
  std::normal_distribution<double> g;
  return drawVec3(g, rng).normalized();
}

Model randomTree(int n, bool floating_base, std::mt19937& rng) {
  static constexpr JointType kinds[] = {
      JointType::Revolute, JointType::Prismatic, JointType::Ball, JointType::Continuous,
      JointType::Planar,   JointType::Floating,  JointType::Fixed};
  ModelBuilder b;
  for (int i = 0; i < n; ++i) {
    int parent = -1;
    JointType type = floating_base ? JointType::Floating : JointType::Revolute;
    if (i > 0) {
      parent = std::uniform_int_distribution<int>(floating_base ? 0 : -1, i - 1)(rng);
      type = kinds[std::uniform_int_distribution<int>(0, 6)(rng)];
    }
    // Last argument first: the order g++ evaluated the former one-line call in.
    const Inertia inertia = randomInertia(rng);
    const Vec3 axis = randomUnit(rng);
    const SE3 placement = randomPlacement(rng);
    b.addBody("body" + std::to_string(i), parent, placement, type, axis, inertia);
  }
  return b.build();
}

VecX randomVector(int n, std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  VecX x(n);
  for (int i = 0; i < n; ++i) x[i] = u(rng);
  return x;
}

}  // namespace appell::test
