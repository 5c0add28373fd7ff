// Evaluating a fitted atlas against its shape (paper Sec. 4): M' fresh points
// x ~ P mapped through phi against M' fresh samples of the shape, in the
// shape's unit frame; and the sampling floor, the same metrics between two
// independent samples of the shape, which is the best a perfect fit can score.
// Both under the Chamfer association and under the exact EMD assignment.
#pragma once
#include <vector>

#include "io/geometry/mesh.h"
#include "io/geometry/normalization.h"
#include "losses/metrics/emd.h"
#include "losses/metrics/metrics.h"
#include "model/atlas.h"

namespace jsa {

struct EvaluationOptions {
  Index samples = 2000;  // M' (paper: 2000)
  uint64_t seed = 0;     // seeds both the P draws and the surface samples
  // Independent draws of the M' points on every side (draw d seeded seed + d),
  // every metric the mean over them. One draw is a noisy measurement where the
  // shape is thin: on one fitted ant the EMD against its floor ranged over
  // 0.99-1.92 between six draws of 2000 points (docs/results.md, "The EMD's
  // own noise"); the mean of both sides over the draws is the ratio to read.
  int draws = 1;
};

struct Evaluation {
  SurfaceMetrics fit;    // atlas vs shape (Chamfer association)
  SurfaceMetrics floor;  // shape vs an independent sample of itself
  EmdMetrics fit_emd;    // the same pairs of sets under the exact EMD assignment (Eq. 13)
  EmdMetrics floor_emd;
  // Per draw, atlas over floor: how far one draw's ratio strays from the mean's.
  std::vector<double> chamfer_ratio, emd_ratio;
};

// `index`: which shape of a collection (0 for a single shape).
Evaluation evaluate_reconstruction(Atlas<float>& atlas, const Mesh& shape,
                                   const Normalization& normalization, const EvaluationOptions& o,
                                   int index = 0);

// The same metrics for any model's M' predicted points and unit normals (unit
// frame of `shape`): the shape is sampled as above, so two models evaluated
// with the same options meet the same ground-truth samples (the baselines of
// model/baselines/atlasnet.h are scored this way).
Evaluation evaluate_points(const Block<double>& points, const Block<double>& normals,
                           const Mesh& shape, const Normalization& normalization,
                           const EvaluationOptions& o);

}  // namespace jsa
