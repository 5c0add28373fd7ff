// Tests of engine/gradcheck.h: the checker must pass a correct pull-back and
// catch a wrong one (a checker that always passes would make every other
// gradient test meaningless).
#include <catch2/catch.hpp>

#include "engine/gradcheck.h"
#include "engine/ops.h"

namespace jsa {
namespace {

// y = x^3 as a custom op whose pull-back multiplies by `factor` * 3 x^2:
// factor = 1 is the true derivative.
Var cube(Tape<double>& t, Var x, double factor) {
  Var y = t.node(t.rows(x), t.cols(x), {x});
  t.value(y) = t.value(x).array().cube();
  t.on_backward(y, [x, factor](Tape<double>& t, Var y) {
    t.grad(x).array() += factor * 3 * t.value(x).array().square() * t.grad(y).array();
  });
  return y;
}

Block<double> input() {
  Block<double> x(3, 2);
  x << 0.5, -1.2, 2.0, 0.3, -0.7, 1.1;
  return x;
}

}  // namespace

TEST_CASE("check_gradients passes a correct pull-back", "[gradcheck]") {
  const auto r = check_gradients(
      [](Tape<double>& t, const std::vector<Var>& v) { return cube(t, v[0], 1.0); }, {input()});
  INFO(r.report);
  CHECK(r.ok);
  CHECK(r.checked == 6);
  CHECK(r.worst_relative < 1e-8);
  CHECK(r.worst_ratio <= 1.0);
}

TEST_CASE("check_gradients catches a pull-back off by 1e-3", "[gradcheck]") {
  const auto r = check_gradients(
      [](Tape<double>& t, const std::vector<Var>& v) { return cube(t, v[0], 1.001); }, {input()});
  CHECK_FALSE(r.ok);
  CHECK(r.worst_relative == Approx(1e-3).epsilon(0.01));
  CHECK(r.report.find("worst relative error") != std::string::npos);
}

TEST_CASE("check_gradients catches a missing path (one input ignored)", "[gradcheck]") {
  // y = a * b, but the pull-back forgets b.
  auto f = [](Tape<double>& t, const std::vector<Var>& v) {
    Var a = v[0], b = v[1];
    Var y = t.node(t.rows(a), t.cols(a), {a, b});
    t.value(y) = t.value(a).cwiseProduct(t.value(b));
    t.on_backward(
        y, [a, b](Tape<double>& t, Var y) { t.grad(a) += t.grad(y).cwiseProduct(t.value(b)); });
    return y;
  };
  const auto r = check_gradients(f, {input(), input()});
  CHECK_FALSE(r.ok);
}

TEST_CASE("check_gradients reads every output entry (not just their sum)", "[gradcheck]") {
  // y = [x0 - x1, x1 - x0]: sum(y) does not depend on x, but sum(R y) does.
  // A pull-back that drops the gradient entirely must fail.
  auto f = [](Tape<double>& t, const std::vector<Var>& v) {
    Var x = v[0];
    Var y = t.node(1, 2, {x});
    t.value(y) << t.value(x)(0, 0) - t.value(x)(0, 1), t.value(x)(0, 1) - t.value(x)(0, 0);
    t.on_backward(y, [](Tape<double>&, Var) {});
    return y;
  };
  Block<double> x(1, 2);
  x << 0.3, 0.8;
  CHECK_FALSE(check_gradients(f, {x}).ok);
}

}  // namespace jsa
