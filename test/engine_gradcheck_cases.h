// Gradient-check cases shared by the engine tests: each case names an op, builds
// a graph from its inputs and carries the inputs it is checked at. The per-op
// tests check them one by one; "gradient check table" runs them all and prints
// one line per op with its worst relative error (analytic vs central differences).
#pragma once
#include <string>
#include <vector>

#include "engine/gradcheck.h"
#include "engine/rng.h"

namespace jsa::test {

struct GradCase {
  std::string op;                     // the table row's name
  GraphBuilder f;                     // inputs -> any block
  std::vector<Block<double>> inputs;  // where the gradient is checked
  GradCheckOptions options = {};      // tolerances (defaults: rtol 1e-5, atol 1e-8)
};

// Defined in engine_ops_test.cpp: one case per op (and broadcast shape).
std::vector<GradCase> op_cases();
// Defined in engine_tangents_test.cpp: losses on the stacked-tangent Jacobian of
// a small MLP, checked w.r.t. the weights and the input points.
std::vector<GradCase> jacobian_cases();

// Entries uniform in [lo, hi).
inline Block<double> uniform_block(Rng& rng, Index rows, Index cols, double lo, double hi) {
  Block<double> b(rows, cols);
  for (Index i = 0; i < b.size(); ++i) b.data()[i] = rng.uniform(lo, hi);
  return b;
}

// Entries with |x| in [lo, hi) and a random sign: bounded away from 0, so ReLU
// kinks and sqrt(0) are never within a finite-difference step.
inline Block<double> signed_block(Rng& rng, Index rows, Index cols, double lo = 0.2,
                                  double hi = 1.0) {
  Block<double> b = uniform_block(rng, rows, cols, lo, hi);
  for (Index i = 0; i < b.size(); ++i)
    if (rng.uniform() < 0.5) b.data()[i] = -b.data()[i];
  return b;
}

}  // namespace jsa::test
