// nearest() against its brute-force oracle, in the dimensions the model uses
// (2: the domain, 3: xyz, 6: xyz + scaled normals) and one generic (5). The
// [.bench] case times the training-loop sizes: `test_geometry "[.bench]"`.
#include <algorithm>
#include <catch2/catch.hpp>
#include <chrono>
#include <cstdio>
#include <limits>

#include "engine/parallel.h"
#include "engine/rng.h"
#include "io/geometry/nearest.h"
#include "test/normal_draws.h"

using namespace jsa;

namespace {

template <class T>
Block<T> random_block(Index n, Index c, uint64_t seed, double scale = 1.0) {
  Rng rng(seed);
  Block<T> b(n, c);
  for (Index i = 0; i < b.size(); ++i) b.data()[i] = T(scale * rng.uniform(-1, 1));
  return b;
}

// xyz in [-1, 1]^3 plus a random unit normal scaled to 0.01: the L_6D targets.
template <class T>
Block<T> points_with_normals(Index n, uint64_t seed) {
  Rng rng(seed);
  Block<T> b(n, 6);
  for (Index i = 0; i < n; ++i) {
    Eigen::Vector3d normal = test_support::normal_vector3(rng);
    normal = 0.01 * normal.normalized();
    for (int d = 0; d < 3; ++d) b(i, d) = T(rng.uniform(-1, 1));
    for (int d = 0; d < 3; ++d) b(i, 3 + d) = T(normal(d));
  }
  return b;
}

template <class T>
void expect_same_as_brute_force(const Block<T>& q, const Block<T>& p) {
  std::vector<int> index, oracle_index;
  std::vector<T> dist, oracle_dist;
  nearest(q, p, index, &dist);
  nearest_brute_force(q, p, oracle_index, &oracle_dist);
  REQUIRE(index.size() == size_t(q.rows()));
  int mismatches = 0;
  for (Index i = 0; i < q.rows(); ++i) {
    if (index[i] != oracle_index[i]) ++mismatches;
    CHECK(dist[i] == Approx(oracle_dist[i]).epsilon(1e-5).margin(1e-12));
    // the reported distance is the distance to the reported point
    CHECK(dist[i] == Approx((q.row(i) - p.row(index[i])).squaredNorm()).epsilon(1e-5));
  }
  CHECK(mismatches == 0);
}

}  // namespace

TEMPLATE_TEST_CASE("nearest matches brute force in 2, 3, 5 and 6 columns", "[nearest]", float,
                   double) {
  for (Index c : {2, 3, 5}) {
    INFO("columns " << c);
    expect_same_as_brute_force(random_block<TestType>(700, c, 1 + c),
                               random_block<TestType>(900, c, 11 + c));
  }
  expect_same_as_brute_force(points_with_normals<TestType>(800, 3),
                             points_with_normals<TestType>(1000, 4));
  // queries far outside the points' bounding box
  expect_same_as_brute_force(random_block<TestType>(200, 2, 5, 10.0),
                             random_block<TestType>(300, 2, 6));
}

TEMPLATE_TEST_CASE("a NearestIndex built once answers like nearest() on every query", "[nearest]",
                   float, double) {
  for (Index c : {2, 3, 5, 6}) {
    INFO("columns " << c);
    const Block<TestType> points =
        c == 6 ? points_with_normals<TestType>(1500, 20) : random_block<TestType>(1500, c, 21 + c);
    const NearestIndex<TestType> index(points);
    CHECK(index.points() == points);
    // Several query sets against the one tree, each checked against the oracle.
    for (uint64_t round = 0; round < 3; ++round) {
      const Block<TestType> q = c == 6 ? points_with_normals<TestType>(400, 30 + round)
                                       : random_block<TestType>(400, c, 40 + round, 1.5);
      std::vector<int> got, oracle;
      std::vector<TestType> dist, oracle_dist;
      index.query(q, got, &dist);
      nearest_brute_force(q, points, oracle, &oracle_dist);
      REQUIRE(got.size() == size_t(q.rows()));
      CHECK(got == oracle);
      for (Index i = 0; i < q.rows(); ++i)
        CHECK(dist[i] == Approx(oracle_dist[i]).epsilon(1e-5).margin(1e-12));
    }
  }
  // Moving the index keeps the tree valid (it points into the moved-from storage).
  NearestIndex<TestType> a(random_block<TestType>(300, 3, 50));
  const Block<TestType> q = random_block<TestType>(100, 3, 51);
  std::vector<int> before, after;
  a.query(q, before);
  NearestIndex<TestType> b(std::move(a));
  b.query(q, after);
  CHECK(before == after);
  // Bad queries are refused, as by nearest().
  std::vector<int> idx;
  CHECK_THROWS(b.query(random_block<TestType>(5, 2, 52), idx));
  Block<TestType> nan_q = random_block<TestType>(5, 3, 53);
  nan_q(2, 1) = std::numeric_limits<TestType>::quiet_NaN();
  CHECK_THROWS(b.query(nan_q, idx));
  // A pool with a NaN is refused when its index is built: queries no longer
  // rescan the pool.
  Block<TestType> nan_pool = random_block<TestType>(300, 3, 54);
  nan_pool(120, 2) = std::numeric_limits<TestType>::quiet_NaN();
  CHECK_THROWS(NearestIndex<TestType>(nan_pool));
}

