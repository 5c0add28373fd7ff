// The shape every reader returns and every writer takes: a triangle mesh, or an
// oriented point cloud when `faces` is empty. Geometry is double; the training
// code converts to its own scalar when it samples.
#pragma once
#include <string>
#include <vector>

#include "engine/block.h"

namespace jsa {

using Faces = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;

struct Mesh {
  Block<double> vertices;             // V x 3
  Faces faces;                        // F x 3 vertex indices; 0 x 3 for a point cloud
  Block<double> normals;              // V x 3 unit per-vertex normals, or 0 x 3 if none
  std::vector<std::string> warnings;  // accepted oddities (non-manifold, components, ...)

  bool is_point_cloud() const { return faces.rows() == 0; }
  bool has_normals() const { return normals.rows() > 0; }
};

}  // namespace jsa
