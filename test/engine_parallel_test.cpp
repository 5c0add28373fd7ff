// Tests of engine/parallel.h: parallel_rows covers [0, n) exactly once in
// grain-sized ranges, whatever n is relative to the grain.
#include <omp.h>

#include <catch2/catch.hpp>
#include <cstdlib>
#include <limits>
#include <vector>

#include "engine/parallel.h"

namespace jsa {

TEST_CASE("parallel_rows covers every row exactly once", "[parallel]") {
  for (Index n : {Index(0), Index(1), Index(100), Index(2048), Index(2049), Index(10000)}) {
    std::vector<int> hits(size_t(n), 0);
    parallel_rows(n, [&](Index r0, Index r1) {
      for (Index i = r0; i < r1; ++i) hits[size_t(i)] += 1;  // disjoint ranges: no race
    });
    INFO("n = " << n);
    for (Index i = 0; i < n; ++i) REQUIRE(hits[size_t(i)] == 1);
  }
}

TEST_CASE("parallel_rows hands out ranges of at most grain rows", "[parallel]") {
  const Index n = 1000, grain = 64;
  std::vector<Index> sizes(size_t((n + grain - 1) / grain), -1);
  parallel_rows(
      n, [&](Index r0, Index r1) { sizes[size_t(r0 / grain)] = r1 - r0; }, grain);
  for (size_t c = 0; c + 1 < sizes.size(); ++c) CHECK(sizes[c] == grain);
  CHECK(sizes.back() == n % grain);
}

TEST_CASE("set_threads(0) keeps the thread count", "[parallel]") {
  const int before = max_threads();
  CHECK(before >= 1);
  set_threads(0);
  CHECK(max_threads() == before);
}

TEST_CASE("set_threads turns denormal floats off on every thread", "[parallel]") {
  if (std::getenv("JSATLAS_KEEP_DENORMALS")) return;  // the comparison switch is set
  set_threads(2);
  // 2^-126 is the smallest normal float; half of it is a denormal unless flushed.
  volatile float smallest = std::numeric_limits<float>::min();
  volatile float half = 0.5f;
  CHECK(denormals_flushed());
  CHECK(smallest * half == 0.0f);
  std::vector<int> flushed(16, -1);
#pragma omp parallel num_threads(2)
  {
    const int id = omp_get_thread_num();
    if (id < 16) flushed[size_t(id)] = denormals_flushed() && smallest * half == 0.0f ? 1 : 0;
  }
  CHECK(flushed[0] == 1);
  CHECK(flushed[1] == 1);
  set_threads(0);
}

}  // namespace jsa