TEMPLATE_TEST_CASE("nearest of the points themselves is themselves", "[nearest]", float, double) {
  const Block<TestType> p = random_block<TestType>(500, 3, 21);
  std::vector<int> index;
  std::vector<TestType> dist;
  nearest(p, p, index, &dist);
  for (Index i = 0; i < p.rows(); ++i) {
    CHECK(index[i] == int(i));
    CHECK(dist[i] == 0);
  }
}

TEST_CASE("nearest breaks ties by the lowest index", "[nearest]") {
  // Points 0..49 repeated three times: every query has three equally near points
  // and both searches must return the copy with the lowest index.
  const Block<double> base = random_block<double>(50, 2, 31);
  Block<double> p(150, 2);
  p << base, base, base;
  const Block<double> q = random_block<double>(400, 2, 32);
  std::vector<int> index, oracle;
  nearest(q, p, index);
  nearest_brute_force(q, p, oracle);
  for (Index i = 0; i < q.rows(); ++i) {
    CHECK(index[i] < 50);
    CHECK(index[i] == oracle[i]);
  }
  // A query exactly between two points (distance 1 to both).
  Block<double> two(2, 2), mid(1, 2);
  two << 1, 0, -1, 0;
  mid << 0, 0;
  nearest(mid, two, index);
  CHECK(index[0] == 0);
}

TEST_CASE("nearest with one point, and with no queries", "[nearest]") {
  Block<float> one(1, 3), q = random_block<float>(10, 3, 41), none(0, 3);
  one << 0.5f, 0.5f, 0.5f;
  std::vector<int> index;
  nearest(q, one, index);
  CHECK(std::all_of(index.begin(), index.end(), [](int i) { return i == 0; }));
  nearest(none, q, index);
  CHECK(index.empty());
}

TEST_CASE("nearest does not depend on the thread count", "[nearest]") {
  const Block<float> q = points_with_normals<float>(3000, 51),
                     p = points_with_normals<float>(3000, 52);
  std::vector<int> a, b;
  std::vector<float> da, db;
  const int threads = max_threads();
  set_threads(1);
  nearest(q, p, a, &da);
  set_threads(std::max(2, threads));
  nearest(q, p, b, &db);
  set_threads(threads);
  CHECK(a == b);
  CHECK(da == db);
}

TEST_CASE("nearest answers each query as its own, whatever the queries' order and spread",
          "[nearest]") {
  // The search visits the queries in Morton order of their first three
  // coordinates (io/geometry/nearest.cpp); the answers must come back in the
  // callers' order. Reversed queries give reversed answers, and queries that
  // are flat in one coordinate (a zero-width Morton axis) or all at one point
  // still match the oracle.
  const Block<float> p = points_with_normals<float>(2000, 61);
  const NearestIndex<float> index(p);
  Block<float> q = points_with_normals<float>(500, 62);
  const Block<float> reversed = q.colwise().reverse();
  std::vector<int> forward, backward, oracle;
  index.query(q, forward);
  index.query(reversed, backward);
  std::reverse(backward.begin(), backward.end());
  CHECK(forward == backward);
  q.col(2).setConstant(0.25f);  // flat in z
  index.query(q, forward);
  nearest_brute_force(q, p, oracle);
  CHECK(forward == oracle);
  Block<float> same(100, 6);
  same.rowwise() = q.row(7);  // every query at one point
  index.query(same, forward);
  nearest_brute_force(same, p, oracle);
  CHECK(forward == oracle);
}

TEST_CASE("a scan and a tree give the same answers on either side of the scan's limit",
          "[nearest]") {
  // nearest() scans every distance when M N <= 2^24 and searches a kd-tree
  // above; both must be the oracle's answer, ties to the lowest index.
  const Block<float> q = points_with_normals<float>(4300, 71),
                     p = points_with_normals<float>(4000, 72);
  REQUIRE(double(q.rows()) * double(p.rows()) > double(1 << 24));
  expect_same_as_brute_force(q, p);                              // the tree
  expect_same_as_brute_force(Block<float>(q.topRows(1000)), p);  // the scan
}

