// A 3-vector of random draws with every compiler drawing in one order.
//
// Several draws in one argument list happen in an order C++ leaves to the
// compiler (g++ draws the last argument first, clang the first), so each
// draw here is its own statement: every compiler builds the same inputs.
// The order is the one g++ used before (the last component first), so the
// tests keep the inputs they were written against.
#pragma once

#include <appell/spatial.hpp>

#include <random>

namespace appell::test {

template <class Distribution>
Vec3 drawVec3(Distribution& d, std::mt19937& rng) {
  const double z = d(rng);
  const double y = d(rng);
  const double x = d(rng);
  return Vec3(x, y, z);
}

}  // namespace appell::test
