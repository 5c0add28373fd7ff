// Shared by the model tests: targets on the unit sphere, the shape whose every
// answer is known (centre 0, radius 1, normal = position).
#pragma once
#include "engine/block.h"
#include "engine/rng.h"
#include "test/normal_draws.h"

namespace test_support {

// n x 6 rows [x, s x] of uniform points on the unit sphere: s = 1 outward
// normals, s = -1 inward.
inline jsa::Block<double> sphere_pool(jsa::Index n, uint64_t seed, double s = 1.0) {
  jsa::Rng rng(seed);
  jsa::Block<double> pool(n, 6);
  for (jsa::Index i = 0; i < n; ++i) {
    Eigen::RowVector3d p = test_support::normal_vector3(rng).transpose();
    p.normalize();
    // Per coordinate: GCC 12 warns (-Warray-bounds) on Eigen's AVX-512 copy of a 3-vector row.
    for (int k = 0; k < 3; ++k) {
      pool(i, k) = p(k);
      pool(i, 3 + k) = s * p(k);
    }
  }
  return pool;
}

}  // namespace test_support
