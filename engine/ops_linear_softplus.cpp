// One MLP layer as one op: Y = softplus_stacked(H W + b) on stacked rows
// [value; tangents], the GEMM's output handled in row tiles while they are in
// cache (issue 21). The same function as linear followed by softplus_stacked
// (engine/ops_linear.cpp, derived in docs/engine.md); what changes is the
// order of the work over memory, and that the pre-activation is not stored.
//
// A tile is a run of points p0..p1, i.e. rows p0..p1 of every stacked block
// (each run contiguous). Forward, per tile: Z = H W into Y's rows (one GEMM
// per block), then bias, softplus and the tangents' factor in place while the
// tile is hot, where the two ops made two passes over the whole 3M x C block
// in memory and kept Z as well. Pull-back, per tile: dZ from dY and Y (in
// place in dY, which nothing reads after this op), then dH = dZ W^T and
// dW += H^T dZ while dZ is hot, where the two ops wrote dZ out and read it
// back twice.
//
// What the pull-back needs of the forward is Y alone. With s = softplus,
// s' = sigmoid(beta z), y_0 = s(z), y_k = s'(z) z_k:
//   s'(z) = 1 - e^(-beta s(z))          (e^(beta s) = 1 + e^(beta z)), so
//   s'    = -expm1(-beta y_0)           accurate to a rounding even where tiny;
//   z_k s''(z) = z_k beta s' (1 - s') = beta (1 - s') y_k,
// so neither z nor z_k is kept: the pull-back of the stacked softplus is
//   dz   = dy_0 s' + beta (1 - s') sum_k dy_k y_k,
//   dz_k = dy_k s'.
// One expm1 per value entry (an exp and a log in Eigen) is what replaces the
// stored pre-activation block; keeping s' (the value rows' third of it)
// instead has not been measured (docs/performance.md, "A fused linear +
// softplus").
//
// Threads: tiles are cut from the shapes alone and each tile's Z depends on
// its rows alone, so Y's bits do not depend on the thread count. dW and db are
// sums over tiles: each thread adds its own contiguous run of tiles, in order,
// into its own partial, and the partials are added in thread order, so the same
// thread count gives the same bits.
#include <omp.h>

#include <algorithm>

#include "engine/gemm.h"
#include "engine/ops.h"
#include "engine/parallel.h"

