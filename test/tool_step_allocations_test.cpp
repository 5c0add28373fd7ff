// A training step's heap allocations once it has warmed up: none. Everything
// a step uses (the tape's closures and gradient blocks, the GEMMs' packing
// buffers, the searches' scratch, the losses' grids) is kept from the step
// before; any of it coming back makes these counts grow. The searches among
// the step's own points are scans at these sizes (io/geometry/nearest.h); a
// kd-tree, built above 2^24 pairs, would add nanoflann's node blocks, which
// its pool frees and takes again at every build. Counted by
// test/allocation_counter.h.
#include <catch2/catch.hpp>
#include <vector>

#include "engine/parallel.h"
#include "model/tool/trainer.h"
#include "test/allocation_counter.h"
#include "test/sphere_pool.h"

using namespace jsa;
using test_support::sphere_pool;

namespace {

// The full method at small sizes (dense L_6D, L_2D, the cycles, L_iso, L_rep),
// in the ramp's first level (M = 64). Not L_even: the lists of its mixture's
// kept terms are as long as the data makes them, and grow (doubling, kept) in
// whichever early step first needs more; counted by bench_step_allocations.
FitOptions small_options() {
  FitOptions o;
  o.atlas.gaussians = 256;
  o.atlas.width = 32;
  o.atlas.hidden_layers = 3;
  o.points = 256;
  o.iterations = 400;
  o.evenness_from = 1;
  return o;
}

// Allocations of each of `count` steps after `warmup` steps.
std::vector<long> step_allocations(Trainer& t, int warmup, int count) {
  for (int i = 0; i < warmup; ++i) t.step();
  std::vector<long> counts;
  for (int i = 0; i < count; ++i) {
    allocation_counter::start();
    t.step();
    counts.push_back(allocation_counter::stop());
  }
  return counts;
}

}  // namespace

TEST_CASE("trainer: steps 3 to 10 of a fit allocate nothing", "[trainer]") {
  if (!allocation_counter::counting_available()) {
    WARN("no allocation counting under a sanitizer");
    return;
  }
  for (const int threads : {1, 2}) {
    struct Threads {  // restored however the test ends
      int before = max_threads();
      explicit Threads(int n) { set_threads(n); }
      ~Threads() { set_threads(before); }
    } scope(threads);
    Trainer t(small_options(), sphere_pool(4000, 1));
    for (long n : step_allocations(t, 3, 8)) {
      INFO(threads << " threads");
      CHECK(n == 0);
    }
  }
}

TEST_CASE("trainer: ... with L_EMD's assignment in the step", "[trainer]") {
  if (!allocation_counter::counting_available()) {
    WARN("no allocation counting under a sanitizer");
    return;
  }
  FitOptions o = small_options();
  o.weights.transport = 0.1;  // from the first step, on 64 of the ramp's points
  o.transport_from = 0;
  o.transport_points = 64;
  Trainer t(o, sphere_pool(4000, 1));
  for (long n : step_allocations(t, 3, 8)) CHECK(n == 0);
}

TEST_CASE("trainer: ... and a collection's step, its shapes split over threads", "[trainer]") {
  if (!allocation_counter::counting_available()) {
    WARN("no allocation counting under a sanitizer");
    return;
  }
  struct Threads {
    int before = max_threads();
    Threads() { set_threads(2); }
    ~Threads() { set_threads(before); }
  } threads;
  FitOptions o = small_options();
  o.atlas.deform_layers = 2;  // phi_i(x) = phi(x) + D(phi(x), f_i), as collections fit
  Trainer t(o, std::vector<Block<double>>{sphere_pool(4000, 1), sphere_pool(4000, 2)});
  for (long n : step_allocations(t, 3, 8)) {
    CHECK(t.shape_threads() == 2);
    CHECK(n == 0);
  }
}
