// Tests of engine/parallel.h: parallel_rows covers [0, n) exactly once in
// equal ranges of at most grain rows, as many per thread, whatever n is.
#include <omp.h>

#include <algorithm>
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

TEST_CASE("parallel_rows hands out balanced ranges of at most grain rows", "[parallel]") {
  const Index grain = 64;
  for (Index n : {Index(65), Index(100), Index(1000), Index(4097)}) {
    std::vector<Index> sizes(size_t(n), 0);  // indexed by a range's first row
    parallel_rows(
        n, [&](Index r0, Index r1) { sizes[size_t(r0)] = r1 - r0; }, grain);
    Index lo = n, hi = 0, count = 0, covered = 0;
    for (Index s : sizes)
      if (s > 0) {
        lo = std::min(lo, s);
        hi = std::max(hi, s);
        ++count;
        covered += s;
      }
    INFO("n = " << n << ", " << count << " ranges of " << lo << ".." << hi << " rows");
    CHECK(covered == n);
    CHECK(hi <= grain);
    CHECK(hi - lo <= 1);                // equal to a row: no thread waits on a short chunk
    CHECK(count % max_threads() == 0);  // and every thread gets as many chunks
    CHECK(count <= (n + grain - 1) / grain + max_threads() - 1);
  }
}

TEST_CASE("parallel_rows balances two threads on a block just past the grain", "[parallel]") {
  // 5000 rows with the default grain: three chunks of 2048, 2048 and 904 rows
  // put 4096 rows on one of two threads; balanced, each thread gets 2500.
  const int before = omp_get_max_threads();
  omp_set_num_threads(2);
  REQUIRE(max_threads() == 2);
  std::vector<Index> rows_of(2, 0);  // each thread adds to its own entry
  parallel_rows(5000,
                [&](Index r0, Index r1) { rows_of[size_t(omp_get_thread_num())] += r1 - r0; });
  omp_set_num_threads(before);
  CHECK(rows_of[0] == 2500);
  CHECK(rows_of[1] == 2500);
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
