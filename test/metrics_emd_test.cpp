// EMD metrics (Eq. 13): zero for a permuted copy, a brute-force association on
// small sets, true inequalities against the Chamfer metric (the assignment
// distance of a point is at least its nearest-neighbour distance) and Jensen's,
// symmetry, and the input errors.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <numeric>

#include "engine/check.h"
#include "engine/parallel.h"
#include "engine/rng.h"
#include "losses/metrics/assignment.h"
#include "losses/metrics/emd.h"
#include "losses/metrics/metrics.h"
#include "test/normal_draws.h"

using namespace jsa;

namespace {

struct OrientedPoints {
  Block<double> points, normals;
};

// xyz in [-1, 1]^3 with random unit normals.
OrientedPoints random_oriented(Index n, uint64_t seed) {
  Rng rng(seed);
  OrientedPoints s{Block<double>(n, 3), Block<double>(n, 3)};
  for (Index i = 0; i < n; ++i) {
    for (int d = 0; d < 3; ++d) s.points(i, d) = rng.uniform(-1, 1);
    Eigen::Vector3d normal = test_support::normal_vector3(rng);
    s.normals.row(i) = normal.normalized().transpose();
  }
  return s;
}

// Rows of s in the order perm: out[k] = s[perm[k]].
OrientedPoints permuted(const OrientedPoints& s, const std::vector<int>& perm) {
  OrientedPoints out{Block<double>(s.points.rows(), 3), Block<double>(s.points.rows(), 3)};
  for (size_t k = 0; k < perm.size(); ++k) {
    out.points.row(Index(k)) = s.points.row(perm[k]);
    out.normals.row(Index(k)) = s.normals.row(perm[k]);
  }
  return out;
}

std::vector<int> shuffled(int n, Rng& rng) {
  std::vector<int> p(n);
  std::iota(p.begin(), p.end(), 0);
  for (int k = n - 1; k > 0; --k) std::swap(p[k], p[rng.below(uint64_t(k) + 1)]);
  return p;
}

}  // namespace

TEST_CASE("EMD of a point set and a permuted copy is zero", "[emd]") {
  Rng rng(3);
  for (int n : {1, 2, 17, 500}) {
    const OrientedPoints s = random_oriented(n, 40 + n);
    const std::vector<int> perm = shuffled(n, rng);
    const OrientedPoints t = permuted(s, perm);
    std::vector<int> association;
    const EmdMetrics e = emd_metrics(s.points, s.normals, t.points, t.normals, &association);
    CHECK(e.spatial == 0);
    CHECK(e.spatial_squared == 0);
    CHECK(e.normal == 0);
    CHECK(e.seconds >= 0);
    // pred row i went to the copy of itself: t[k] = s[perm[k]], so k with perm[k] = i
    for (int i = 0; i < n; ++i) CHECK(perm[association[i]] == i);
  }
}

TEST_CASE("EMD association equals brute force on small sets", "[emd]") {
  for (uint64_t seed = 0; seed < 50; ++seed) {
    const int n = 1 + int(seed % 8);
    const OrientedPoints p = random_oriented(n, 1000 + seed), t = random_oriented(n, 2000 + seed);
    std::vector<int> association;
    const EmdMetrics e = emd_metrics(p.points, p.normals, t.points, t.normals, &association);
    // The oracle, written out: every permutation, the smallest sum of squared distances.
    std::vector<int> perm(n), best;
    std::iota(perm.begin(), perm.end(), 0);
    double best_sum = std::numeric_limits<double>::infinity();
    do {
      double sum = 0;
      for (int i = 0; i < n; ++i) sum += (p.points.row(i) - t.points.row(perm[i])).squaredNorm();
      if (sum < best_sum) {
        best_sum = sum;
        best = perm;
      }
    } while (std::next_permutation(perm.begin(), perm.end()));
    CHECK(e.spatial_squared == Approx(best_sum / n).epsilon(1e-12));
    // Random real points: the optimum is unique, so the association is too.
    CHECK(association == best);
    double spatial = 0, normal = 0;
    for (int i = 0; i < n; ++i) {
      spatial += (p.points.row(i) - t.points.row(best[i])).norm();
      normal += (p.normals.row(i) - t.normals.row(best[i])).norm();
    }
    CHECK(e.spatial == Approx(spatial / n).epsilon(1e-12));
    CHECK(e.normal == Approx(normal / n).epsilon(1e-12));
  }
}

