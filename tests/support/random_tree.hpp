// Random kinematic trees for tests and benchmarks: every joint type, random
// placements and inertias (physically valid), fixed or floating base.
#pragma once

#include <appell/appell.hpp>

#include <random>

namespace appell::test {

Inertia randomInertia(std::mt19937& rng);

SE3 randomPlacement(std::mt19937& rng);

Vec3 randomUnit(std::mt19937& rng);

/// A random tree of n bodies; body i's parent is uniform in [−1 or 0, i−1].
/// Joint types cycle through all moving types (plus a few fixed joints).
Model randomTree(int n, bool floating_base, std::mt19937& rng);

VecX randomVector(int n, std::mt19937& rng, double scale = 1.0);

}  // namespace appell::test
