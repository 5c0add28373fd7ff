// What a fit starts from: the input shape (a file or builtin:NAME), a fixed pool
// of surface samples with unit normals, and the normalisation to the unit frame
// (centre at the mean, farthest sample at distance 1, as the paper's data).
#pragma once
#include <string>
#include <vector>

#include "io/geometry/mesh.h"
#include "io/geometry/normalization.h"
#include "io/geometry/rigid_align.h"

namespace jsa {

struct RunInput {
  Mesh mesh;                    // in the input's own frame
  Normalization normalization;  // input frame -> unit frame
  Block<double> pool;           // P x 6 [x_S, n_S] in the unit frame, unit normals
};

// spec: a path, or "builtin:NAME". The pool is drawn with Rng(seed, stream 2).
RunInput load_run_input(const std::string& spec, Index pool_size, uint64_t seed);
Mesh load_shape(const std::string& spec);

// Turns the shape into the pose `rotation` gives (its pool, and its
// normalization, so every output goes back to the input's own frame).
void set_rotation(RunInput& input, const Eigen::Matrix3d& rotation);

// The pose step of a collection: every shape after the first is rotated onto
// the first (rigid_align on the pools in the unit frames; docs/collections.md).
// Returns one alignment per shape (the first: the identity).
std::vector<RigidAlignment> align_to_first(std::vector<RunInput>& inputs,
                                           const RigidAlignOptions& options = {});

}  // namespace jsa
