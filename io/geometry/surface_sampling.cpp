// Area-weighted triangle choice by binary search in the cumulative areas, then a
// uniform point in the triangle with the square-root trick: for u, v ~ U[0,1),
//   p = (1 - sqrt(u)) a + sqrt(u) (1 - v) b + sqrt(u) v c
// is uniform over triangle abc (sqrt(u) undoes the density growing with distance from a).
#include "io/geometry/surface_sampling.h"

#include <algorithm>
#include <vector>

#include "engine/check.h"

namespace jsa {
namespace {

SurfaceSamples resample_points(const Mesh& mesh, Index count, Rng& rng) {
  JSA_CHECK(mesh.has_normals(), "a point cloud without normals cannot be sampled");
  SurfaceSamples samples{Block<double>(count, 3), Block<double>(count, 3)};
  for (Index i = 0; i < count; ++i) {
    const Index pick = Index(rng.below(uint64_t(mesh.vertices.rows())));
    samples.points.row(i) = mesh.vertices.row(pick);
    samples.normals.row(i) = mesh.normals.row(pick);
  }
  return samples;
}

}  // namespace

SurfaceSamples sample_surface(const Mesh& mesh, Index count, Rng& rng) {
  JSA_CHECK(count >= 0, "sample count must be non-negative, got " << count);
  JSA_CHECK(mesh.vertices.rows() > 0, "cannot sample an empty mesh");
  if (mesh.is_point_cloud()) return resample_points(mesh, count, rng);

  const Block<double> unit_normals = face_normals(mesh.vertices, mesh.faces);
  // cumulative[f] = total area of faces 0..f (areas are |e1 x e2| / 2; the 1/2 cancels)
  std::vector<double> cumulative(mesh.faces.rows());
  double total = 0;
  for (Index f = 0; f < mesh.faces.rows(); ++f) {
    const Eigen::RowVector3d a = mesh.vertices.row(mesh.faces(f, 0));
    const Eigen::RowVector3d e1 = mesh.vertices.row(mesh.faces(f, 1)) - a;
    const Eigen::RowVector3d e2 = mesh.vertices.row(mesh.faces(f, 2)) - a;
    total += e1.cross(e2).norm();
    cumulative[f] = total;
  }
  JSA_CHECK(total > 0, "mesh has zero surface area (validate_mesh rejects such meshes)");

  SurfaceSamples samples{Block<double>(count, 3), Block<double>(count, 3)};
  for (Index i = 0; i < count; ++i) {
    const double target = rng.uniform() * total;
    const auto it = std::upper_bound(cumulative.begin(), cumulative.end(), target);
    const Index f = std::min<Index>(it - cumulative.begin(), mesh.faces.rows() - 1);
    const double root_u = std::sqrt(rng.uniform());
    const double v = rng.uniform();
    const double wa = 1 - root_u, wb = root_u * (1 - v), wc = root_u * v;
    const int a = mesh.faces(f, 0), b = mesh.faces(f, 1), c = mesh.faces(f, 2);
    samples.points.row(i) =
        wa * mesh.vertices.row(a) + wb * mesh.vertices.row(b) + wc * mesh.vertices.row(c);
    Eigen::RowVector3d normal = unit_normals.row(f);
    if (mesh.has_normals()) {
      const Eigen::RowVector3d blend =
          wa * mesh.normals.row(a) + wb * mesh.normals.row(b) + wc * mesh.normals.row(c);
      const double length = blend.norm();
      if (length > 1e-12) normal = blend / length;  // opposite corner normals can cancel
    }
    samples.normals.row(i) = normal;
  }
  return samples;
}

}  // namespace jsa
