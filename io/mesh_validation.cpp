// Validation of a freshly read mesh or oriented point cloud.
#include "io/mesh_validation.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <utility>

#include "io/geometry/vertex_normals.h"
#include "io/input_file.h"

namespace jsa {
namespace {

void check_finite_rows(const std::string& path, const Block<double>& rows, const char* what) {
  for (Index i = 0; i < rows.rows(); ++i)
    if (!rows.row(i).allFinite())
      input_error(path, std::string(what) + " " + std::to_string(i),
                  "coordinate is NaN or infinite");
}

void check_face_indices(const std::string& path, const Mesh& mesh) {
  const Index count = mesh.vertices.rows();
  for (Index f = 0; f < mesh.faces.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int v = mesh.faces(f, k);
      if (v < 0 || v >= count)
        input_error(path, "face " + std::to_string(f),
                    "vertex index " + std::to_string(v) + " is out of range [0, " +
                        std::to_string(count) + ")");
    }
}

// Number of connected components of the faces (union-find over vertices).
Index count_components(const Mesh& mesh) {
  std::vector<int> parent(mesh.vertices.rows());
  std::iota(parent.begin(), parent.end(), 0);
  auto root = [&](int v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for (Index f = 0; f < mesh.faces.rows(); ++f)
    for (int k = 1; k < 3; ++k) parent[root(mesh.faces(f, k))] = root(mesh.faces(f, 0));
  // every face joins the tree of its first vertex: count the distinct roots
  std::vector<char> seen(parent.size(), 0);
  Index components = 0;
  for (Index f = 0; f < mesh.faces.rows(); ++f) {
    const int r = root(mesh.faces(f, 0));
    if (!seen[r]) seen[r] = 1, ++components;
  }
  return components;
}

Index count_non_manifold_edges(const Mesh& mesh) {
  std::map<std::pair<int, int>, int> faces_per_edge;
  for (Index f = 0; f < mesh.faces.rows(); ++f) {
    const auto face = mesh.faces.row(f);
    if (face(0) == face(1) || face(1) == face(2) || face(2) == face(0)) continue;  // a sliver
    for (int k = 0; k < 3; ++k) {
      const int a = face(k), b = face((k + 1) % 3);
      ++faces_per_edge[{std::min(a, b), std::max(a, b)}];
    }
  }
  Index count = 0;
  for (const auto& entry : faces_per_edge) count += entry.second > 2;
  return count;
}

void add_topology_warnings(Mesh& mesh, const Block<double>& unit_face_normals) {
  Index degenerate = 0;
  for (Index f = 0; f < unit_face_normals.rows(); ++f)
    degenerate += unit_face_normals.row(f).squaredNorm() == 0;
  if (degenerate > 0)
    mesh.warnings.push_back(std::to_string(degenerate) +
                            " degenerate (zero-area) faces kept; they are never sampled");
  const Index non_manifold = count_non_manifold_edges(mesh);
  if (non_manifold > 0)
    mesh.warnings.push_back(std::to_string(non_manifold) +
                            " non-manifold edges (shared by more than two faces)");
  const Index components = count_components(mesh);
  if (components > 1)
    mesh.warnings.push_back("mesh has " + std::to_string(components) + " connected components");
}

void normalize_normals(const std::string& path, Mesh& mesh) {
  check_finite_rows(path, mesh.normals, "normal of vertex");
  Block<double> recomputed;
  Index zero = 0;
  for (Index i = 0; i < mesh.normals.rows(); ++i) {
    const double length = mesh.normals.row(i).norm();
    if (length > 0) {
      mesh.normals.row(i) /= length;
      continue;
    }
    if (mesh.is_point_cloud())
      input_error(path, "normal of point " + std::to_string(i),
                  "has zero length and there are no faces to recompute it from");
    if (recomputed.rows() == 0)
      recomputed = area_weighted_vertex_normals(mesh.vertices, mesh.faces);
    mesh.normals.row(i) = recomputed.row(i);
    if (mesh.normals.row(i).squaredNorm() == 0) mesh.normals.row(i) << 0, 0, 1;
    ++zero;
  }
  if (zero > 0)
    mesh.warnings.push_back(std::to_string(zero) +
                            " zero-length normals recomputed from the faces");
}

}  // namespace

void validate_mesh(const std::string& path, Mesh& mesh) {
  if (mesh.vertices.rows() == 0) input_error(path, "", "no vertices");
  check_finite_rows(path, mesh.vertices, "vertex");
  check_face_indices(path, mesh);
  if (mesh.faces.rows() == 0 && !mesh.has_normals())
    input_error(path, "",
                "no faces and no normals: a point cloud needs oriented points "
                "(x y z nx ny nz per point)");
  if (mesh.has_normals() && mesh.normals.rows() != mesh.vertices.rows())
    input_error(path, "",
                std::to_string(mesh.normals.rows()) + " normals for " +
                    std::to_string(mesh.vertices.rows()) + " vertices; expected one per vertex");
  if (mesh.faces.rows() > 0) {
    const Block<double> unit = face_normals(mesh.vertices, mesh.faces);
    if (unit.rowwise().squaredNorm().maxCoeff() == 0)
      input_error(path, "",
                  "all " + std::to_string(mesh.faces.rows()) +
                      " faces are degenerate (zero area); nothing to sample");
    add_topology_warnings(mesh, unit);
  }
  if (mesh.has_normals()) normalize_normals(path, mesh);
}

}  // namespace jsa
