// The similarity (rotation, uniform scale, translation; never a reflection)
// that best maps one 2D point set onto another in weighted least squares
// (Umeyama 1991, restricted to proper rotations). After a chart's UVs are made
// valid they are aligned back onto psi's, so the learned layout stays: the
// same domain region lands in the same UV region on every shape.
#pragma once
#include <limits>
#include <vector>

#include "engine/block.h"

namespace jsa {

struct Similarity2 {
  double scale = 1;
  Eigen::Matrix2d rotation = Eigen::Matrix2d::Identity();
  Eigen::RowVector2d translation = Eigen::RowVector2d::Zero();
  Block<double> apply(const Block<double>& p) const {
    return ((scale * p * rotation.transpose()).rowwise() + translation).eval();
  }
};

// argmin over similarities S of sum_i w_i |S(from_i) - to_i|^2 (from, to: N x 2;
// w: N weights >= 0, empty for all 1). Degenerate input gives the identity
// rotation and scale 1 with the centroids matched.
// The scale can be held to [min_scale, max_scale] (the rotation and the
// translation are then the best for that scale).
Similarity2 fit_similarity(const Block<double>& from, const Block<double>& to,
                           const std::vector<double>& w = {}, double min_scale = 0,
                           double max_scale = std::numeric_limits<double>::infinity());

}  // namespace jsa
