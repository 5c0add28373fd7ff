// nanoflann behind our interface. Three small pieces plug into its kd-tree:
//   RowsSource  : the point set, a row-major N x C block seen as N points;
//   SquaredL2   : the metric, |a - b|^2 summed in column order, as in the
//                 brute-force oracle;
//   ClosestOne  : a one-slot result set that breaks ties by the lowest index.
// The tree is built once per call (O(N log N), serial) and queried in parallel.
#include "io/geometry/nearest.h"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <nanoflann.hpp>

#include "engine/check.h"
#include "engine/parallel.h"

namespace jsa {
namespace {

template <class T>
struct RowsSource {
  const T* data;
  size_t rows, cols;
  size_t kdtree_get_point_count() const { return rows; }
  T kdtree_get_pt(uint32_t i, size_t d) const { return data[size_t(i) * cols + d]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;  // let the tree compute its own bounding box
  }
};

// |a - b|^2 over C columns. Dim > 0 fixes C at compile time so the loop unrolls.
template <class T, int Dim>
T squared_l2(const T* a, const T* b, size_t cols) {
  const size_t c = Dim > 0 ? size_t(Dim) : cols;
  T s = T(0);
  for (size_t d = 0; d < c; ++d) {
    const T diff = a[d] - b[d];
    s += diff * diff;
  }
  return s;
}

template <class T, int Dim>
struct SquaredL2 {
  using ElementType = T;
  using DistanceType = T;
  const RowsSource<T>& source;
  explicit SquaredL2(const RowsSource<T>& s) : source(s) {}
  T evalMetric(const T* a, uint32_t b, size_t cols) const {
    return squared_l2<T, Dim>(a, source.data + size_t(b) * source.cols, cols);
  }
  // One coordinate's share of the squared distance (used for pruning).
  template <class U, class V>
  T accum_dist(U a, V b, size_t) const {
    return T((a - b) * (a - b));
  }
};

// Keeps the single closest point; equal distances go to the lower index.
// The tree prunes a cell when its (rounded) lower bound exceeds worstDist(), so
// worstDist() reports the best distance inflated by a few ulps: a cell holding a
// point tied with, or within rounding of, the best is still visited, and
// addPoint() makes the exact comparison.
template <class T>
class ClosestOne {
 public:
  bool addPoint(T dist, uint32_t index) {
    if (dist < best_ || (dist == best_ && index < index_)) {
      best_ = dist;
      index_ = index;
      slack_ = best_ * (T(1) + 8 * std::numeric_limits<T>::epsilon()) +
               std::numeric_limits<T>::denorm_min();
    }
    return true;  // keep searching
  }
  T worstDist() const { return slack_; }
  bool full() const { return index_ != kNone; }
  T distance() const { return best_; }
  uint32_t index() const { return index_; }

