#include "io/geometry/uv_slim.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "engine/parallel.h"
#include "io/geometry/sparse_spd.h"

namespace jsa {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

Eigen::Vector2d at(const Block<double>& uv, int v) { return uv.row(v).transpose(); }

double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

// Smallest positive root of c + b t + a t^2 (c > 0), +inf if none.
double first_positive_root(double a, double b, double c) {
  const double scale = std::abs(a) + std::abs(b) + std::abs(c);
  if (std::abs(a) <= 1e-14 * scale) return b < 0 ? -c / b : kInf;
  const double disc = b * b - 4 * a * c;
  if (disc < 0) return kInf;
  // Stable roots: q = -(b + sign(b) sqrt(disc)) / 2, roots q / a and c / q.
  const double q = -0.5 * (b + (b >= 0 ? 1 : -1) * std::sqrt(disc));
  double best = kInf;
  for (double r : {q / a, q != 0 ? c / q : kInf})
    if (r > 0) best = std::min(best, r);
  return best;
}

}  // namespace

std::vector<TriangleFrame> triangle_frames(const Block<double>& positions, const Faces& local) {
  std::vector<TriangleFrame> frames(size_t(local.rows()));
  parallel_rows(local.rows(), [&](Index b, Index e) {
    for (Index f = b; f < e; ++f)
      frames[size_t(f)] = triangle_frame(positions.row(local(f, 0)).transpose(),
                                         positions.row(local(f, 1)).transpose(),
                                         positions.row(local(f, 2)).transpose());
  });
  return frames;
}

double symmetric_dirichlet(const std::vector<TriangleFrame>& frames, const Faces& local,
                           const Block<double>& uv) {
  std::vector<double> e(size_t(local.rows()));
  parallel_rows(local.rows(), [&](Index b, Index end) {
    for (Index f = b; f < end; ++f) {
      const TriangleFrame& t = frames[size_t(f)];
      if (!(t.area > 0)) {
        e[size_t(f)] = 0;
        continue;
      }
      const Eigen::Matrix2d J =
          uv_jacobian(t, at(uv, local(f, 0)), at(uv, local(f, 1)), at(uv, local(f, 2)));
      const double det = J.determinant();
      e[size_t(f)] = det > 0 ? t.area * (J.squaredNorm() + J.squaredNorm() / (det * det)) : kInf;
    }
  });
  // |J^-1|_F^2 = |J|_F^2 / det^2 for 2 x 2. Summed in face order: deterministic.
  double sum = 0, area = 0;
  for (size_t f = 0; f < e.size(); ++f) {
    sum += e[f];
    area += frames[f].area;
  }
  return area > 0 ? sum / area : 0;
}

double max_injective_step(const Faces& local, const Block<double>& uv, const Block<double>& d) {
  const Index F = local.rows();
  std::vector<double> t(static_cast<size_t>(F));
  parallel_rows(F, [&](Index b, Index e) {
    for (Index f = b; f < e; ++f) {
      const int i = local(f, 0), j = local(f, 1), k = local(f, 2);
      const Eigen::Vector2d e1 = at(uv, j) - at(uv, i), e2 = at(uv, k) - at(uv, i);
      const Eigen::Vector2d f1 = at(d, j) - at(d, i), f2 = at(d, k) - at(d, i);
      // 2 A(t) = (e1 + t f1) x (e2 + t f2) = c + b t + a t^2.
      t[size_t(f)] =
          first_positive_root(cross2(f1, f2), cross2(e1, f2) + cross2(f1, e2), cross2(e1, e2));
    }
  });
  double best = kInf;
  for (double x : t) best = std::min(best, x);  // min is exact: order does not matter
  return best;
}

