// Placing a shape in the unit ball, as the paper's data is prepared: subtract
// the mean of the points, divide by the largest distance to it, so the farthest
// point lies at norm 1. `from_unit` maps fitted points back to the input frame.
#pragma once
#include <string>

#include "engine/block.h"

namespace jsa {

struct Normalization {
  Eigen::RowVector3d center = Eigen::RowVector3d::Zero();  // mean of the points
  double scale = 1;                                        // max distance from center; > 0

  Block<double> to_unit(const Block<double>& points) const;    // (p - center) / scale
  Block<double> from_unit(const Block<double>& points) const;  // p * scale + center
};

// The normalization of N x 3 `points`. Throws InputError, naming `source` (the
// file the points came from, if any), when N == 0 or all points coincide.
Normalization normalization_of(const Block<double>& points, const std::string& source = "");

}  // namespace jsa
