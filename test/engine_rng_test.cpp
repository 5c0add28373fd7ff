// Tests of engine/rng.h: reproducibility, independent streams, and the moments
// of uniform() and normal(), and the range of below(n).
//
// Moment tolerances are ~4-5 standard errors for n = 200,000 draws (the draws
// are deterministic, so a pass is a pass forever; the margin is for seeds):
//   uniform mean   0.5 +- 0.003   (s.e. 0.289 / sqrt(n) = 6.5e-4)
//   uniform var  1/12 +- 0.001    (s.e. ~1.9e-4)
//   normal mean    0   +- 0.01    (s.e. 2.2e-3)
//   normal var     1   +- 0.015   (s.e. sqrt(2 / n) = 3.2e-3)
#include <catch2/catch.hpp>
#include <set>

#include "engine/check.h"
#include "engine/rng.h"

namespace jsa {

TEST_CASE("same seed, same sequence", "[rng]") {
  Rng a(42), b(42), c(43);
  bool differs = false;
  for (int i = 0; i < 1000; ++i) {
    const uint64_t x = a.next();
    CHECK(x == b.next());
    differs = differs || x != c.next();
  }
  CHECK(differs);
  // State round trip.
  Rng d(7);
  d.next();
  Rng e(0);
  e.set_state(d.state());
  for (int i = 0; i < 10; ++i) CHECK(d.next() == e.next());
}

TEST_CASE("different streams differ", "[rng]") {
  Rng s0(42, 0), s1(42, 1), s2(42, 2);
  int equal01 = 0, equal12 = 0;
  for (int i = 0; i < 1000; ++i) {
    const uint64_t a = s0.next(), b = s1.next(), c = s2.next();
    equal01 += a == b;
    equal12 += b == c;
  }
  CHECK(equal01 == 0);
  CHECK(equal12 == 0);

  // Derived streams: reproducible, and distinct from each other and the parent.
  const Rng parent(9);
  Rng p1 = parent.stream(1), p1b = parent.stream(1), p2 = parent.stream(2), pc = parent;
  int equal = 0;
  for (int i = 0; i < 1000; ++i) {
    const uint64_t a = p1.next();
    CHECK(a == p1b.next());
    equal += (a == p2.next()) + (a == pc.next());
  }
  CHECK(equal == 0);
}

TEST_CASE("uniform() and normal() have the right moments", "[rng]") {
  const int n = 200000;
  Rng rng(2022);
  double s = 0, s2 = 0, lo = 1, hi = 0;
  for (int i = 0; i < n; ++i) {
    const double u = rng.uniform();
    s += u;
    s2 += u * u;
    lo = std::min(lo, u);
    hi = std::max(hi, u);
  }
  const double mean = s / n, var = s2 / n - mean * mean;
  INFO("uniform mean " << mean << " var " << var << " range [" << lo << ", " << hi << "]");
  CHECK(std::abs(mean - 0.5) < 0.003);
  CHECK(std::abs(var - 1.0 / 12) < 0.001);
  CHECK(lo >= 0.0);
  CHECK(hi < 1.0);

  double t = 0, t2 = 0;
  for (int i = 0; i < n; ++i) {
    const double z = rng.normal();
    REQUIRE(std::isfinite(z));
    t += z;
    t2 += z * z;
  }
  const double nmean = t / n, nvar = t2 / n - nmean * nmean;
  INFO("normal mean " << nmean << " var " << nvar);
  CHECK(std::abs(nmean) < 0.01);
  CHECK(std::abs(nvar - 1.0) < 0.015);

  Rng r2(1);
  for (int i = 0; i < 1000; ++i) {
    const double x = r2.uniform(-3.0, 5.0);
    CHECK(x >= -3.0);
    CHECK(x < 5.0);
  }
}

// (No square bracket in a test's name: catch_discover_tests hands CMake a
// list, and a '[' there keeps the names after it from being split, so they
// ran as one ctest entry that matched no test and passed.)
TEST_CASE("below(n) stays in 0..n-1 and reaches every value", "[rng]") {
  Rng rng(5);
  for (uint64_t n : {uint64_t(1), uint64_t(2), uint64_t(7), uint64_t(1000)}) {
    std::set<uint64_t> seen;
    for (int i = 0; i < 20000; ++i) {
      const uint64_t k = rng.below(n);
      REQUIRE(k < n);
      seen.insert(k);
    }
    INFO("n = " << n);
    CHECK(seen.size() == n);
  }
  CHECK_THROWS_AS(rng.below(0), InternalError);  // empty range: a programmer error
  // A bound past 2^63, where a naive modulo would be badly biased.
  const uint64_t big = (uint64_t(1) << 63) + 12345;
  int upper = 0;
  for (int i = 0; i < 10000; ++i) {
    const uint64_t k = rng.below(big);
    REQUIRE(k < big);
    upper += k >= big / 2;
  }
  CHECK(upper > 4700);  // ~half land in the upper half (s.e. 50)
  CHECK(upper < 5300);
}

}  // namespace jsa