 private:
  static constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();
  T best_ = std::numeric_limits<T>::max();
  T slack_ = std::numeric_limits<T>::infinity();
  uint32_t index_ = kNone;
};

template <class T, int Dim>
using KdTree = nanoflann::KDTreeSingleIndexAdaptor<SquaredL2<T, Dim>, RowsSource<T>, Dim, uint32_t>;

// Leaves of ~16 points: a leaf scan is a short, branch-light loop.
template <class T, int Dim>
std::unique_ptr<KdTree<T, Dim>> build_tree(const RowsSource<T>& source) {
  return std::make_unique<KdTree<T, Dim>>(source.cols, source,
                                          nanoflann::KDTreeSingleIndexAdaptorParams(16));
}

// Spreads the low 21 bits of v three apart (bit b goes to bit 3b), for a
// Morton code of three coordinates.
uint64_t spread_bits_by_3(uint64_t v) {
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffULL;
  v = (v | v << 16) & 0x1f0000ff0000ffULL;
  v = (v | v << 8) & 0x100f00f00f00f00fULL;
  v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
  v = (v | v << 2) & 0x1249249249249249ULL;
  return v;
}

// The queries in Morton (Z-curve) order of their first three coordinates.
// Consecutive queries then descend the same branches of the tree, whose nodes
// and points are still in cache: a dense L_6D pool (2 x 10^5 points of 6
// floats, and its tree) is larger than a core's L2, and a step's queries
// arrive in the random order of the domain's samples. Every query's answer is
// its own (ties go to the lowest index, whatever the order), so the order
// changes no result, only the time.
// order and code are the caller's (kept between calls by a NearestScratch).
template <class T>
void locality_order(const Block<T>& queries, std::vector<Index>& order,
                    std::vector<uint64_t>& code) {
  const Index m = queries.rows();
  order.resize(static_cast<size_t>(m));
  for (Index i = 0; i < m; ++i) order[size_t(i)] = i;
  const Index dims = std::min<Index>(3, queries.cols());
  if (m < 64 || dims < 2) return;  // too few to gain from it
  double lo[3] = {0, 0, 0}, scale[3] = {0, 0, 0};
  for (Index d = 0; d < dims; ++d) {
    lo[d] = double(queries.col(d).minCoeff());
    const double width = double(queries.col(d).maxCoeff()) - lo[d];
    scale[d] = width > 0 ? double((1 << 21) - 1) / width : 0;
  }
  code.resize(static_cast<size_t>(m));
  for (Index i = 0; i < m; ++i) {
    uint64_t c = 0;
    for (Index d = 0; d < dims; ++d) {
      double cell = (double(queries(i, d)) - lo[d]) * scale[d];
      // A NaN or infinite coordinate gets cell 0: its answer is still its own.
      cell = cell > 0 ? std::min(cell, double((1 << 21) - 1)) : 0;
      c |= spread_bits_by_3(uint64_t(cell)) << d;
    }
    code[size_t(i)] = c;
  }
  std::sort(order.begin(), order.end(), [&](Index a, Index b) {
    return code[size_t(a)] != code[size_t(b)] ? code[size_t(a)] < code[size_t(b)] : a < b;
  });
}

// A search's working storage (NearestScratch<T>::Impl holds one per column
// count): the visiting order, and a tree rebuilt in place over new points.
template <class T, int Dim>
struct TreeCache {
  std::vector<Index> order;
  std::vector<uint64_t> code;
  RowsSource<T> source{nullptr, 0, 0};  // the tree reads the points through this
  std::unique_ptr<KdTree<T, Dim>> tree;

