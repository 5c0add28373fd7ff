// Repulsion, Eq. (11): exact oracle and the cut-off kernel on a uniform grid.
//
// The grid. Cells are squares of side h (r_c / 4) over the bounding box of mu,
// numbered row-major (cell = cy * nx + cx). The means are sorted by cell with a
// stable counting sort into structure-of-arrays copies (xs, ys). Each cell
// gathers, once, the means of the cells that can hold a point within r_c of it;
// each of its means then makes one branch-free, vectorised pass over that list
// (Eigen arrays: sqrt, exp, sums). Gathered pairs beyond r_c are kept: they are
// exact terms, so keeping them only helps.
#include "losses/repulsion.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "engine/parallel.h"

namespace jsa {

template <class T>
double repulsion_exact(const Block<T>& mu, T sigma, Block<T>* dmu) {
  JSA_CHECK(mu.cols() == 2,
            "repulsion: mu is " << mu.rows() << " x " << mu.cols() << ", not K x 2");
  JSA_CHECK(sigma > 0, "repulsion: sigma = " << sigma);
  const Index K = mu.rows();
  if (dmu) dmu->setZero(K, 2);
  if (K == 0) return 0;
  const double s = double(sigma), inv_k2 = 1.0 / (double(K) * double(K));
  double total = 0;
  for (Index i = 0; i < K; ++i) {
    double row = 0, gx = 0, gy = 0;
    for (Index j = 0; j < K; ++j) {
      const double dx = double(mu(i, 0)) - double(mu(j, 0));
      const double dy = double(mu(i, 1)) - double(mu(j, 1));
      const double d = std::sqrt(dx * dx + dy * dy), w = std::exp(-d / s);
      row += w;
      if (d > 0) {  // i = j and coincident means: no gradient (see the header)
        gx += w * dx / d;
        gy += w * dy / d;
      }
    }
    total += row;
    if (dmu) {
      (*dmu)(i, 0) = T(-2 / s * inv_k2 * gx);
      (*dmu)(i, 1) = T(-2 / s * inv_k2 * gy);
    }
  }
  return total * inv_k2;
}

namespace {

// The means sorted by grid cell; cell c holds sorted rows [start[c], start[c+1]).
struct Grid {
  double x0 = 0, y0 = 0, h = 1;  // lower-left corner and cell side
  Index nx = 1, ny = 1;
  std::vector<Index> cell_of;  // K: the cell of mu_i (original order)
  std::vector<Index> start;    // nx * ny + 1
  std::vector<Index> order;    // sorted position -> original row
  Index cell_x(double x) const {
    return std::clamp(Index(std::floor((x - x0) / h)), Index(0), nx - 1);
  }
  Index cell_y(double y) const {
    return std::clamp(Index(std::floor((y - y0) / h)), Index(0), ny - 1);
  }
};

// Cells of side h = r_c / 4, so a cell's candidate region hugs the disc of
// radius r_c (about 5.7 r_c^2 of area instead of 9 r_c^2 with h = r_c). A tiny
// r_c relative to the spread would give a huge grid of empty cells, so the cell
// count is capped near 4 K by doubling h (any h is correct, larger just scans more).
template <class T>
void build_grid(const Block<T>& mu, double r_c, Grid& g, std::vector<T>& xs, std::vector<T>& ys,
                std::vector<Index>& fill) {
  const Index K = mu.rows();
  g.x0 = double(mu.col(0).minCoeff());
  g.y0 = double(mu.col(1).minCoeff());
  const double wx = double(mu.col(0).maxCoeff()) - g.x0, wy = double(mu.col(1).maxCoeff()) - g.y0;
  g.h = r_c / 4;
  const double max_cells = 4.0 * double(K) + 16;
  while ((wx / g.h + 1) * (wy / g.h + 1) > max_cells) g.h *= 2;
  g.nx = Index(wx / g.h) + 1;
  g.ny = Index(wy / g.h) + 1;
  g.cell_of.resize(K);
  // nx ny <= max_cells by the loop above: kept at that size from the first
  // step, the grid does not allocate again when the means spread.
  g.start.reserve(size_t(max_cells) + 1);
  fill.reserve(size_t(max_cells));
  g.start.assign(g.nx * g.ny + 1, 0);
  for (Index i = 0; i < K; ++i) {
    g.cell_of[i] = g.cell_y(double(mu(i, 1))) * g.nx + g.cell_x(double(mu(i, 0)));
    ++g.start[g.cell_of[i] + 1];
  }
  for (Index c = 0; c < g.nx * g.ny; ++c) g.start[c + 1] += g.start[c];
  g.order.resize(K);
  xs.resize(K);
  ys.resize(K);
  fill.assign(g.start.begin(), g.start.end() - 1);
  for (Index i = 0; i < K; ++i) {  // stable: equal cells keep the original order
    const Index at = fill[g.cell_of[i]]++;
    g.order[at] = i;
    xs[at] = mu(i, 0);
    ys[at] = mu(i, 1);
  }
}

// Everything the cut-off sum needs besides its inputs. The tape op keeps one
// on its tape (Tape::workspace), so a step of the same K allocates nothing;
// the per-thread candidate lists only grow.
template <class T>
struct RepulsionScratch {
  using Array = Eigen::Array<T, Eigen::Dynamic, 1>;
  Grid grid;
  std::vector<T> xs, ys;  // coordinates in sorted order
  std::vector<Index> fill;
  std::vector<double> rows;
  struct Candidates {
    Array x, y, d, w;  // the candidates' coordinates, then d_ij and w_ij of one mean
  };
  std::vector<Candidates> per_thread;
};

template <class T>
double repulsion_cutoff_in(const Block<T>& mu, T sigma, Block<T>* dmu, const RepulsionOptions& o,
                           RepulsionScratch<T>& scratch);

}  // namespace

template <class T>
double repulsion_cutoff(const Block<T>& mu, T sigma, Block<T>* dmu, const RepulsionOptions& o) {
  RepulsionScratch<T> scratch;
  return repulsion_cutoff_in(mu, sigma, dmu, o, scratch);
}

namespace {

// Per mean i (one thread writes row i, sums in a fixed order):
//   row_i = sum_j w_ij,  w_ij = exp(-d_ij / sigma)
//   g_i   = sum_j w_ij / d_ij (mu_i - mu_j)    (terms with d_ij = 0 dropped)
//   L = 1/K^2 sum_i row_i,   dL/dmu_i = -2 / (sigma K^2) g_i
// Work goes cell by cell. A cell's candidates are the cells that some point of
// it could have within r_c: in grid row ry, at vertical gap gy = (|ry - cy| - 1)+ h,
// the columns with (|rx - cx| - 1)+ h <= sqrt(r_c^2 - gy^2). Per row those form
// one contiguous run of the sorted arrays (row-major numbering); the runs are
// copied once per cell into a scratch list, which each of the cell's means then
// scans in one vectorised pass. The d_ij = 0 terms need no branch: they have
// mu_i - mu_j = 0, so w / max(d, tiny) times it is 0 (tiny = the smallest
// normal T; only a d_ij below it would be mis-scaled).
template <class T>
double repulsion_cutoff_in(const Block<T>& mu, T sigma, Block<T>* dmu, const RepulsionOptions& o,
                           RepulsionScratch<T>& scratch) {
  JSA_CHECK(mu.cols() == 2,
            "repulsion: mu is " << mu.rows() << " x " << mu.cols() << ", not K x 2");
  JSA_CHECK(sigma > 0, "repulsion: sigma = " << sigma);
  JSA_CHECK(o.tolerance > 0 && o.tolerance < 1, "repulsion: tolerance = " << o.tolerance);
  JSA_CHECK(mu.allFinite(), "repulsion: a mean is not finite");
  const Index K = mu.rows();
  if (dmu) dmu->resize(K, 2);
  if (K == 0) return 0;
  // r_c, widened by a hair so rounding in the cell arithmetic never drops a pair
  // inside r_c.
  const double r_c = double(sigma) * std::log(1.0 / o.tolerance) * (1 + 1e-9);

  Grid& g = scratch.grid;
  std::vector<T>& xs = scratch.xs;  // coordinates in sorted order
  std::vector<T>& ys = scratch.ys;
  build_grid(mu, r_c, g, xs, ys, scratch.fill);

  using Array = Eigen::Array<T, Eigen::Dynamic, 1>;
  using ConstMap = Eigen::Map<const Array>;
  const T inv_sigma = T(1) / sigma, tiny = std::numeric_limits<T>::min();
  const double inv_k2 = 1.0 / (double(K) * double(K));
  const T grad_scale = T(-2.0 / double(sigma) * inv_k2);
  const Index reach = Index(r_c / g.h) + 1;  // rows and columns a cell can see
  std::vector<double>& rows = scratch.rows;
  rows.assign(size_t(K), 0.0);
  if (scratch.per_thread.size() < size_t(max_threads()))
    scratch.per_thread.resize(size_t(max_threads()));

  // One cell's means, with a thread's candidate lists (per-thread scratch,
  // grown when a cell needs more, never shrunk, kept from step to step: the
  // candidates' coordinates, then d_ij and w_ij of one mean; only the first n
  // entries of a cell's lists are read).
  using Candidates = typename RepulsionScratch<T>::Candidates;
  auto cell_pass = [&](Candidates& own, Index c) {
    Array &cand_x = own.x, &cand_y = own.y, &d = own.d, &w = own.w;
    if (g.start[c] == g.start[c + 1]) return;
    const Index cx = c % g.nx, cy = c / g.nx;
    Index n = 0;  // candidates gathered so far
    for (Index ry = std::max<Index>(0, cy - reach); ry <= std::min(g.ny - 1, cy + reach); ++ry) {
      const double gap = double(std::max<Index>(0, std::abs(ry - cy) - 1)) * g.h;
      if (gap > r_c) continue;
      // max(0, .): with gap = r_c, a fused multiply-add can leave -tiny here
      const Index span = Index(std::sqrt(std::max(0.0, r_c * r_c - gap * gap)) / g.h) + 1;
      const Index first = g.start[ry * g.nx + std::max<Index>(0, cx - span)];
      const Index last = g.start[ry * g.nx + std::min(g.nx - 1, cx + span) + 1];
      const Index m = last - first;
      if (n + m > cand_x.size()) {
        cand_x.conservativeResize(2 * (n + m));
        cand_y.conservativeResize(2 * (n + m));
      }
      cand_x.segment(n, m) = ConstMap(xs.data() + first, m);
      cand_y.segment(n, m) = ConstMap(ys.data() + first, m);
      n += m;
    }
    if (n > d.size()) {
      d.resize(cand_x.size());
      w.resize(cand_x.size());
    }
    auto d_n = d.head(n), w_n = w.head(n);
    for (Index s = g.start[c]; s < g.start[c + 1]; ++s) {
      const Index i = g.order[s];
      const auto dx = xs[s] - cand_x.head(n);  // mu_i - mu_j, as expressions
      const auto dy = ys[s] - cand_y.head(n);
      d_n = (dx.square() + dy.square()).sqrt();
      w_n = (d_n * -inv_sigma).exp();
      rows[i] = double(w_n.sum());
      if (dmu) {
        w_n /= d_n.max(tiny);  // now w_ij / d_ij
        (*dmu)(i, 0) = grad_scale * (w_n * dx).sum();
        (*dmu)(i, 1) = grad_scale * (w_n * dy).sum();
      }
    }
  };
  // Row i is written by one thread and its sums run in a fixed order, so the
  // split does not matter; inside another team (region_would_be_serial) the
  // cells run inline, without a region of one thread.
  const Index cells = g.nx * g.ny;
  if (K <= 1024 || region_would_be_serial()) {
    for (Index c = 0; c < cells; ++c) cell_pass(scratch.per_thread[0], c);
  } else {
#pragma omp parallel
    {
      Candidates& own = scratch.per_thread[size_t(omp_get_thread_num())];
#pragma omp for schedule(dynamic, 4)
      for (Index c = 0; c < cells; ++c) cell_pass(own, c);
    }
  }
  double total = 0;
  for (Index i = 0; i < K; ++i) total += rows[i];
  return total * inv_k2;
}

}  // namespace

// Forward stores dL/dmu in a helper node (storage reused across steps);
// pull-back: dmu += dL * (dL_rep/dmu).
template <class T>
Var repulsion(Tape<T>& t, Var mu, T sigma, const RepulsionOptions& o) {
  const bool want_grad = t.needs_grad(mu);
  Var dmu_store = t.node(t.rows(mu), 2, {});
  const double value =
      repulsion_cutoff_in(t.value(mu), sigma, want_grad ? &t.value(dmu_store) : nullptr, o,
                          t.template workspace<RepulsionScratch<T>>());
  Var out = t.node(1, 1, {mu});
  t.value(out)(0, 0) = T(value);
  t.on_backward(out, [mu, dmu_store](Tape<T>& t, Var out) {
    t.grad(mu) += t.grad(out)(0, 0) * t.value(dmu_store);
  });
  return out;
}

#define JSA_INSTANTIATE(T)                                                                     \
  template Var repulsion<T>(Tape<T>&, Var, T, const RepulsionOptions&);                        \
  template double repulsion_cutoff<T>(const Block<T>&, T, Block<T>*, const RepulsionOptions&); \
  template double repulsion_exact<T>(const Block<T>&, T, Block<T>*);
JSA_INSTANTIATE(float)
JSA_INSTANTIATE(double)

}  // namespace jsa
