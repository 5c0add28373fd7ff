// L_even and the mixture's log-density it stands on (evenness.h).
//
// The cut-off. With w_nk = exp(-|x_n - mu_k|^2 / (2 sigma^2)) and S_n = sum_k
// w_nk, terms with w_nk < tolerance lie beyond r_c = sigma sqrt(2 ln(1/tolerance))
// and are dropped: less than K tolerance in all (S_n is the sum of the kept
// terms, value and gradient alike). When the kept sum is
// under 1000 K tolerance (a point far out in a tail, where that could exceed
// 0.1% of S_n) the point takes the exact sum instead, so every log S_n is
// within 1e-3 of the exact one (and in practice within K tolerance / S_n).
// The means are binned in square cells of side r_c, so a point's candidates
// are the 3 x 3 cells around its own (clamped to the grid: a point outside the
// means' bounding box still sees every mean within r_c of it).
#include "losses/evenness.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "engine/ops.h"
#include "engine/parallel.h"

namespace jsa {

namespace {

// The means sorted by cell; cell c holds sorted rows [start[c], start[c + 1]).
struct MeanGrid {
  double x0 = 0, y0 = 0, h = 1;
  Index nx = 1, ny = 1;
  std::vector<Index> start, order;  // order: sorted position -> mean
  std::vector<Index> cell, fill;    // building scratch: each mean's cell, the cells' fill
  Index cell_x(double x) const {
    return std::clamp(Index(std::floor((x - x0) / h)), Index(0), nx - 1);
  }
  Index cell_y(double y) const {
    return std::clamp(Index(std::floor((y - y0) / h)), Index(0), ny - 1);
  }
};

// Cells of side r_c, their count capped near 4 K by doubling the side (a
// larger side is as correct: a point just scans more means).
template <class T>
void build_grid(const Block<T>& mu, double r_c, MeanGrid& g) {
  const Index K = mu.rows();
  g.x0 = double(mu.col(0).minCoeff());
  g.y0 = double(mu.col(1).minCoeff());
  const double wx = double(mu.col(0).maxCoeff()) - g.x0, wy = double(mu.col(1).maxCoeff()) - g.y0;
  g.h = r_c;
  while ((wx / g.h + 1) * (wy / g.h + 1) > 4.0 * double(K) + 16) g.h *= 2;
  g.nx = Index(wx / g.h) + 1;
  g.ny = Index(wy / g.h) + 1;
  std::vector<Index>& cell = g.cell;
  cell.assign(size_t(K), 0);
  g.start.assign(size_t(g.nx * g.ny + 1), 0);
  for (Index k = 0; k < K; ++k) {
    cell[size_t(k)] = g.cell_y(double(mu(k, 1))) * g.nx + g.cell_x(double(mu(k, 0)));
    ++g.start[size_t(cell[size_t(k)] + 1)];
  }
  for (Index c = 0; c < g.nx * g.ny; ++c) g.start[size_t(c + 1)] += g.start[size_t(c)];
  g.order.resize(size_t(K));
  std::vector<Index>& fill = g.fill;
  fill.assign(g.start.begin(), g.start.end() - 1);
  for (Index k = 0; k < K; ++k) g.order[size_t(fill[size_t(cell[size_t(k)])]++)] = k;
}

// The kept terms of every point: point n's are entries [begin[n], begin[n + 1])
// of `mean` and `r`, with r = w_nk / S_n (the mean's share of the point's
// density, the weight both pull-backs need).
struct Shares {
  std::vector<int> mean;
  std::vector<double> r;
  std::vector<Index> begin;
};

// Appends the point (x, y)'s kept terms to (mean, r) and returns log S: the
// means of the 3 x 3 cells around the point within r_c (w >= tolerance), or,
// when their sum is under min_sum (the dropped terms could matter), every
// mean, their weights shifted by the nearest one's exponent so that a far
// point's S does not underflow (log-sum-exp).
template <class T>
double gather_shares(const Block<T>& mu, const MeanGrid& g, double inv_2s2, double r2,
                     double min_sum, double x, double y, std::vector<int>& mean,
                     std::vector<double>& r) {
  const size_t first_entry = mean.size();
  const Index cx = g.cell_x(x), cy = g.cell_y(y);
  double sum = 0;
  for (Index ry = std::max<Index>(0, cy - 1); ry <= std::min(g.ny - 1, cy + 1); ++ry) {
    const Index first = g.start[size_t(ry * g.nx + std::max<Index>(0, cx - 1))];
    const Index last = g.start[size_t(ry * g.nx + std::min(g.nx - 1, cx + 1) + 1)];
    for (Index s = first; s < last; ++s) {
      const Index k = g.order[size_t(s)];
      const double dx = x - double(mu(k, 0)), dy = y - double(mu(k, 1));
      const double d2 = dx * dx + dy * dy;
      if (d2 > r2) continue;  // w < tolerance: dropped
      const double w = std::exp(-d2 * inv_2s2);
      sum += w;
      mean.push_back(int(k));
      r.push_back(w);
    }
  }
  double log_sum = std::log(sum);
  if (!(sum >= min_sum)) {
    mean.resize(first_entry);
    r.resize(first_entry);
    double nearest = 0;
    for (Index k = 0; k < mu.rows(); ++k) {
      const double dx = x - double(mu(k, 0)), dy = y - double(mu(k, 1));
      const double e = (dx * dx + dy * dy) * inv_2s2;
      if (k == 0 || e < nearest) nearest = e;
    }
    sum = 0;
    for (Index k = 0; k < mu.rows(); ++k) {
      const double dx = x - double(mu(k, 0)), dy = y - double(mu(k, 1));
      const double w = std::exp(nearest - (dx * dx + dy * dy) * inv_2s2);
      sum += w;
      mean.push_back(int(k));
      r.push_back(w);
    }
    log_sum = std::log(sum) - nearest;
  }
  for (size_t e = first_entry; e < r.size(); ++e) r[e] /= sum;
  return log_sum;
}

// What the op keeps between its forward and its pull-back, on its tape
// (Tape::workspace): every vector keeps its capacity from one step to the
// next, so a step of the same sizes allocates nothing.
template <class T>
struct MixtureScratch {
  MeanGrid grid;
  std::vector<Shares> parts;  // per thread of the forward
  Shares shares;              // the parts joined in order
  Block<double> dmu;          // the pull-back's sums for the means
};

}  // namespace

template <class T>
Block<double> mixture_log_density_exact(const Block<T>& x, const Block<T>& mu, T sigma) {
  JSA_CHECK(x.cols() == 2 && mu.cols() == 2 && mu.rows() >= 1,
            "mixture density: x must be N x 2 and mu K x 2 with K >= 1");
  const double inv_2s2 = 1.0 / (2.0 * double(sigma) * double(sigma));
  Block<double> out(x.rows(), 1);
  for (Index n = 0; n < x.rows(); ++n) {
    std::vector<double> e(size_t(mu.rows()));
    for (Index k = 0; k < mu.rows(); ++k) {
      const double dx = double(x(n, 0)) - double(mu(k, 0)), dy = double(x(n, 1)) - double(mu(k, 1));
      e[size_t(k)] = -(dx * dx + dy * dy) * inv_2s2;
    }
    const double top = *std::max_element(e.begin(), e.end());
    double sum = 0;
    for (double v : e) sum += std::exp(v - top);
    out(n, 0) = top + std::log(sum);
  }
  return out;
}

// Forward: l_n = log S_n, and every kept share r_nk. Pull-back, with g_n = dL/dl_n:
//   dx_n  += -g_n / sigma^2 sum_k r_nk (x_n - mu_k)
//   dmu_k +=  1 / sigma^2 sum_n g_n r_nk (x_n - mu_k)
// The forward's exponentials are its cost; the pull-back reuses the shares.
// The points are split into one contiguous range per thread, each range's
// shares kept apart and joined in order, so the shares do not depend on the
// thread count; dx's rows are independent, and dmu's sums run over the points
// in order on one thread.
template <class T>
Var mixture_log_density(Tape<T>& t, Var x, Var mu, T sigma, const MixtureDensityOptions& o) {
  // The node first: appending it may move the tape's storage, and with it any
  // reference to an input's value taken before.
  const Index N = t.rows(x);
  Var out = t.node(N, 1, {x, mu});
  const Block<T>& xv = t.value(x);
  const Block<T>& mv = t.value(mu);
  JSA_CHECK(xv.cols() == 2 && mv.cols() == 2 && mv.rows() >= 1,
            "mixture density: x is " << xv.rows() << " x " << xv.cols() << " and mu " << mv.rows()
                                     << " x " << mv.cols() << "; need N x 2 and K x 2 with K >= 1");
  JSA_CHECK(sigma > 0, "mixture density: sigma = " << sigma);
  JSA_CHECK(o.tolerance > 0 && o.tolerance < 1e-3, "mixture density: tolerance = " << o.tolerance);
  JSA_CHECK(xv.allFinite() && mv.allFinite(), "mixture density: a point or a mean is not finite");
  const double s = double(sigma), inv_2s2 = 1.0 / (2 * s * s);
  const double r2 = 2 * s * s * std::log(1 / o.tolerance);  // r_c^2: w = tolerance there
  const double min_sum = 1000.0 * double(mv.rows()) * o.tolerance;
  MixtureScratch<T>& scratch = t.template workspace<MixtureScratch<T>>();
  MeanGrid& grid = scratch.grid;
  build_grid(mv, std::sqrt(r2) * (1 + 1e-9), grid);
  Block<T>& l = t.value(out);
  std::vector<Shares>& parts = scratch.parts;
  parts.resize(size_t(N > 512 ? max_threads() : 1));
  for (Shares& part : parts) {
    part.mean.clear();
    part.r.clear();
    part.begin.clear();
  }
  auto gather = [&](int id, int teams) {
    const Index begin = N * id / teams, end = N * (id + 1) / teams;
    Shares& part = parts[size_t(id)];
    for (Index n = begin; n < end; ++n) {
      part.begin.push_back(Index(part.mean.size()));
      l(n, 0) = T(gather_shares(mv, grid, inv_2s2, r2, min_sum, double(xv(n, 0)), double(xv(n, 1)),
                                part.mean, part.r));
    }
  };
  // (inside another team a region would have one thread: inline, no region;
  // engine/parallel.h, region_would_be_serial)
  if (parts.size() == 1 || region_would_be_serial()) {
    gather(0, 1);
  } else {
#pragma omp parallel num_threads(int(parts.size()))
    gather(omp_get_thread_num(), omp_get_num_threads());
  }
  Shares* shares = &scratch.shares;  // lives on the tape until its next clear()
  shares->mean.clear();
  shares->r.clear();
  shares->begin.clear();
  for (const Shares& part : parts) {
    const Index offset = Index(shares->mean.size());
    for (Index b : part.begin) shares->begin.push_back(offset + b);
    shares->mean.insert(shares->mean.end(), part.mean.begin(), part.mean.end());
    shares->r.insert(shares->r.end(), part.r.begin(), part.r.end());
  }
  shares->begin.push_back(Index(shares->mean.size()));
  Block<double>* dmu_sums = &scratch.dmu;
  t.on_backward(out, [x, mu, shares, dmu_sums, s](Tape<T>& t, Var out) {
    const Block<T>& xv = t.value(x);
    const Block<T>& mv = t.value(mu);
    const Block<T>& g = t.grad(out);
    const Index N = xv.rows();
    const double inv_s2 = 1 / (s * s);
    const Shares& sh = *shares;
    if (t.needs_grad(x)) {
      Block<T>& dx = t.grad(x);
      auto pull = [&](Index n) {
        const double px = double(xv(n, 0)), py = double(xv(n, 1));
        double ax = 0, ay = 0;
        for (Index e = sh.begin[size_t(n)]; e < sh.begin[size_t(n + 1)]; ++e) {
          const Index k = sh.mean[size_t(e)];
          ax += sh.r[size_t(e)] * (px - double(mv(k, 0)));
          ay += sh.r[size_t(e)] * (py - double(mv(k, 1)));
        }
        const double c = -double(g(n, 0)) * inv_s2;
        dx(n, 0) += T(c * ax);
        dx(n, 1) += T(c * ay);
      };
      if (N <= 512 || region_would_be_serial()) {
        for (Index n = 0; n < N; ++n) pull(n);
      } else {
#pragma omp parallel for schedule(static)
        for (Index n = 0; n < N; ++n) pull(n);
      }
    }
    if (t.needs_grad(mu)) {
      Block<double>& dmu = *dmu_sums;
      dmu.setZero(mv.rows(), 2);
      for (Index n = 0; n < N; ++n) {
        const double px = double(xv(n, 0)), py = double(xv(n, 1));
        const double c = double(g(n, 0)) * inv_s2;
        for (Index e = sh.begin[size_t(n)]; e < sh.begin[size_t(n + 1)]; ++e) {
          const Index k = sh.mean[size_t(e)];
          dmu(k, 0) += c * sh.r[size_t(e)] * (px - double(mv(k, 0)));
          dmu(k, 1) += c * sh.r[size_t(e)] * (py - double(mv(k, 1)));
        }
      }
      t.grad(mu) += dmu.cast<T>();
    }
  });
  return out;
}

// L_even = mean_m (l_m - mean l)^2, l_m = log p(x_m) - 1/2 log |J_u x J_v|^2.
// The area element's square gets a floor of 1e-12 (a degenerate Jacobian, where
// phi folds, would otherwise give log 0).
template <class T>
Var evenness_loss(Tape<T>& t, Var x, Var mu, T sigma, Var du, Var dv,
                  const MixtureDensityOptions& o) {
  const Var normal = cross3(t, du, dv);  // J_u x J_v, unnormalised
  const Var area2 = offset(t, row_dot(t, normal, normal), T(1e-12));
  const Var l = sub(t, mixture_log_density(t, x, mu, sigma, o), scale(t, log(t, area2), T(0.5)));
  return mean(t, square(t, sub(t, l, mean(t, l))));
}

#define JSA_INSTANTIATE(T)                                                                  \
  template Var mixture_log_density<T>(Tape<T>&, Var, Var, T, const MixtureDensityOptions&); \
  template Block<double> mixture_log_density_exact<T>(const Block<T>&, const Block<T>&, T); \
  template Var evenness_loss<T>(Tape<T>&, Var, Var, T, Var, Var, const MixtureDensityOptions&);
JSA_INSTANTIATE(float)
JSA_INSTANTIATE(double)

}  // namespace jsa