  // The tree over `points`: buildIndex() on the kept tree reuses its index
  // array (the same build as a new tree's: the index array reset, the bounding
  // box computed, the nodes split the same way).
  const KdTree<T, Dim>& build(const Block<T>& points) {
    const size_t cols = size_t(points.cols());
    const bool same_cols = source.cols == cols;
    source = RowsSource<T>{points.data(), size_t(points.rows()), cols};
    if (tree && same_cols)
      tree->buildIndex();
    else
      tree = build_tree<T, Dim>(source);
    return *tree;
  }
};

template <class T, int Dim>
void query_tree(const KdTree<T, Dim>& tree, const Block<T>& queries, std::vector<int>& index,
                std::vector<T>* squared_distance, std::vector<Index>& order,
                std::vector<uint64_t>& code) {
  const nanoflann::SearchParams params;  // eps = 0: exact search
  const Index m = queries.rows();
  const T* q = queries.data();
  const size_t c = size_t(queries.cols());
  T* dist = squared_distance ? squared_distance->data() : nullptr;
  locality_order(queries, order, code);
  auto answer = [&](Index j) {
    const Index i = order[size_t(j)];
    ClosestOne<T> best;
    tree.findNeighbors(best, q + size_t(i) * c, params);
    index[i] = int(best.index());
    if (dist) dist[i] = best.distance();
  };
  // Tiny batches stay serial: a parallel region costs more than it saves; so do
  // searches inside another team (the trainer's shape workers), where a region
  // would have one thread and cost a heap block (engine/parallel.h,
  // region_would_be_serial). The cut-off was 1024 queries; the ramp's first
  // level (M = 625 against the 200k-point pool, phi still far from the surface,
  // where each query visits many cells) then searched on one core while the
  // other waited, and its steps took 8% longer (docs/performance.md, "The
  // first level's searches"). Chunks of a sixteenth keep both threads busy to
  // the end of a small batch.
  if (m <= 128 || region_would_be_serial()) {
    for (Index j = 0; j < m; ++j) answer(j);
    return;
  }
  const Index chunk = std::clamp<Index>(m / 16, 32, 256);
#pragma omp parallel for schedule(dynamic)
  for (Index first = 0; first < m; first += chunk)
    for (Index j = first; j < std::min(m, first + chunk); ++j) answer(j);
}

template <class T, int Dim>
void nearest_kdtree(const Block<T>& queries, const Block<T>& points, std::vector<int>& index,
                    std::vector<T>* squared_distance, TreeCache<T, Dim>* cache) {
  if (cache) {
    const KdTree<T, Dim>& tree = cache->build(points);
    query_tree<T, Dim>(tree, queries, index, squared_distance, cache->order, cache->code);
    return;
  }
  const RowsSource<T> source{points.data(), size_t(points.rows()), size_t(points.cols())};
  std::vector<Index> order;
  std::vector<uint64_t> code;
  query_tree<T, Dim>(*build_tree<T, Dim>(source), queries, index, squared_distance, order, code);
}

// Every distance at once, for sets small enough (M N up to kPairsByScan): the
// M x N squared distances, a row at a time, each row a loop over the points
// in columns (points transposed, so the loop runs over contiguous floats and
// vectorises), with the row's minimum and, for both_ways, every column's
// running minimum kept as it goes. At the default M = 2500 in 6 columns this
// is 6.25 M distances, cheaper than building a tree and searching it (the
// tree's cells in 6D hold few points and overlap many query balls;
// docs/performance.md, "Small searches by a scan"). Each distance is summed in
// column order, the way squared_l2 sums it, and ties go to the lowest index,
// so the answers are the tree's to the bit. Rows are split over the threads in
// contiguous ranges; each thread keeps its own column minima, merged in thread
// order (strict <: the lowest row wins ties), so the result does not depend on
// the thread count.
constexpr double kPairsByScan = double(1 << 24);

template <class T>
struct ScanScratch {
  std::vector<T> transposed, column_best;
  std::vector<int> column_index;
};

// One vector of lanes (GCC's and Clang's vector extension: 64 bytes, compiled
// to whatever the target has, two AVX2 registers or one AVX-512), and the
// same count of indices as integers of T's width, so a comparison's mask
// selects both.
template <class T>
struct ScanLanes;
template <>
struct ScanLanes<float> {
  typedef float Value __attribute__((vector_size(64)));
  typedef int32_t Index __attribute__((vector_size(64)));
  typedef int32_t Int;
};
template <>
struct ScanLanes<double> {
  typedef double Value __attribute__((vector_size(64)));
  typedef int64_t Index __attribute__((vector_size(64)));
  typedef int64_t Int;
};

// Rows [begin, end) of x against all of y (transposed into `cols` rows of
// `padded` values, the padding at +infinity: never a minimum). R rows at a
// time: each vector of y's lanes is loaded once for R rows, as a GEMM kernel
// reuses a panel. Per row, each lane keeps its first minimum (strict <, j
// ascending); per column, the block's R rows are merged in ascending order
// first, then against the running minimum (strict <: earlier rows win ties).
template <class T, int Dim, int R>
void scan_rows(const T* x, Index cols_runtime, const T* yt, Index padded, Index begin, Index end,
               std::vector<int>* x_to_y, std::vector<T>* x_distance, T* column_best,
               int* column_index) {
  using V = typename ScanLanes<T>::Value;
  using I = typename ScanLanes<T>::Index;
  using Int = typename ScanLanes<T>::Int;
  constexpr int L = int(sizeof(V) / sizeof(T));
  const Index cols = Dim > 0 ? Index(Dim) : cols_runtime;
  I iota;
  for (int l = 0; l < L; ++l) iota[l] = Int(l);
  for (Index i0 = begin; i0 + R <= end; i0 += R) {
    V row_best[R];
    I row_at[R];
    for (int r = 0; r < R; ++r) {
      row_best[r] = V{} + std::numeric_limits<T>::infinity();
      row_at[r] = I{} + Int(std::numeric_limits<int>::max());
    }
    for (Index j = 0; j < padded; j += L) {
      V d[R];
      for (int r = 0; r < R; ++r) d[r] = V{};
      for (Index c = 0; c < cols; ++c) {
        V yc;
        __builtin_memcpy(&yc, yt + size_t(c * padded + j), sizeof(V));
        for (int r = 0; r < R; ++r) {
          const V diff = x[size_t((i0 + r) * cols + c)] - yc;
          d[r] += diff * diff;
        }
      }
      const I at = iota + Int(j);
      for (int r = 0; r < R; ++r) {
        const I closer = d[r] < row_best[r];
        row_best[r] = closer ? d[r] : row_best[r];
        row_at[r] = closer ? at : row_at[r];
      }
      if (column_best) {
        V best = d[0];
        I who = I{} + Int(i0);
        for (int r = 1; r < R; ++r) {
          const I closer = d[r] < best;
          best = closer ? d[r] : best;
          who = closer ? I{} + Int(i0 + r) : who;
        }
        V kept;
        __builtin_memcpy(&kept, column_best + j, sizeof(V));
        I kept_who;
        for (int l = 0; l < L; ++l) kept_who[l] = Int(column_index[j + l]);
        const I closer = best < kept;
        kept = closer ? best : kept;
        kept_who = closer ? who : kept_who;
        __builtin_memcpy(column_best + j, &kept, sizeof(V));
        for (int l = 0; l < L; ++l) column_index[j + l] = int(kept_who[l]);
      }
    }
    if (!x_to_y) continue;
    for (int r = 0; r < R; ++r) {  // the lanes merged: least distance, then lowest index
      T best = row_best[r][0];
      Int at = row_at[r][0];
      for (int l = 1; l < L; ++l)
        if (row_best[r][l] < best || (row_best[r][l] == best && row_at[r][l] < at)) {
          best = row_best[r][l];
          at = row_at[r][l];
        }
      // (Every distance infinite, the coordinates' squares overflowing: the first.)
      (*x_to_y)[size_t(i0 + r)] = at == Int(std::numeric_limits<int>::max()) ? 0 : int(at);
      if (x_distance) (*x_distance)[size_t(i0 + r)] = best;
    }
  }
}

template <class T, int Dim>
void scan_nearest(const Block<T>& x, const Block<T>& y, std::vector<int>* x_to_y,
                  std::vector<T>* x_distance, std::vector<int>* y_to_x, std::vector<T>* y_distance,
                  ScanScratch<T>& s) {
  constexpr int L = int(sizeof(typename ScanLanes<T>::Value) / sizeof(T));
  constexpr int R = 4;  // rows per pass over y
  const Index m = x.rows(), n = y.rows(), cols = x.cols();
  const Index padded = (n + L - 1) / L * L;
  s.transposed.assign(size_t(cols * padded), std::numeric_limits<T>::infinity());
  for (Index j = 0; j < n; ++j)
    for (Index c = 0; c < cols; ++c) s.transposed[size_t(c * padded + j)] = y(j, c);
  const bool parallel = double(m) * double(n) > 1e5 && !region_would_be_serial();
  const int threads = parallel ? max_threads() : 1;
  if (y_to_x) {
    s.column_best.assign(size_t(threads) * size_t(padded), std::numeric_limits<T>::infinity());
    s.column_index.assign(size_t(threads) * size_t(padded), 0);
  }
  auto rows = [&](int thread, Index begin, Index end) {
    T* column_best = y_to_x ? s.column_best.data() + size_t(thread) * size_t(padded) : nullptr;
    int* column_index = y_to_x ? s.column_index.data() + size_t(thread) * size_t(padded) : nullptr;
    const Index blocked = begin + (end - begin) / R * R;
    scan_rows<T, Dim, R>(x.data(), cols, s.transposed.data(), padded, begin, blocked, x_to_y,
                         x_distance, column_best, column_index);
    scan_rows<T, Dim, 1>(x.data(), cols, s.transposed.data(), padded, blocked, end, x_to_y,
                         x_distance, column_best, column_index);
  };
  if (threads == 1) {
    rows(0, 0, m);
  } else {
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int t = 0; t < threads; ++t) rows(t, m * t / threads, m * (t + 1) / threads);
  }
  if (!y_to_x) return;
  for (Index j = 0; j < n; ++j) {
    T best = s.column_best[size_t(j)];
    int at = s.column_index[size_t(j)];
    for (int t = 1; t < threads; ++t) {
      const size_t k = size_t(t) * size_t(padded) + size_t(j);
      if (s.column_best[k] < best) {
        best = s.column_best[k];
        at = s.column_index[k];
      }
    }
    (*y_to_x)[size_t(j)] = at;
    if (y_distance) (*y_distance)[size_t(j)] = best;
  }
}

template <class T>
void scan_nearest(const Block<T>& x, const Block<T>& y, std::vector<int>* x_to_y,
                  std::vector<T>* x_distance, std::vector<int>* y_to_x, std::vector<T>* y_distance,
                  ScanScratch<T>& s) {
  switch (x.cols()) {
    case 2:
      return scan_nearest<T, 2>(x, y, x_to_y, x_distance, y_to_x, y_distance, s);
    case 3:
      return scan_nearest<T, 3>(x, y, x_to_y, x_distance, y_to_x, y_distance, s);
    case 6:
      return scan_nearest<T, 6>(x, y, x_to_y, x_distance, y_to_x, y_distance, s);
    case 9:
      return scan_nearest<T, 9>(x, y, x_to_y, x_distance, y_to_x, y_distance, s);
    default:
      return scan_nearest<T, -1>(x, y, x_to_y, x_distance, y_to_x, y_distance, s);
  }
}

// `points_checked`: the points' finiteness was checked when their index was built
// (a NearestIndex's pool is fixed, and scanning 10^5-10^6 floats on every query
// cost 1.7-2.1% of a training step, docs/performance.md).
template <class T>
void check_shapes(const Block<T>& queries, const Block<T>& points, bool points_checked = false) {
  JSA_CHECK(points.rows() >= 1, "nearest: no points to search");
  JSA_CHECK(queries.cols() == points.cols(),
            "nearest: queries have " << queries.cols() << " columns, points " << points.cols());
  JSA_CHECK(points.rows() < Index(std::numeric_limits<int>::max()), "nearest: too many points");
  JSA_CHECK(queries.allFinite() && (points_checked || points.allFinite()),
            "nearest: a coordinate is not finite");
}

}  // namespace

