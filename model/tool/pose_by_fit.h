// Choosing between near-tied poses by fitting them (beyond the paper; the pose
// step of a collection, docs/collections.md "Shapes in any pose").
//
// The rigid pose step (io/geometry/rigid_align.h) scores a pose by the
// Chamfer distance of the two shapes as they stand. A near-symmetric shape (an
// ant end to end: head and abdomen swap, the six legs land on six legs) scores
// two poses within a few percent, and on the SHREC ants the lower one is the
// wrong one as often as not. What the collection will do with a pose is a
// better judge: every shape starts as the template's atlas and is deformed onto
// its own surface, and a shape turned end to end must grow the template's head
// out of its abdomen. So each near-tied pose gets a short fit, the template's
// atlas (shape 0 alone, once) deformed onto the shape in that pose with the
// collection's own objective, and the pose whose fit ends at the lower loss wins.
#pragma once
#include <cstdint>
#include <vector>

#include "engine/block.h"
#include "model/tool/trainer.h"

namespace jsa {

struct PoseFitOptions {
  int64_t template_steps = 1000;  // steps of the reference alone, fitted once for all candidates
  int64_t steps = 300;            // joint steps of the reference and one candidate pose
  int64_t scored = 100;           // the mean loss of the last this many steps is the score
  bool by_surface = false;        // score by the fitted L_6D on fresh draws instead
  Index surface_samples = 4000;   // draws of P (and pool rows) for that score
};

struct PoseFitChoice {
  int chosen = 0;                // index into the candidates
  std::vector<double> losses;    // per candidate: mean loss of its last `scored` steps
  std::vector<double> surfaces;  // per candidate: L_6D of the fitted shape, fresh draws
  double seconds = 0;            // wall time of the fits
};

// Fits shape 0's atlas once (the reference, FitOptions::template_start), then, for
// each candidate rotation R_c, a two-shape collection {reference, pool * R_c}
// from it for PoseFitOptions::steps joint steps, with `run`'s objective, sizes
// and seed (M fixed at run.points; no checkpoints). Pools: P x 6 rows [x, n]
// in the unit frames, `pool` in its input pose (rotation identity). Returns
// the candidate with the lowest score. Deterministic for a seed and thread
// count. Throws InputError (from the trainer) on options it cannot run.
PoseFitChoice choose_pose_by_fit(const FitOptions& run, const Block<double>& reference,
                                 const Block<double>& pool,
                                 const std::vector<Eigen::Matrix3d>& candidates,
                                 const PoseFitOptions& options = {});

// As above for several shapes against one reference, sharing the reference's fit:
// candidates[i] lists shape i's rotations (fewer than two: nothing to choose,
// chosen 0 and no fit).
std::vector<PoseFitChoice> choose_poses_by_fit(
    const FitOptions& run, const Block<double>& reference, const std::vector<Block<double>>& pools,
    const std::vector<std::vector<Eigen::Matrix3d>>& candidates,
    const PoseFitOptions& options = {});

}  // namespace jsa
