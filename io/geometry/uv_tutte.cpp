#include "io/geometry/uv_tutte.h"

#include <Eigen/SparseCholesky>
#include <cmath>

#include "engine/check.h"
#include "io/geometry/uv_cut.h"

namespace jsa {

Block<double> tutte_embedding(const Block<double>& positions, const Faces& local) {
  const Index V = positions.rows();
  const auto loops = boundary_loops(local, V);
  if (loops.size() != 1)
    throw InputError("tutte: the chart is not a disk (" + std::to_string(loops.size()) +
                     " boundary loops)");
  const std::vector<int>& loop = loops[0];
  double area = 0;
  for (Index f = 0; f < local.rows(); ++f) {
    const Eigen::RowVector3d a = positions.row(local(f, 0)), b = positions.row(local(f, 1)),
                             c = positions.row(local(f, 2));
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  const double radius = std::sqrt(std::max(area, 1e-300) / M_PI);
  // Boundary on the circle at angles proportional to arc length, counter-
  // clockwise (the loop runs with the chart on its left).
  Block<double> uv = Block<double>::Zero(V, 2);
  std::vector<double> arc(loop.size() + 1, 0);
  for (size_t i = 0; i < loop.size(); ++i)
    arc[i + 1] =
        arc[i] + (positions.row(loop[(i + 1) % loop.size()]) - positions.row(loop[i])).norm();
  std::vector<int> slot(size_t(V), -1);  // -1 boundary, else index among inner vertices
  std::vector<char> on_boundary(size_t(V), 0);
  for (size_t i = 0; i < loop.size(); ++i) {
    const double angle = 2 * M_PI * (arc[i] / (arc.back() > 0 ? arc.back() : 1.0));
    uv.row(loop[i]) << radius * std::cos(angle), radius * std::sin(angle);
    on_boundary[size_t(loop[i])] = 1;
  }
  int inner = 0;
  for (Index v = 0; v < V; ++v)
    if (!on_boundary[size_t(v)]) slot[size_t(v)] = inner++;
  if (inner == 0) return uv;
  // Uniform weights: L x = b with L = degree on the diagonal, -1 per inner
  // neighbour, b = sum of the boundary neighbours' positions. Each undirected
  // edge once (an edge is shared by two faces inside the chart).
  std::vector<std::pair<int, int>> edges;
  for (Index f = 0; f < local.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = local(f, k), b = local(f, (k + 1) % 3);
      edges.push_back({std::min(a, b), std::max(a, b)});
    }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  std::vector<Eigen::Triplet<double>> trip;
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(inner, 2);
  std::vector<double> degree(size_t(inner), 0);
  for (const auto& [a, b] : edges) {
    const int sa = slot[size_t(a)], sb = slot[size_t(b)];
    if (sa >= 0) degree[size_t(sa)] += 1;
    if (sb >= 0) degree[size_t(sb)] += 1;
    if (sa >= 0 && sb >= 0) {
      trip.push_back({sa, sb, -1.0});
      trip.push_back({sb, sa, -1.0});
    } else if (sa >= 0) {
      rhs.row(sa) += uv.row(b);
    } else if (sb >= 0) {
      rhs.row(sb) += uv.row(a);
    }
  }
  for (int i = 0; i < inner; ++i) trip.push_back({i, i, degree[size_t(i)]});
  Eigen::SparseMatrix<double> L(inner, inner);
  L.setFromTriplets(trip.begin(), trip.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(L);
  if (solver.info() != Eigen::Success)
    throw InputError("tutte: an inner vertex is not connected to the boundary");
  const Eigen::MatrixXd x = solver.solve(rhs);
  for (Index v = 0; v < V; ++v)
    if (slot[size_t(v)] >= 0) uv.row(v) = x.row(slot[size_t(v)]);
  return uv;
}

}  // namespace jsa
