// VALUES of the cycle terms' distance (Eq. 9, losses/cycle.h): 0 for an exact
// round trip, the closed form for a known offset. The two cycle terms of the
// objective themselves are checked on an exact inverse pair (phi, psi) in
// model_objective_test.cpp.
#include <catch2/catch.hpp>

#include "engine/rng.h"
#include "engine/tape.h"
#include "losses/cycle.h"

using namespace jsa;

TEST_CASE("mean_squared_distance: 0 for equal blocks, the closed form for an offset", "[cycle]") {
  Rng rng(2);
  const Index m = 40;
  for (int c : {2, 6}) {
    Block<double> a(m, c);
    for (Index i = 0; i < a.size(); ++i) a.data()[i] = rng.uniform(-1, 1);
    Tape<double> t;
    CHECK(t.scalar(mean_squared_distance(t, t.constant(a), t.constant(a))) == 0.0);
    // b_m = a_m + d_m with |d_m|^2 = (m + 1) / 10 along one axis: the mean of
    // (m + 1) / 10 over m = 0..M-1 is (M + 1) / 20.
    Block<double> b = a;
    for (Index i = 0; i < m; ++i) b(i, i % c) += std::sqrt(double(i + 1) / 10.0);
    CHECK(t.scalar(mean_squared_distance(t, t.constant(a), t.constant(b))) ==
          Approx(double(m + 1) / 20.0).epsilon(1e-13));
  }
}