TEST_CASE("EMD is at least the Chamfer spatial metric, and symmetric", "[emd]") {
  // Per point, |x_i - y_sigma(i)| >= min_j |x_i - y_j|: summing over i bounds
  // the X -> Y Chamfer direction, summing over sigma(i) the Y -> X one, so EMD
  // spatial >= their mean. And mean d^2 >= (mean d)^2 (Jensen).
  for (int n : {10, 200, 1000}) {
    const OrientedPoints p = random_oriented(n, 7 * n), t = random_oriented(n, 7 * n + 1);
    const EmdMetrics e = emd_metrics(p.points, p.normals, t.points, t.normals);
    const SurfaceMetrics chamfer = surface_metrics(p.points, p.normals, t.points, t.normals);
    INFO("n = " << n << ": EMD " << e.spatial << ", Chamfer " << chamfer.chamfer_spatial);
    CHECK(e.spatial >= chamfer.chamfer_spatial);
    CHECK(e.spatial > chamfer.chamfer_spatial);  // strict for random sets
    CHECK(e.spatial_squared >= e.spatial * e.spatial);
    // Swapping the roles transposes the cost matrix: the same optimum.
    const EmdMetrics back = emd_metrics(t.points, t.normals, p.points, p.normals);
    CHECK(back.spatial_squared == Approx(e.spatial_squared).epsilon(1e-12));
  }
}

TEST_CASE("EMD is the same for any thread count", "[emd]") {
  const OrientedPoints p = random_oriented(1000, 91), t = random_oriented(1000, 92);
  const int threads = max_threads();
  set_threads(1);
  std::vector<int> one, many;
  const EmdMetrics a = emd_metrics(p.points, p.normals, t.points, t.normals, &one);
  set_threads(std::max(2, threads));
  const EmdMetrics b = emd_metrics(p.points, p.normals, t.points, t.normals, &many);
  set_threads(threads);
  CHECK(one == many);
  CHECK(a.spatial == b.spatial);
  CHECK(a.spatial_squared == b.spatial_squared);
  CHECK(a.normal == b.normal);
}

TEST_CASE("squared distance costs against the obvious loop", "[emd]") {
  Rng rng(5);
  for (Index c : {2, 3, 6}) {
    Block<double> a(130, c), b(70, c);
    for (Index k = 0; k < a.size(); ++k) a.data()[k] = rng.uniform(-1, 1);
    for (Index k = 0; k < b.size(); ++k) b.data()[k] = rng.uniform(-1, 1);
    const Block<double> cost = squared_distance_costs(a, b);
    REQUIRE(cost.rows() == 130);
    REQUIRE(cost.cols() == 70);
    double worst = 0;
    for (Index i = 0; i < 130; ++i)
      for (Index j = 0; j < 70; ++j) {
        double sum = 0;
        for (Index d = 0; d < c; ++d) sum += (a(i, d) - b(j, d)) * (a(i, d) - b(j, d));
        worst = std::max(worst, std::abs(cost(i, j) - sum));
      }
    CHECK(worst <= 1e-14);  // entries are at most 4c; allow a few roundings
  }
}

TEST_CASE("EMD rejects bad input", "[emd]") {
  const OrientedPoints p = random_oriented(10, 1), t = random_oriented(11, 2);
  CHECK_THROWS_AS(emd_metrics(p.points, p.normals, t.points, t.normals), InputError);
  CHECK_THROWS_WITH(emd_metrics(p.points, p.normals, t.points, t.normals),
                    Catch::Contains("10") && Catch::Contains("11"));
  const Block<double> none(0, 3);
  CHECK_THROWS_AS(emd_metrics(none, none, none, none), InputError);
  const OrientedPoints q = random_oriented(10, 3);
  CHECK_THROWS_AS(emd_metrics(p.points, p.normals, q.points, q.normals.topRows(9)), InputError);
  Block<double> bad = q.points;
  bad(4, 1) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(emd_metrics(p.points, p.normals, bad, q.normals), InputError);
}