SlimReport slim_symmetric_dirichlet(const Block<double>& positions, const Faces& local,
                                    Block<double>& uv, const SlimOptions& o,
                                    const std::function<bool(const Block<double>&)>& accept) {
  const auto start = std::chrono::steady_clock::now();
  const Index V = uv.rows(), F = local.rows();
  const std::vector<TriangleFrame> frames = triangle_frames(positions, local);
  SlimReport rep;
  rep.energy_start = rep.energy_end = symmetric_dirichlet(frames, local, uv);
  if (F == 0 || !std::isfinite(rep.energy_start)) return rep;

  // The sparsity pattern of the global system, once: unknown u_v at v, v_v at
  // V + v; each face couples its 6 unknowns. pos[36 f + 6 i + j] is where the
  // (i, j) entry of face f's 6 x 6 block lives in the compressed matrix.
  auto var = [&](Index f, int i) { return i < 3 ? Index(local(f, i)) : V + local(f, i - 3); };
  Eigen::SparseMatrix<double> H(2 * V, 2 * V);
  {
    std::vector<Eigen::Triplet<double>> trip;
    trip.reserve(size_t(36 * F + 2 * V));
    for (Index f = 0; f < F; ++f)
      for (int i = 0; i < 6; ++i)
        for (int j = 0; j < 6; ++j) trip.push_back({int(var(f, i)), int(var(f, j)), 0.0});
    for (Index v = 0; v < 2 * V; ++v) trip.push_back({int(v), int(v), 0.0});
    H.setFromTriplets(trip.begin(), trip.end());
    H.makeCompressed();
  }
  auto position = [&](Index row, Index col) {
    const int* inner = H.innerIndexPtr();
    const int* b = inner + H.outerIndexPtr()[col];
    const int* e = inner + H.outerIndexPtr()[col + 1];
    return int(std::lower_bound(b, e, int(row)) - inner);
  };
  std::vector<int> pos(size_t(36 * F)), diag(size_t(2 * V));
  parallel_rows(F, [&](Index b, Index e) {
    for (Index f = b; f < e; ++f)
      for (int i = 0; i < 6; ++i)
        for (int j = 0; j < 6; ++j)
          pos[size_t(36 * f + 6 * i + j)] = position(var(f, i), var(f, j));
  });
  for (Index v = 0; v < 2 * V; ++v) diag[size_t(v)] = position(v, v);
  SpdSolver solver(SpdSolver::Use::many);
  solver.analyze(H);

  // A tiny proximal term pins the translation (D does not see it).
  const double lambda = 1e-8;
  std::vector<Eigen::Matrix<double, 6, 6>> blocks(static_cast<size_t>(F));
  std::vector<Eigen::Matrix<double, 6, 1>> rhs_blocks(static_cast<size_t>(F));
  double energy = rep.energy_start;
  for (int it = 0; it < o.max_iterations; ++it) {
    // Local step: J = U S V^T; closest rotation R = U V^T; weights from
    // w_i^2 = (dD/dsigma_i) / (2 (sigma_i - 1)) = (sigma_i - sigma_i^-3) / (sigma_i - 1),
    // whose limit at sigma = 1 is 4.
    parallel_rows(F, [&](Index b, Index e) {
      for (Index f = b; f < e; ++f) {
        const TriangleFrame& t = frames[size_t(f)];
        blocks[size_t(f)].setZero();
        rhs_blocks[size_t(f)].setZero();
        if (!(t.area > 0)) continue;
        const Eigen::Matrix2d J =
            uv_jacobian(t, at(uv, local(f, 0)), at(uv, local(f, 1)), at(uv, local(f, 2)));
        Eigen::JacobiSVD<Eigen::Matrix2d> svd(J, Eigen::ComputeFullU | Eigen::ComputeFullV);
        Eigen::Matrix2d U = svd.matrixU(), Vm = svd.matrixV();
        Eigen::Vector2d s = svd.singularValues();
        if ((U * Vm.transpose()).determinant() <
            0) {  // never for an injective map; kept for safety
          U.col(1) *= -1;
          s(1) *= -1;
        }
        const Eigen::Matrix2d R = U * Vm.transpose();
        Eigen::Vector2d w;
        for (int i = 0; i < 2; ++i) {
          const double x = std::max(std::abs(s(i)), 1e-8);
          w(i) = std::abs(x - 1) < 1e-8 ? 2.0 : std::sqrt((x - std::pow(x, -3)) / (x - 1));
        }
        const Eigen::Matrix2d W = U * w.asDiagonal() * U.transpose();
        const Eigen::Matrix2d WR = W * R;
        // Residual rows of W (J - R): for column c (d/dx, d/dy) and row r,
        // sum_k (W_r0 G_ck u_k + W_r1 G_ck v_k) - (W R)_rc.
        for (int r = 0; r < 2; ++r)
          for (int c = 0; c < 2; ++c) {
            Eigen::Matrix<double, 6, 1> a;
            for (int k = 0; k < 3; ++k) {
              a(k) = W(r, 0) * t.grad(c, k);
              a(3 + k) = W(r, 1) * t.grad(c, k);
            }
            blocks[size_t(f)] += t.area * a * a.transpose();
            rhs_blocks[size_t(f)] += t.area * WR(r, c) * a;
          }
      }
    });
    // Global step: scatter the blocks (serially: faces share entries) and solve.
    double* values = H.valuePtr();
    std::fill(values, values + H.nonZeros(), 0.0);
    Eigen::VectorXd g = Eigen::VectorXd::Zero(2 * V);
    for (Index f = 0; f < F; ++f) {
      for (int i = 0; i < 6; ++i) {
        g(var(f, i)) += rhs_blocks[size_t(f)](i);
        for (int j = 0; j < 6; ++j)
          values[pos[size_t(36 * f + 6 * i + j)]] += blocks[size_t(f)](i, j);
      }
    }
    for (Index v = 0; v < 2 * V; ++v) {
      values[diag[size_t(v)]] += lambda;
      g(v) += lambda * (v < V ? uv(v, 0) : uv(v - V, 1));
    }
    if (!solver.factorize(H)) break;
    const Eigen::VectorXd x = solver.solve(g);
    if (!x.allFinite()) break;
    Block<double> d(V, 2);
    for (Index v = 0; v < V; ++v) d.row(v) << x(v) - uv(v, 0), x(V + v) - uv(v, 1);
    // Line search: a flip-free cap, then halving until D decreases and the
    // caller accepts the iterate. From Tutte's embedding the full step would
    // often swing the boundary across itself; a shorter one still gains.
    double step = std::min(1.0, o.step_fraction * max_injective_step(local, uv, d));
    Block<double> trial;
    double e_trial = kInf;
    bool found = false;
    for (int k = 0; k < 40 && step > 1e-12; ++k, step *= 0.5) {
      trial = uv + step * d;
      e_trial = symmetric_dirichlet(frames, local, trial);
      if (e_trial < energy && (!accept || accept(trial))) {
        found = true;
        break;
      }
    }
    if (!found) break;
    const double gain = (energy - e_trial) / energy;
    uv.swap(trial);
    energy = e_trial;
    rep.iterations = it + 1;
    if (gain < o.tolerance) break;
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >
        o.max_seconds) {
      rep.time_capped = true;
      break;
    }
  }
  rep.energy_end = energy;
  return rep;
}

}  // namespace jsa
