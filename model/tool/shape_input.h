// What a fit starts from: the input shape (a file or builtin:NAME), a fixed pool
// of surface samples with unit normals, and the normalisation to the unit frame
// (centre at the mean, farthest sample at distance 1, as the paper's data).
#pragma once
#include <string>

#include "io/geometry/mesh.h"
#include "io/geometry/normalization.h"

namespace jsa {

struct RunInput {
  Mesh mesh;                    // in the input's own frame
  Normalization normalization;  // input frame -> unit frame
  Block<double> pool;           // P x 6 [x_S, n_S] in the unit frame, unit normals
};

// spec: a path, or "builtin:NAME". The pool is drawn with Rng(seed, stream 2).
RunInput load_run_input(const std::string& spec, Index pool_size, uint64_t seed);
Mesh load_shape(const std::string& spec);

}  // namespace jsa