// One cache per column count nearest() fixes at compile time.
template <class T>
struct NearestScratch<T>::Impl {
  TreeCache<T, 2> d2;
  TreeCache<T, 3> d3;
  TreeCache<T, 6> d6;
  TreeCache<T, 9> d9;
  TreeCache<T, -1> any;
  ScanScratch<T> scan;
};

template <class T>
NearestScratch<T>::NearestScratch() : impl_(std::make_unique<Impl>()) {}
template <class T>
NearestScratch<T>::~NearestScratch() = default;
template <class T>
NearestScratch<T>::NearestScratch(NearestScratch&&) noexcept = default;
template <class T>
NearestScratch<T>& NearestScratch<T>::operator=(NearestScratch&&) noexcept = default;

template <class T>
void nearest(const Block<T>& queries, const Block<T>& points, std::vector<int>& index,
             std::vector<T>* squared_distance, NearestScratch<T>* scratch) {
  check_shapes(queries, points);
  index.resize(queries.rows());
  if (squared_distance) squared_distance->resize(queries.rows());
  typename NearestScratch<T>::Impl* s = scratch ? &scratch->impl() : nullptr;
  if (double(queries.rows()) * double(points.rows()) <= kPairsByScan) {
    ScanScratch<T> local;
    scan_nearest<T>(queries, points, &index, squared_distance, nullptr, nullptr,
                    s ? s->scan : local);
    return;
  }
  switch (points.cols()) {
    case 2:
      return nearest_kdtree<T, 2>(queries, points, index, squared_distance, s ? &s->d2 : nullptr);
    case 3:
      return nearest_kdtree<T, 3>(queries, points, index, squared_distance, s ? &s->d3 : nullptr);
    case 6:
      return nearest_kdtree<T, 6>(queries, points, index, squared_distance, s ? &s->d6 : nullptr);
    case 9:  // L_6D with the intrinsic descriptors (io/geometry/intrinsic_descriptors.h)
      return nearest_kdtree<T, 9>(queries, points, index, squared_distance, s ? &s->d9 : nullptr);
    default:
      return nearest_kdtree<T, -1>(queries, points, index, squared_distance, s ? &s->any : nullptr);
  }
}

