// Gaussian vectors and rotations for the tests' fixtures, drawn in a fixed
// order. A constructor call such as Eigen::Vector3d(rng.normal(), rng.normal(),
// rng.normal()) leaves the order of its three draws to the compiler (GCC
// evaluates the last argument first, clang the first), so one seed gave the
// two compilers different fixtures, and a test whose margin was measured on
// GCC's failed under clang's sanitizer build. These draw in GCC's order (the
// last coordinate first), so the figures the tests were written with stand.
#pragma once
#include <Eigen/Geometry>

#include "engine/rng.h"

namespace test_support {

// (x, y, z), each N(0, 1), drawn z first.
inline Eigen::Vector3d normal_vector3(jsa::Rng& rng) {
  const double z = rng.normal(), y = rng.normal(), x = rng.normal();
  return Eigen::Vector3d(x, y, z);
}

// A quaternion (w, x, y, z) with N(0, 1) entries, drawn z first: normalised, a
// uniformly random rotation.
inline Eigen::Quaterniond normal_quaternion(jsa::Rng& rng) {
  const double z = rng.normal(), y = rng.normal(), x = rng.normal(), w = rng.normal();
  return Eigen::Quaterniond(w, x, y, z);
}

}  // namespace test_support
