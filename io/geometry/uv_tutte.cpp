#include "io/geometry/uv_tutte.h"

#include <Eigen/SparseLU>
#include <cmath>
#include <utility>

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
  // Mean value weights (Floater 2003): w_ij = (tan(a/2) + tan(b/2)) / |x_i - x_j|,
  // a and b the angles at i of the two triangles on the edge ij. Positive, so
  // the embedding stays bijective, and close to the harmonic map, which does
  // not depend on the resolution: uniform weights squeeze the inside of a fine
  // chart geometrically with its graph distance from the boundary.
  // Row i of L x = b: sum_j w_ij (x_i - x_j) = 0, boundary neighbours moved to b.
  std::vector<Eigen::Triplet<double>> trip;
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(inner, 2);
  std::vector<double> diagonal(size_t(inner), 0);
  for (Index f = 0; f < local.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int i = local(f, k), j = local(f, (k + 1) % 3), l = local(f, (k + 2) % 3);
      const Eigen::Vector3d pi = positions.row(i).transpose(), pj = positions.row(j).transpose(),
                            pl = positions.row(l).transpose();
      const Eigen::Vector3d eij = pj - pi, eil = pl - pi;
      const double lij = eij.norm(), lil = eil.norm();
      if (!(lij > 0) || !(lil > 0)) continue;
      // The angle at i, tan(angle / 2) = |e x f| / (|e||f| + e.f), stable near 0 and pi.
      const double t = eij.cross(eil).norm() / (lij * lil + eij.dot(eil));
      if (!std::isfinite(t)) continue;
      // The angle at i lies between the edges ij and il: it adds to both weights.
      for (const auto& [other, length] : {std::pair<int, double>{j, lij}, {l, lil}}) {
        const int si = slot[size_t(i)];
        if (si < 0) continue;
        const double w = t / length;
        diagonal[size_t(si)] += w;
        const int so = slot[size_t(other)];
        if (so >= 0)
          trip.push_back({si, so, -w});
        else
          rhs.row(si) += w * uv.row(other);
      }
    }
  for (int i = 0; i < inner; ++i) trip.push_back({i, i, diagonal[size_t(i)]});
  Eigen::SparseMatrix<double> L(inner, inner);
  L.setFromTriplets(trip.begin(), trip.end());
  Eigen::SparseLU<Eigen::SparseMatrix<double>> solver;
  solver.analyzePattern(L);
  solver.factorize(L);
  if (solver.info() != Eigen::Success)
    throw InputError("tutte: an inner vertex is not connected to the boundary");
  const Eigen::MatrixXd x = solver.solve(rhs);
  for (Index v = 0; v < V; ++v)
    if (slot[size_t(v)] >= 0) uv.row(v) = x.row(slot[size_t(v)]);
  return uv;
}

}  // namespace jsa