TEMPLATE_TEST_CASE("nearest_both_ways gives nearest() in both directions", "[nearest]", float,
                   double) {
  // Points 0..299 repeated: every point of x has two equally near points in
  // y, and every point of y's first copy is tied with its second.
  const Block<TestType> base = points_with_normals<TestType>(300, 81);
  Block<TestType> y(600, 6);
  y << base, base;
  const Block<TestType> x = points_with_normals<TestType>(700, 82);
  for (const bool large : {false, true}) {
    // Large: 4200 x 4200, above the scan's limit, two tree searches.
    const Block<TestType> a = large ? points_with_normals<TestType>(4200, 83) : x;
    const Block<TestType> b = large ? points_with_normals<TestType>(4200, 84) : y;
    std::vector<int> ab, ba, ab_oracle, ba_oracle;
    std::vector<TestType> dab, dba, dab_oracle, dba_oracle;
    NearestScratch<TestType> sa, sb;
    for (int round = 0; round < 2; ++round) {  // the second reuses the scratch
      INFO("large " << large << ", round " << round);
      nearest_both_ways(a, b, ab, &dab, ba, &dba, &sa, &sb);
      nearest_brute_force(a, b, ab_oracle, &dab_oracle);
      nearest_brute_force(b, a, ba_oracle, &dba_oracle);
      CHECK(ab == ab_oracle);
      CHECK(ba == ba_oracle);
      // The distances are summed with the same terms in the same order, but
      // the compiler may fuse them differently in the oracle's generic loop.
      for (size_t i = 0; i < ab.size(); ++i)
        CHECK(dab[i] == Approx(dab_oracle[i]).epsilon(1e-6).margin(1e-12));
      for (size_t j = 0; j < ba.size(); ++j)
        CHECK(dba[j] == Approx(dba_oracle[j]).epsilon(1e-6).margin(1e-12));
    }
  }
}

TEST_CASE("nearest_both_ways does not depend on the thread count", "[nearest]") {
  const Block<float> x = points_with_normals<float>(2500, 91),
                     y = points_with_normals<float>(2300, 92);
  std::vector<int> a1, b1, a2, b2;
  std::vector<float> da1, db1, da2, db2;
  const int threads = max_threads();
  set_threads(1);
  nearest_both_ways(x, y, a1, &da1, b1, &db1);
  set_threads(std::max(2, threads));
  nearest_both_ways(x, y, a2, &da2, b2, &db2);
  set_threads(threads);
  CHECK(a1 == a2);
  CHECK(b1 == b2);
  CHECK(da1 == da2);
  CHECK(db1 == db2);
}

TEST_CASE("nearest timing at training-loop sizes", "[.bench][nearest]") {
  // 10^4 x 10^4 in 2D (L_2D) and 6D (L_6D), float; median of 15 runs.
  auto median_ms = [](auto&& f) {
    std::vector<double> ms;
    for (int r = 0; r < 15; ++r) {
      const auto t0 = std::chrono::steady_clock::now();
      f();
      ms.push_back(
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    }
    std::sort(ms.begin(), ms.end());
    return ms[ms.size() / 2];
  };
  std::vector<int> index, oracle;
  const Block<float> q2 = random_block<float>(10000, 2, 61), p2 = random_block<float>(10000, 2, 62);
  const Block<float> q6 = points_with_normals<float>(10000, 63),
                     p6 = points_with_normals<float>(10000, 64);
  nearest(q2, p2, index);
  nearest_brute_force(q2, p2, oracle);
  REQUIRE(index == oracle);  // validate, then time
  nearest(q6, p6, index);
  nearest_brute_force(q6, p6, oracle);
  REQUIRE(index == oracle);
  const double k2 = median_ms([&] { nearest(q2, p2, index); });
  const double k6 = median_ms([&] { nearest(q6, p6, index); });
  const double b2 = median_ms([&] { nearest_brute_force(q2, p2, oracle); });
  std::printf(
      "nearest 10^4 x 10^4, %d threads, median of 15: 2D %.2f ms, 6D %.2f ms"
      " (brute force 2D %.1f ms)\n",
      max_threads(), k2, k6, b2);

  // The Chamfer terms' sizes at the default M = 2500: both directions by the
  // scan (nearest_both_ways) against two kd-trees built and searched
  // (NearestIndex always uses a tree).
  for (const Index c : {Index(2), Index(6)}) {
    const Block<float> x =
        c == 6 ? points_with_normals<float>(2500, 65) : random_block<float>(2500, 2, 65);
    const Block<float> y =
        c == 6 ? points_with_normals<float>(2500, 66) : random_block<float>(2500, 2, 66);
    std::vector<int> xy, yx, xy_tree, yx_tree;
    NearestScratch<float> sx, sy;
    nearest_both_ways<float>(x, y, xy, nullptr, yx, nullptr, &sx, &sy);
    NearestIndex<float>(y).query(x, xy_tree);
    NearestIndex<float>(x).query(y, yx_tree);
    REQUIRE(xy == xy_tree);
    REQUIRE(yx == yx_tree);
    const double scan =
        median_ms([&] { nearest_both_ways<float>(x, y, xy, nullptr, yx, nullptr, &sx, &sy); });
    const double trees = median_ms([&] {
      NearestIndex<float>(y).query(x, xy_tree);
      NearestIndex<float>(x).query(y, yx_tree);
    });
    std::printf(
        "both ways 2500 x 2500 in %dD, %d threads, median of 15: scan %.3f ms, two trees %.3f ms\n",
        int(c), max_threads(), scan, trees);
  }
}
