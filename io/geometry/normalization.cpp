// Mean-centre and scale to the unit ball.
#include "io/geometry/normalization.h"

#include <cmath>

#include "engine/check.h"

namespace jsa {

Block<double> Normalization::to_unit(const Block<double>& points) const {
  JSA_CHECK(points.cols() == 3, "points must be N x 3, got N x " << points.cols());
  return ((points.rowwise() - center) / scale) * rotation;
}

Block<double> Normalization::from_unit(const Block<double>& points) const {
  JSA_CHECK(points.cols() == 3, "points must be N x 3, got N x " << points.cols());
  return ((points * rotation.transpose()) * scale).rowwise() + center;
}

Block<double> Normalization::normals_to_unit(const Block<double>& normals) const {
  JSA_CHECK(normals.cols() == 3, "normals must be N x 3, got N x " << normals.cols());
  return normals * rotation;
}

Block<double> Normalization::normals_from_unit(const Block<double>& normals) const {
  JSA_CHECK(normals.cols() == 3, "normals must be N x 3, got N x " << normals.cols());
  return normals * rotation.transpose();
}

Normalization normalization_of(const Block<double>& points, const std::string& source) {
  JSA_CHECK(points.cols() == 3, "points must be N x 3, got N x " << points.cols());
  const std::string prefix = (source.empty() ? std::string("normalization") : source) + ": ";
  if (points.rows() == 0) throw InputError(prefix + "the shape has no points to normalise");
  Normalization n;
  n.center = points.colwise().mean();
  n.scale = std::sqrt((points.rowwise() - n.center).rowwise().squaredNorm().maxCoeff());
  if (!(n.scale > 0))
    throw InputError(prefix + "all " + std::to_string(points.rows()) +
                     " points coincide, so the shape has no extent to scale to the unit ball");
  return n;
}

}  // namespace jsa