// NearestIndex: the points, and a tree over them whose column count is fixed
// at compile time where nearest() fixes it.
template <class T>
struct NearestIndex<T>::Impl {
  Block<T> points;
  RowsSource<T> source;
  explicit Impl(Block<T> p)
      : points(std::move(p)), source{points.data(), size_t(points.rows()), size_t(points.cols())} {}
  virtual ~Impl() = default;
  // order and code: the visiting order's storage (a NearestScratch's, or the call's own).
  virtual void query(const Block<T>& q, std::vector<int>& index, std::vector<T>* d,
                     std::vector<Index>& order, std::vector<uint64_t>& code) const = 0;
};

namespace {
template <class T, int Dim>
struct TreeImpl final : NearestIndex<T>::Impl {
  std::unique_ptr<KdTree<T, Dim>> tree;
  explicit TreeImpl(Block<T> p)
      : NearestIndex<T>::Impl(std::move(p)), tree(build_tree<T, Dim>(this->source)) {}
  void query(const Block<T>& q, std::vector<int>& index, std::vector<T>* d,
             std::vector<Index>& order, std::vector<uint64_t>& code) const override {
    query_tree<T, Dim>(*tree, q, index, d, order, code);
  }
};
}  // namespace

template <class T>
NearestIndex<T>::NearestIndex(Block<T> points) {
  check_shapes(points, points);
  switch (points.cols()) {
    case 2:
      impl_ = std::make_unique<TreeImpl<T, 2>>(std::move(points));
      break;
    case 3:
      impl_ = std::make_unique<TreeImpl<T, 3>>(std::move(points));
      break;
    case 6:
      impl_ = std::make_unique<TreeImpl<T, 6>>(std::move(points));
      break;
    case 9:
      impl_ = std::make_unique<TreeImpl<T, 9>>(std::move(points));
      break;
    default:
      impl_ = std::make_unique<TreeImpl<T, -1>>(std::move(points));
      break;
  }
}

