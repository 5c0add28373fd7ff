// Shared by the loss and metric tests: generic points, every coordinate
// uniform in [-1, 1), so that nearest neighbours and optimal matchings are
// unique (no ties) and the oracles have one answer to agree with.
#pragma once
#include "engine/block.h"
#include "engine/rng.h"

namespace test_support {

// rows x cols, filled in storage order from Rng(seed).
inline jsa::Block<double> uniform_block(jsa::Index rows, jsa::Index cols, uint64_t seed) {
  jsa::Rng rng(seed);
  jsa::Block<double> b(rows, cols);
  for (jsa::Index i = 0; i < b.size(); ++i) b.data()[i] = rng.uniform(-1, 1);
  return b;
}

}  // namespace test_support
