// L_EMD (losses/transport.h): its value is the optimum over every one-to-one
// matching (the brute-force oracle), every target gets a sample of its own
// where Chamfer would let samples share one, and its gradient passes the
// central finite-difference check (the matching is a constant of the step, so
// away from ties the loss is smooth in the samples).
#include <algorithm>
#include <catch2/catch.hpp>
#include <numeric>
#include <vector>

#include "engine/gradcheck.h"
#include "engine/tape.h"
#include "losses/transport.h"
#include "test/uniform_block.h"

using namespace jsa;
using test_support::uniform_block;

namespace {
// min over every permutation s of (1/n) sum_i |x_i - y_s(i)|^2.
double best_over_permutations(const Block<double>& x, const Block<double>& y) {
  std::vector<int> s(size_t(x.rows()));
  std::iota(s.begin(), s.end(), 0);
  double best = 1e300;
  do {
    double c = 0;
    for (Index i = 0; i < x.rows(); ++i) c += (x.row(i) - y.row(s[size_t(i)])).squaredNorm();
    best = std::min(best, c / double(x.rows()));
  } while (std::next_permutation(s.begin(), s.end()));
  return best;
}
}  // namespace

TEST_CASE("L_EMD is the least mean squared distance over every one-to-one matching",
          "[transport]") {
  for (uint64_t seed : {1, 2, 3}) {
    const Block<double> x = uniform_block(7, 3, seed), y = uniform_block(7, 3, seed + 10);
    Tape<double> t;
    const double value = t.scalar(transport_loss(t, t.constant(x), t.constant(y)));
    CHECK(value == Approx(best_over_permutations(x, y)).epsilon(1e-12));
  }
}

TEST_CASE("L_EMD gives every target a sample of its own", "[transport]") {
  // Four samples on one target of four: Chamfer's accuracy direction is 0, the
  // transport moves three of them, to the three targets nobody else takes.
  Block<double> y(4, 3);
  y << 0, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0, 3;
  const Block<double> x = Block<double>::Zero(4, 3);
  Tape<double> t;
  const Var vx = t.constant(x);
  const Var l = transport_loss(t, vx, t.constant(y));
  CHECK(t.scalar(l) == Approx((0.0 + 1.0 + 4.0 + 9.0) / 4.0).epsilon(1e-14));
}

TEST_CASE("L_EMD passes the finite-difference check in the samples", "[transport]") {
  // Generic points: the optimal matching is unique and stays so within the
  // finite-difference step.
  const Block<double> x = uniform_block(9, 3, 4), y = uniform_block(9, 3, 5);
  const GradCheckResult r = check_gradients(
      [&](Tape<double>& t, const std::vector<Var>& v) {
        return transport_loss(t, v[0], t.constant(y));
      },
      {x});
  INFO(r.report);
  CHECK(r.ok);
  CHECK(r.checked == 27);
}
