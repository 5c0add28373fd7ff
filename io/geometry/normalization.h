// Placing a shape in the unit ball, as the paper's data is prepared: subtract
// the mean of the points, divide by the largest distance to it, so the farthest
// point lies at norm 1. `from_unit` maps fitted points back to the input frame.
// A collection may also turn a shape into the pose of its first shape
// (io/geometry/rigid_align.h): `rotation` (identity by default) is applied after
// the centring and scaling; normals turn with it.
#pragma once
#include <string>

#include "engine/block.h"

namespace jsa {

struct Normalization {
  Eigen::RowVector3d center = Eigen::RowVector3d::Zero();  // mean of the points
  double scale = 1;                                        // max distance from center; > 0
  Eigen::Matrix3d rotation =
      Eigen::Matrix3d::Identity();  // rows turn as x -> x * rotation; det = +1

  Block<double> to_unit(const Block<double>& points) const;    // (p - center) / scale * rotation
  Block<double> from_unit(const Block<double>& points) const;  // p * rotation^T * scale + center
  Block<double> normals_to_unit(const Block<double>& normals) const;    // n * rotation
  Block<double> normals_from_unit(const Block<double>& normals) const;  // n * rotation^T
};

// The normalization of N x 3 `points`. Throws InputError, naming `source` (the
// file the points came from, if any), when N == 0 or all points coincide.
Normalization normalization_of(const Block<double>& points, const std::string& source = "");

}  // namespace jsa