template <class T>
NearestIndex<T>::~NearestIndex() = default;
template <class T>
NearestIndex<T>::NearestIndex(NearestIndex&&) noexcept = default;
template <class T>
NearestIndex<T>& NearestIndex<T>::operator=(NearestIndex&&) noexcept = default;

template <class T>
void NearestIndex<T>::query(const Block<T>& queries, std::vector<int>& index,
                            std::vector<T>* squared_distance, NearestScratch<T>* scratch) const {
  check_shapes(queries, impl_->points, /*points_checked=*/true);
  index.resize(queries.rows());
  if (squared_distance) squared_distance->resize(queries.rows());
  if (scratch) {  // the order's storage of the generic cache (no tree of its own is built)
    auto& cache = scratch->impl().any;
    impl_->query(queries, index, squared_distance, cache.order, cache.code);
    return;
  }
  std::vector<Index> order;
  std::vector<uint64_t> code;
  impl_->query(queries, index, squared_distance, order, code);
}

template <class T>
const Block<T>& NearestIndex<T>::points() const {
  return impl_->points;
}

template <class T>
void nearest_both_ways(const Block<T>& x, const Block<T>& y, std::vector<int>& x_to_y,
                       std::vector<T>* x_distance, std::vector<int>& y_to_x,
                       std::vector<T>* y_distance, NearestScratch<T>* x_scratch,
                       NearestScratch<T>* y_scratch) {
  if (double(x.rows()) * double(y.rows()) > kPairsByScan) {
    nearest(x, y, x_to_y, x_distance, x_scratch);
    nearest(y, x, y_to_x, y_distance, y_scratch);
    return;
  }
  check_shapes(x, y);  // both sets finite, y not empty, the same columns
  JSA_CHECK(x.rows() >= 1, "nearest: no points to search");
  x_to_y.resize(x.rows());
  y_to_x.resize(y.rows());
  if (x_distance) x_distance->resize(x.rows());
  if (y_distance) y_distance->resize(y.rows());
  ScanScratch<T> local;
  scan_nearest(x, y, &x_to_y, x_distance, &y_to_x, y_distance,
               x_scratch ? x_scratch->impl().scan : local);
}

template <class T>
void nearest_brute_force(const Block<T>& queries, const Block<T>& points, std::vector<int>& index,
                         std::vector<T>* squared_distance) {
  check_shapes(queries, points);
  const Index m = queries.rows(), n = points.rows();
  const size_t c = size_t(points.cols());
  index.resize(m);
  if (squared_distance) squared_distance->resize(m);
#pragma omp parallel for schedule(static) if (m > 64)
  for (Index i = 0; i < m; ++i) {
    const T* q = queries.data() + size_t(i) * c;
    T best = std::numeric_limits<T>::max();
    int best_j = -1;
    for (Index j = 0; j < n; ++j) {
      const T d = squared_l2<T, -1>(q, points.data() + size_t(j) * c, c);
      if (best_j < 0 || d < best) {  // strict: the lowest index wins ties
        best = d;
        best_j = int(j);
      }
    }
    index[i] = best_j;
    if (squared_distance) (*squared_distance)[i] = best;
  }
}

#define JSA_INSTANTIATE(T)                                                                       \
  template class NearestScratch<T>;                                                              \
  template void nearest<T>(const Block<T>&, const Block<T>&, std::vector<int>&, std::vector<T>*, \
                           NearestScratch<T>*);                                                  \
  template void nearest_brute_force<T>(const Block<T>&, const Block<T>&, std::vector<int>&,      \
                                       std::vector<T>*);                                         \
  template void nearest_both_ways<T>(const Block<T>&, const Block<T>&, std::vector<int>&,        \
                                     std::vector<T>*, std::vector<int>&, std::vector<T>*,        \
                                     NearestScratch<T>*, NearestScratch<T>*);                    \
  template class NearestIndex<T>;
JSA_INSTANTIATE(float)
JSA_INSTANTIATE(double)

}  // namespace jsa
