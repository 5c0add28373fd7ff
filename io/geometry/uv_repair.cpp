#include "io/geometry/uv_repair.h"

#include <Eigen/SparseCholesky>

#include "io/geometry/triangle_frame.h"
#include "io/geometry/uv_injectivity.h"
#include "io/geometry/uv_tutte.h"

namespace jsa {

const char* to_string(ChartStart s) {
  switch (s) {
    case ChartStart::psi:
      return "psi";
    case ChartStart::repaired:
      return "repaired";
    case ChartStart::tutte:
      return "tutte";
    default:
      return "failed";
  }
}

bool lscm_fill(const Block<double>& positions, const Faces& local, const std::vector<char>& free,
               Block<double>& uv) {
  const Index V = positions.rows();
  std::vector<int> slot(size_t(V), -1);
  int n = 0;
  for (Index v = 0; v < V; ++v)
    if (free[size_t(v)]) slot[size_t(v)] = n++;
  if (n == 0) return true;
  // Conformality on each triangle (frame x, y): u_x = v_y and u_y = -v_x, as two
  // residual rows weighted by sqrt(area); unknowns u at 2 slot, v at 2 slot + 1.
  std::vector<Eigen::Triplet<double>> trip;
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(2 * n);
  for (Index f = 0; f < local.rows(); ++f) {
    bool touches = false;
    for (int k = 0; k < 3; ++k) touches |= free[size_t(local(f, k))] != 0;
    if (!touches) continue;
    const TriangleFrame t = triangle_frame(positions.row(local(f, 0)).transpose(),
                                           positions.row(local(f, 1)).transpose(),
                                           positions.row(local(f, 2)).transpose());
    if (!(t.area > 0)) continue;
    for (int r = 0; r < 2; ++r) {
      int var[6];
      double coef[6], fixed_part = 0;
      for (int k = 0; k < 3; ++k) {
        const int v = local(f, k);
        const double cu = r == 0 ? t.grad(0, k) : t.grad(1, k);
        const double cv = r == 0 ? -t.grad(1, k) : t.grad(0, k);
        coef[2 * k] = cu, coef[2 * k + 1] = cv;
        if (slot[size_t(v)] >= 0) {
          var[2 * k] = 2 * slot[size_t(v)], var[2 * k + 1] = 2 * slot[size_t(v)] + 1;
        } else {
          var[2 * k] = var[2 * k + 1] = -1;
          fixed_part += cu * uv(v, 0) + cv * uv(v, 1);
        }
      }
      for (int i = 0; i < 6; ++i) {
        if (var[i] < 0) continue;
        rhs(var[i]) -= t.area * coef[i] * fixed_part;
        for (int j = 0; j < 6; ++j)
          if (var[j] >= 0) trip.push_back({var[i], var[j], t.area * coef[i] * coef[j]});
      }
    }
  }
  Eigen::SparseMatrix<double> H(2 * n, 2 * n);
  H.setFromTriplets(trip.begin(), trip.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(H);
  if (solver.info() != Eigen::Success) return false;
  const Eigen::VectorXd x = solver.solve(rhs);
  if (solver.info() != Eigen::Success || !x.allFinite()) return false;
  // A singular system can still factor with tiny pivots: check the residual.
  if ((H * x - rhs).norm() > 1e-6 * std::max(1.0, rhs.norm())) return false;
  for (Index v = 0; v < V; ++v)
    if (slot[size_t(v)] >= 0) uv.row(v) << x(2 * slot[size_t(v)]), x(2 * slot[size_t(v)] + 1);
  return true;
}

ChartStartResult start_chart_uv(const Block<double>& positions, const Faces& local,
                                const Block<double>& psi, const std::vector<char>& usable,
                                int max_rings, bool tutte) {
  ChartStartResult r;
  const Index V = positions.rows();
  bool all_usable = true;
  for (char u : usable) all_usable &= u != 0;
  if (all_usable && psi.allFinite() && chart_is_injective(local, psi)) {
    r.uv = psi;
    r.start = ChartStart::psi;
    return r;
  }
  // Free: the vertices of unusable faces; grown by a ring each round.
  std::vector<char> free(size_t(V), 0);
  for (Index f = 0; f < local.rows(); ++f)
    if (!usable[size_t(f)])
      for (int k = 0; k < 3; ++k) free[size_t(local(f, k))] = 1;
  for (int ring = 0; ring <= max_rings; ++ring) {
    Index fixed = 0;
    for (char c : free) fixed += c == 0;
    if (fixed < 2) break;
    if (ring > 0) {
      std::vector<char> grown = free;
      for (Index f = 0; f < local.rows(); ++f) {
        bool any = false;
        for (int k = 0; k < 3; ++k) any |= free[size_t(local(f, k))] != 0;
        if (any)
          for (int k = 0; k < 3; ++k) grown[size_t(local(f, k))] = 1;
      }
      free.swap(grown);
      Index still = 0;
      for (char c : free) still += c == 0;
      if (still < 2) break;
    }
    bool any_free = false;
    for (char c : free) any_free |= c != 0;
    if (!any_free) break;  // psi's UVs are usable everywhere but overlap: nothing local to repair
    Block<double> uv = psi;
    if (lscm_fill(positions, local, free, uv) && uv.allFinite() && chart_is_injective(local, uv)) {
      r.uv = std::move(uv);
      r.start = ChartStart::repaired;
      r.rings = ring;
      return r;
    }
  }
  if (!tutte) return r;  // failed, without Tutte's embedding
  Block<double> uv = tutte_embedding(positions, local);
  if (uv.allFinite() && chart_is_injective(local, uv)) {
    r.uv = std::move(uv);
    r.start = ChartStart::tutte;
    return r;
  }
  r.uv = std::move(uv);
  r.start = ChartStart::failed;
  return r;
}

}  // namespace jsa