namespace jsa {

namespace {

constexpr int kMaxWidth = 4096;  // as softplus_stacked: the command line's width bound
template <class T>
using RowArray = Eigen::Array<T, 1, Eigen::Dynamic, Eigen::RowMajor, 1, kMaxWidth>;
template <class T>
using ConstRowMap = Eigen::Map<const Eigen::Array<T, 1, Eigen::Dynamic, Eigen::RowMajor>>;

// A tile's output rows over all blocks in about this many bytes: with the
// tile's input rows, within a core's L2 (512 kB and more on current x86).
constexpr Index kTileBytes = 192 * 1024;

Index tile_points(Index m, Index blocks, Index cols, Index bytes_per_entry, Index asked) {
  if (asked > 0) return std::min(asked, m);
  const Index p = kTileBytes / (blocks * cols * bytes_per_entry);
  return std::clamp<Index>(p / 8 * 8, 8, std::max<Index>(m, 8));
}

// Runs f(thread, first, p0, p1) over tiles of `tile` points covering [0, m):
// thread p of the team takes the contiguous run tiles * p / team .. tiles * (p
// + 1) / team, in order (first: its first tile). Returns the team size.
// When the region would have one thread (one tile, one thread, or inside
// another team: the trainer's shape workers) the tiles run inline as that
// thread's, with no region (libgomp would allocate one: region_would_be_serial).
template <class F>
int for_tiles(Index m, Index tile, int max_team, F&& f) {
  const Index tiles = (m + tile - 1) / tile;
  if (tiles <= 1 || max_team <= 1 || region_would_be_serial()) {
    for (Index k = 0; k < tiles; ++k) f(0, k == 0, k * tile, std::min(m, (k + 1) * tile));
    return 1;
  }
  int team = 1;
#pragma omp parallel num_threads(max_team)
  {
    const int p = omp_get_thread_num(), size = omp_get_num_threads();
    if (p == 0) team = size;
    const Index k0 = tiles * p / size, k1 = tiles * (p + 1) / size;
    for (Index k = k0; k < k1; ++k) f(p, k == k0, k * tile, std::min(m, (k + 1) * tile));
  }
  return team;
}

// Whether thread p of a team of `team` had any of `tiles` tiles.
bool had_tiles(Index tiles, int team, int p) { return tiles * (p + 1) / team > tiles * p / team; }

}  // namespace

template <class T>
Var linear_softplus_stacked(Tape<T>& t, Var h, Var w, Var b, Index m, T beta, Index tile) {
  const Index n = t.rows(h), cin = t.cols(h), c = t.cols(w);
  JSA_CHECK(t.rows(w) == cin, "linear_softplus_stacked: H is " << n << "x" << cin << ", W is "
                                                               << t.rows(w) << "x" << c);
  JSA_CHECK(m > 0 && n % m == 0,
            "linear_softplus_stacked: " << n << " rows is not a multiple of " << m);
  JSA_CHECK(beta > T(0), "linear_softplus_stacked: beta must be positive, got " << beta);
  JSA_CHECK(c <= kMaxWidth, "linear_softplus_stacked: " << c << " columns, at most " << kMaxWidth);
  JSA_CHECK(!b.valid() || (t.rows(b) == 1 && t.cols(b) == c),
            "linear_softplus_stacked: bias must be 1x" << c);
  const Index blocks = n / m;
  tile = tile_points(m, blocks, std::max(cin, c), Index(sizeof(T)), tile);
  const Index tiles = (m + tile - 1) / tile;
  const int slots = max_threads();
  Var y = b.valid() ? t.node(n, c, {h, w, b}) : t.node(n, c, {h, w});
  // Scratch for the pull-back's per-thread partial sums of dW (cin rows each)
  // and db (one row each): a node of its own, so the tape keeps its storage
  // from step to step like any value.
  Var partial = t.node(t.needs_grad(y) ? slots * (cin + 1) : 0, c, {});
  const Block<T>& H = t.value(h);
  const Block<T>& W = t.value(w);
  Block<T>& Y = t.value(y);
  const T* bias = b.valid() ? t.value(b).data() : nullptr;

  // z = h W + b ;  y_0 = s(z) = log(1 + e^(beta z)) / beta ;  y_k = s'(z) z_k,
  // with log(1 + e^bz) = max(bz, 0) + log1p(e^-|bz|), sigmoid from e = e^-|bz|.
  for_tiles(m, tile, slots, [&](int, bool, Index p0, Index p1) {
    GemmCall z{false, false, false, p1 - p0, c, cin};
    for (Index k = 0; k < blocks; ++k)
      gemm(z, H.row(k * m + p0).data(), W.data(), Y.row(k * m + p0).data());
    RowArray<T> bz(c), e(c), s1(c);
    for (Index i = p0; i < p1; ++i) {
      auto y0 = Y.row(i).array();
      if (bias)
        bz = beta * (y0 + ConstRowMap<T>(bias, c));
      else
        bz = beta * y0;
      e = (-bz.abs()).exp();
      y0 = (bz.max(T(0)) + e.log1p()) / beta;
      if (blocks == 1) continue;
      // A plain loop, as in ops_linear.cpp: Eigen's select runs one coefficient at a time.
      for (Index j = 0; j < c; ++j) s1[j] = (bz[j] >= T(0) ? T(1) : e[j]) / (T(1) + e[j]);
      for (Index k = 1; k < blocks; ++k) Y.row(k * m + i).array() *= s1;
    }
  });

  // s' = -expm1(-beta y_0) ;  dz = dy_0 s' + beta (1 - s') sum_k dy_k y_k ;  dz_k = dy_k s'
  // then dH (+)= dZ W^T ;  dW += H^T dZ ;  db += sum over the value rows of dZ.
  t.on_backward(y, [h, w, b, partial, m, blocks, beta, tile, tiles, slots](Tape<T>& t, Var y) {
    const Index cin = t.cols(h), c = t.cols(y);
    const Block<T>& H = t.value(h);
    const Block<T>& W = t.value(w);
    const Block<T>& Y = t.value(y);
    Block<T>& dZ = t.grad(y);  // dY, overwritten tile by tile with dZ (read by no one else)
    Block<T>& part = t.value(partial);
    bool first_h = false;
    Block<T>* dH = t.needs_grad(h) ? &t.grad_to_overwrite(h, &first_h) : nullptr;
    const bool want_w = t.needs_grad(w), want_b = b.valid() && t.needs_grad(b);
    const int team = for_tiles(m, tile, slots, [&](int p, bool first, Index p0, Index p1) {
      RowArray<T> s1(c), g(c);
      for (Index i = p0; i < p1; ++i) {
        s1 = -(-beta * Y.row(i).array()).expm1();
        auto dz0 = dZ.row(i).array();
        if (blocks == 1) {
          dz0 *= s1;
          continue;
        }
        g = dZ.row(m + i).array() * Y.row(m + i).array();
        for (Index k = 2; k < blocks; ++k)
          g += dZ.row(k * m + i).array() * Y.row(k * m + i).array();
        dz0 = dz0 * s1 + beta * (T(1) - s1) * g;
        for (Index k = 1; k < blocks; ++k) dZ.row(k * m + i).array() *= s1;
      }
      const Index len = p1 - p0;
      if (dH) {
        const GemmCall dh{false, true, !first_h, len, cin, c};
        for (Index k = 0; k < blocks; ++k)
          gemm(dh, dZ.row(k * m + p0).data(), W.data(), dH->row(k * m + p0).data());
      }
      if (want_w)
        for (Index k = 0; k < blocks; ++k) {
          const GemmCall dw{true, false, !(first && k == 0), cin, c, len};
          gemm(dw, H.row(k * m + p0).data(), dZ.row(k * m + p0).data(), part.row(p * cin).data());
        }
      if (want_b) {
        auto db = part.row(slots * cin + p);
        if (first) db.setZero();
        for (Index i = p0; i < p1; ++i) db += dZ.row(i);
      }
    });
    if (want_w) {
      bool first_w = false;
      Block<T>& dW = t.grad_to_overwrite(w, &first_w);
      for (int p = 0; p < team; ++p) {
        if (!had_tiles(tiles, team, p)) continue;
        const auto sum = part.middleRows(p * cin, cin);
        if (first_w)
          dW = sum;
        else
          dW += sum;
        first_w = false;
      }
    }
    if (want_b) {
      auto db = t.grad(b).row(0);
      for (int p = 0; p < team; ++p)
        if (had_tiles(tiles, team, p)) db += part.row(slots * cin + p);
    }
  });
  return y;
}

#define JSA_INSTANTIATE(T) \
  template Var linear_softplus_stacked<T>(Tape<T>&, Var, Var, Var, Index, T, Index);
JSA_INSTANTIATE(float)
JSA_INSTANTIATE(double)

}  // namespace jsa
