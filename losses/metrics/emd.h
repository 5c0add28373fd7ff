// Earth Mover's Distance of the paper's evaluation (Sec. 4, "Reconstruction
// metrics", Eq. 13): between two sets of M' oriented points (M' = 2000 in the
// paper), the one-to-one association sigma minimising sum_i |x_i - y_sigma(i)|^2,
// found exactly (LAPJV, losses/metrics/assignment.h). Reported over that association:
//  - spatial: mean |x_i - y_sigma(i)|, a distance, not squared, like the Chamfer
//    spatial metric of losses/metrics/metrics.h (so the two columns are comparable);
//  - spatial_squared: mean |x_i - y_sigma(i)|^2, what Eq. 13 writes;
//  - normal: mean |n_i - n_sigma(i)| of unit normals ("distances of the normals
//    using the associations given by ... the EMD using the spatial coordinates").
#pragma once
#include <vector>

#include "engine/block.h"

namespace jsa {

struct EmdMetrics {
  double spatial = 0;          // mean |x_i - y_sigma(i)|
  double spatial_squared = 0;  // mean |x_i - y_sigma(i)|^2 (Eq. 13)
  double normal = 0;           // mean |n_i - n_sigma(i)|
  double seconds = 0;          // wall time: cost matrix + assignment
};

// pred_points, true_points: M x C (C = 3 for xyz); normals: M x C too, unit
// length (not checked: a caller may pass any per-point attribute). The two sets
// must have the same count M >= 1, else InputError naming both counts.
// Coordinates must be finite (InputError). If `association` is given it
// receives sigma: (*association)[i] is the ground-truth row matched to pred row i.
EmdMetrics emd_metrics(const Block<double>& pred_points, const Block<double>& pred_normals,
                       const Block<double>& true_points, const Block<double>& true_normals,
                       std::vector<int>* association = nullptr);

// The cost matrix: out(i, j) = |a_i - b_j|^2 summed in column order (a: M x C,
// b: N x C). Rows are filled in parallel; each entry is computed alone, so the
// result does not depend on the thread count. Exact zeros for equal points
// (the difference is taken first, not |a|^2 + |b|^2 - 2 a.b).
Block<double> squared_distance_costs(const Block<double>& a, const Block<double>& b);

}  // namespace jsa
