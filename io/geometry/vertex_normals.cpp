// Face and area-weighted vertex normals.
#include "io/geometry/vertex_normals.h"

namespace jsa {
namespace {

Eigen::RowVector3d face_cross(const Block<double>& vertices, const Faces& faces, Index f) {
  const Eigen::RowVector3d a = vertices.row(faces(f, 0));
  const Eigen::RowVector3d e1 = vertices.row(faces(f, 1)) - a;
  const Eigen::RowVector3d e2 = vertices.row(faces(f, 2)) - a;
  return e1.cross(e2);  // length = 2 * area
}

void normalize_rows(Block<double>& rows) {
  for (Index i = 0; i < rows.rows(); ++i) {
    const double length = rows.row(i).norm();
    if (length > 0) rows.row(i) /= length;
  }
}

}  // namespace

Block<double> face_normals(const Block<double>& vertices, const Faces& faces) {
  Block<double> normals(faces.rows(), 3);
  for (Index f = 0; f < faces.rows(); ++f) normals.row(f) = face_cross(vertices, faces, f);
  normalize_rows(normals);
  return normals;
}

Block<double> area_weighted_vertex_normals(const Block<double>& vertices, const Faces& faces) {
  Block<double> normals = Block<double>::Zero(vertices.rows(), 3);
  for (Index f = 0; f < faces.rows(); ++f) {
    const Eigen::RowVector3d weighted = face_cross(vertices, faces, f);
    for (int k = 0; k < 3; ++k) normals.row(faces(f, k)) += weighted;
  }
  normalize_rows(normals);
  return normals;
}

}  // namespace jsa
