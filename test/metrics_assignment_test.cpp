// Linear assignment: LAPJV against the brute-force oracle (small n, with ties and
// zeros), against the independent auction on the same integer matrix (exactly
// equal optimal costs), and against its own duality certificate at n = 2000.
#include <algorithm>
#include <catch2/catch.hpp>
#include <chrono>
#include <cstdio>
#include <limits>
#include <numeric>

#include "engine/check.h"
#include "engine/rng.h"
#include "losses/metrics/assignment.h"
#include "losses/metrics/assignment_auction.h"
#include "losses/metrics/emd.h"

using namespace jsa;

namespace {

// Small integers, so many entries tie and some are zero; costs stay exact in double.
Block<double> tied_costs(int n, int levels, Rng& rng) {
  Block<double> c(n, n);
  for (Index k = 0; k < c.size(); ++k) c.data()[k] = double(rng.below(levels));
  return c;
}

Block<double> uniform_costs(int n, Rng& rng) {
  Block<double> c(n, n);
  for (Index k = 0; k < c.size(); ++k) c.data()[k] = rng.uniform(-1, 1);
  return c;
}

Block<double> random_points(Index n, uint64_t seed) {
  Rng rng(seed);
  Block<double> p(n, 3);
  for (Index k = 0; k < p.size(); ++k) p.data()[k] = rng.uniform(-1, 1);
  return p;
}

bool is_permutation_of_n(const std::vector<int>& p) {
  std::vector<int> s = p;
  std::sort(s.begin(), s.end());
  for (size_t k = 0; k < s.size(); ++k)
    if (s[k] != int(k)) return false;
  return true;
}

double cost_of(const Block<double>& c, const std::vector<int>& column_of_row) {
  double s = 0;
  for (size_t i = 0; i < column_of_row.size(); ++i) s += c(Index(i), column_of_row[i]);
  return s;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

TEST_CASE("LAPJV matches brute force on random n <= 8, with ties and zeros", "[assignment]") {
  Rng rng(11);
  int cases = 0;
  for (int n = 1; n <= 8; ++n) {
    for (int levels : {1, 2, 3, 10, 1000}) {
      const int repeats = n <= 6 ? 40 : 6;
      for (int r = 0; r < repeats; ++r) {
        const Block<double> c = tied_costs(n, levels, rng);
        const Assignment fast = assign_lapjv(c), oracle = assign_brute_force(c);
        INFO("n = " << n << ", levels = " << levels << "\n" << c);
        REQUIRE(is_permutation_of_n(fast.column_of_row));
        CHECK(fast.cost == oracle.cost);  // integers: exact
        CHECK(cost_of(c, fast.column_of_row) == fast.cost);
        CHECK(check_certificate(c, fast).proves_optimal(0.0));
        ++cases;
      }
    }
  }
  // real-valued costs, negative ones included
  for (int r = 0; r < 300; ++r) {
    const int n = 1 + int(rng.below(8));
    const Block<double> c = uniform_costs(n, rng);
    const Assignment fast = assign_lapjv(c), oracle = assign_brute_force(c);
    INFO("n = " << n << "\n" << c);
    CHECK(fast.cost == Approx(oracle.cost).margin(1e-12));
    CHECK(check_certificate(c, fast).proves_optimal(1e-12));
    ++cases;
  }
  CHECK(cases > 1000);
}

TEST_CASE("brute force oracle catches a wrong matching", "[assignment]") {
  // The certificate must reject a non-optimal matching: swap two columns of an
  // optimal answer on a matrix with a unique optimum.
  Block<double> c(3, 3);
  c << 1, 5, 9,  //
      6, 2, 7,   //
      8, 9, 3;
  Assignment a = assign_lapjv(c);
  CHECK(a.column_of_row == std::vector<int>{0, 1, 2});
  CHECK(a.cost == 6);
  CHECK(assign_brute_force(c).cost == 6);
  std::swap(a.column_of_row[0], a.column_of_row[1]);
  CHECK_FALSE(check_certificate(c, a).proves_optimal(1e-9));
  a.column_of_row[0] = a.column_of_row[1];
  CHECK_FALSE(check_certificate(c, a).is_permutation);
}

TEST_CASE("assignment degenerate inputs", "[assignment]") {
  SECTION("n = 0 and n = 1") {
    CHECK(assign_lapjv(Block<double>(0, 0)).column_of_row.empty());
    Block<double> one(1, 1);
    one << -2.5;
    const Assignment a = assign_lapjv(one);
    CHECK(a.column_of_row == std::vector<int>{0});
    CHECK(a.cost == -2.5);
    CHECK(check_certificate(one, a).proves_optimal(0.0));
    CHECK(assign_auction(integer_costs(one, 2.0)).cost == -5);
  }
  SECTION("all costs equal") {
    for (int n : {2, 7, 100}) {
      const Block<double> c = Block<double>::Constant(n, n, 4.0);
      const Assignment a = assign_lapjv(c);
      REQUIRE(is_permutation_of_n(a.column_of_row));
      CHECK(a.cost == 4.0 * n);
      CHECK(check_certificate(c, a).proves_optimal(0.0));
      CHECK(assign_auction(integer_costs(c, 1.0)).cost == 4 * n);
    }
  }
  SECTION("all zero") {
    const Block<double> c = Block<double>::Zero(50, 50);
    const Assignment a = assign_lapjv(c);
    REQUIRE(is_permutation_of_n(a.column_of_row));
    CHECK(a.cost == 0);
  }
  SECTION("identical point sets: cost 0, each point matched to itself") {
    const Block<double> p = random_points(300, 5);
    const Block<double> c = squared_distance_costs(p, p);
    const Assignment a = assign_lapjv(c);
    CHECK(a.cost == 0);
    std::vector<int> identity(300);
    std::iota(identity.begin(), identity.end(), 0);
    CHECK(a.column_of_row == identity);  // distinct points: the only zero-cost matching
  }
  SECTION("a rectangular matrix is a programmer error") {
    CHECK_THROWS_AS(assign_lapjv(Block<double>::Zero(2, 3)), InternalError);
  }
}

TEST_CASE("auction matches brute force on small integer matrices", "[assignment]") {
  Rng rng(23);
  for (int r = 0; r < 400; ++r) {
    const int n = 1 + int(rng.below(8));
    const int levels = r % 2 ? 3 : 1000;
    const Block<double> c = tied_costs(n, levels, rng);
    const IntegerAssignment a = assign_auction(integer_costs(c, 1.0));
    INFO("n = " << n << "\n" << c);
    REQUIRE(is_permutation_of_n(a.column_of_row));
    CHECK(double(a.cost) == assign_brute_force(c).cost);
  }
}

TEST_CASE("LAPJV and auction agree on larger matrices full of ties", "[assignment]") {
  // Few distinct values: many optimal matchings, many equal reduced costs, the
  // tie branches of both algorithms; the optimal cost is still unique.
  Rng rng(31);
  for (int levels : {2, 5, 1000}) {
    for (int n : {60, 300}) {
      const Block<double> c = tied_costs(n, levels, rng);
      const Assignment exact = assign_lapjv(c);
      const IntegerAssignment auction = assign_auction(integer_costs(c, 1.0));
      INFO("n = " << n << ", levels = " << levels);
      REQUIRE(is_permutation_of_n(exact.column_of_row));
      REQUIRE(is_permutation_of_n(auction.column_of_row));
      CHECK(double(auction.cost) == exact.cost);
      CHECK(check_certificate(c, exact).proves_optimal(0.0));
    }
  }
}

TEST_CASE("LAPJV stays exact when costs span many orders of magnitude", "[assignment]") {
  // Entries k * 1e16 + uniform[0, 1): near 1e16 a double's spacing is 2, so
  // price updates round and small price drops vanish (the case the bid budget
  // and the "drop rounded away" branch are there for). The solver must still
  // stop and be optimal up to that rounding.
  Rng rng(47);
  for (int r = 0; r < 200; ++r) {
    const int n = 2 + int(rng.below(7));
    Block<double> c(n, n);
    for (Index k = 0; k < c.size(); ++k) c.data()[k] = 1e16 * double(rng.below(3)) + rng.uniform();
    const Assignment fast = assign_lapjv(c), oracle = assign_brute_force(c);
    INFO("n = " << n << "\n" << c);
    REQUIRE(is_permutation_of_n(fast.column_of_row));
    CHECK(fast.cost == Approx(oracle.cost).margin(8 * n));  // a few spacings per row
  }
  const int n = 300;
  Block<double> c(n, n);
  for (Index k = 0; k < c.size(); ++k) c.data()[k] = 1e16 * double(rng.below(3)) + rng.uniform();
  const Assignment a = assign_lapjv(c);
  REQUIRE(is_permutation_of_n(a.column_of_row));
  CHECK(check_certificate(c, a).max_dual_violation <= 64.0);  // ~ spacing 2 times a few roundings
}

TEST_CASE("auction refuses costs that could overflow, integer_costs non-finite input",
          "[assignment]") {
  Block<int64_t> huge = Block<int64_t>::Zero(100, 100);
  huge(3, 7) = int64_t(1) << 50;  // times (n + 1)^2 ~ 2^63.3: too large
  CHECK_THROWS_AS(assign_auction(huge), InternalError);
  huge(3, 7) = int64_t(1) << 40;  // ~ 2^53.3: fine
  CHECK(assign_auction(huge).cost == 0);
  Block<double> c = Block<double>::Zero(2, 2);
  c(1, 1) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(integer_costs(c, 1.0), InternalError);
  CHECK_THROWS_AS(assign_lapjv(c), InternalError);
}

TEST_CASE("LAPJV and auction agree exactly on integer-scaled squared distances", "[assignment]") {
  // Costs are round(1e6 |x - y|^2): both algorithms solve the same integer
  // matrix, LAPJV in double (exact: integers below 2^53), the auction in int64.
  for (int n : {200, 2000}) {
    const Block<int64_t> ci = integer_costs(
        squared_distance_costs(random_points(n, 100 + n), random_points(n, 200 + n)), 1e6);
    const Block<double> cd = ci.cast<double>();
    auto t0 = std::chrono::steady_clock::now();
    const Assignment exact = assign_lapjv(cd);
    const double lapjv_seconds = seconds_since(t0);
    t0 = std::chrono::steady_clock::now();
    const IntegerAssignment auction = assign_auction(ci);
    const double auction_seconds = seconds_since(t0);
    std::printf("n = %d: LAPJV %.3f s, auction %.3f s (%d phases, %lld bids)\n", n, lapjv_seconds,
                auction_seconds, auction.phases, (long long)auction.bids);
    REQUIRE(is_permutation_of_n(auction.column_of_row));
    CHECK(double(auction.cost) == exact.cost);
    CHECK(cost_of(cd, auction.column_of_row) == exact.cost);
    CHECK(check_certificate(cd, exact).proves_optimal(0.0));
  }
}

TEST_CASE("LAPJV duality certificate on 2000 x 2000 squared distances", "[assignment]") {
  const int n = 2000;
  const Block<double> c = squared_distance_costs(random_points(n, 1), random_points(n, 2));
  const auto t0 = std::chrono::steady_clock::now();
  const Assignment a = assign_lapjv(c);
  std::printf("LAPJV 2000 x 2000 (double): %.3f s, cost %.6f\n", seconds_since(t0), a.cost);
  const AssignmentCertificate cert = check_certificate(c, a);
  INFO("dual violation " << cert.max_dual_violation << ", slackness "
                         << cert.max_slackness_violation);
  CHECK(cert.proves_optimal(1e-12));
  CHECK(cert.cost_gap_bound < 1e-8);
  CHECK(cost_of(c, a.column_of_row) == Approx(a.cost).epsilon(1e-14));
  // Deterministic: a second solve gives the same matching.
  CHECK(assign_lapjv(c).column_of_row == a.column_of_row);
}

TEST_CASE("LAPJV with a kept workspace: the same solves as fresh ones, sizes up and down",
          "[assignment]") {
  // One result and one workspace carried through problems of changing n (the
  // training step's L_EMD keeps them across steps): every solve must equal a
  // solve from nothing, matching, cost and duals, whatever the previous one left.
  Rng rng(7);
  Assignment kept;
  AssignmentWorkspace workspace;
  for (int n : {6, 40, 1, 0, 40, 17, 3, 40}) {
    const Block<double> c = n % 2 ? tied_costs(n, 4, rng) : uniform_costs(n, rng);
    assign_lapjv(c, kept, workspace);
    const Assignment fresh = assign_lapjv(c);
    INFO("n = " << n);
    CHECK(kept.column_of_row == fresh.column_of_row);
    CHECK(kept.row_dual == fresh.row_dual);
    CHECK(kept.column_dual == fresh.column_dual);
    CHECK(kept.cost == fresh.cost);
    CHECK(check_certificate(c, kept).proves_optimal(1e-12));
  }
}
