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

// The pose step of a collection: the first shape turned into its canonical
// frame (reference_frame), then every other shape rotated onto it
// (align_to_reference; rigid_align on the pools in the unit frames;
// docs/collections.md). Returns one alignment per shape (the first: its frame
// alone). Shapes given in other poses get the same canonical unit frames.
std::vector<RigidAlignment> align_to_first(std::vector<RunInput>& inputs,
                                           const RigidAlignOptions& options = {});
// Near ties (RigidAlignment::near_poses, a near-symmetric shape: an ant end to
// end) settled by the whole collection rather than the reference alone: each
// such shape takes the near pose whose mean symmetric Chamfer distance to all
// the other shapes, in their poses, is lowest (near_collection), in rounds
// until no pose changes (at most 3). Pairs of near-symmetric shapes disagree
// with each other (docs/collections.md), so the majority of the family decides.
// A shape whose own input pose was kept (RigidAlignOptions::keep_input) stays.
// align_to_first calls it for three shapes or more.
void settle_near_ties(std::vector<RunInput>& inputs, std::vector<RigidAlignment>& poses,
                      Index samples = 3000);

// The reference's pool (and normalisation) turned into canonical_rotation of
// its points (io/geometry/rigid_align.h); returns that rotation.
Eigen::Matrix3d reference_frame(RunInput& reference);
// `input` turned onto `reference` (already in its frame): rigid_align with the
// input's own pose taken relative to the reference's file; the rotations
// returned (and near_poses) are absolute, input file -> unit frame.
RigidAlignment align_to_reference(RunInput& input, const RunInput& reference,
                                  const RigidAlignOptions& options = {});

// The template of a collection's template start (FitOptions::template_shape,
// `--template-shape -1`): the medoid, the shape whose symmetric Chamfer
// distance (mean squared, both ways, on the first `samples` rows of the pools,
// in their aligned unit frames) to all the others sums least. Starting every
// shape from the most typical one asks the least deformation of the others:
// a template whose arms are folded must grow arms for every other bear
// (docs/collections.md, sixth round). Ties go to the lowest index.
struct MedoidChoice {
  int shape = 0;
  std::vector<double> sums;  // per shape: its Chamfer distances to the others, summed
};
MedoidChoice medoid_shape(const std::vector<Block<double>>& pools, Index samples = 3000);

}  // namespace jsa
