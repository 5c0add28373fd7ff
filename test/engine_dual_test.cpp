// Tests of engine/dual.h: each rule against a derivative known in closed form.
#include <catch2/catch.hpp>
#include <cmath>

#include "engine/dual.h"

namespace jsa {

using D = Dual<double, 2>;

TEST_CASE("dual arithmetic gives exact partial derivatives", "[dual]") {
  const D u = D::variable(1.5, 0), v = D::variable(-0.5, 1);
  // f = u v + u / v - (u - v):  f_u = v + 1/v - 1,  f_v = u - u/v^2 + 1
  const D f = u * v + u / v - (u - v);
  CHECK(f.a == Approx(1.5 * -0.5 + 1.5 / -0.5 - 2.0));
  CHECK(f.v[0] == Approx(-0.5 + 1 / -0.5 - 1));
  CHECK(f.v[1] == Approx(1.5 - 1.5 / 0.25 + 1));

  // g = sqrt(u^2 + v^2): g_u = u / g,  g_v = v / g
  const D g = sqrt(u * u + v * v);
  CHECK(g.a == Approx(std::sqrt(2.5)));
  CHECK(g.v[0] == Approx(1.5 / std::sqrt(2.5)));
  CHECK(g.v[1] == Approx(-0.5 / std::sqrt(2.5)));

  // h = exp(u v): h_u = v h,  h_v = u h
  const D h = exp(u * v);
  CHECK(h.v[0] == Approx(-0.5 * std::exp(-0.75)));
  CHECK(h.v[1] == Approx(1.5 * std::exp(-0.75)));

  // Constants carry no derivative; += accumulates.
  D c(2.0);
  CHECK(c.v[0] == 0);
  c += u;
  CHECK(c.a == 3.5);
  CHECK(c.v[0] == 1);
  CHECK(c.v[1] == 0);
}

TEST_CASE("dual relu passes or blocks the derivative", "[dual]") {
  const D p = D::variable(0.3, 0), n = D::variable(-0.3, 1);
  CHECK(relu(p).a == 0.3);
  CHECK(relu(p).v[0] == 1);
  CHECK(relu(n).a == 0);
  CHECK(relu(n).v[1] == 0);
}

TEST_CASE("dual softplus: value log(1 + e^(beta a)) / beta, derivative sigmoid(beta a)", "[dual]") {
  for (const double beta : {0.5, 2.0, 40.0}) {
    for (const double a : {-1.3, -0.02, 0.0, 0.4, 2.0}) {
      // f = softplus(u v) at (u, v) = (a, 1): f_u = sigmoid(beta a) v,  f_v = sigmoid(beta a) u
      const D u = D::variable(a, 0), v = D::variable(1.0, 1);
      const D f = softplus(u * v, beta);
      const double sigmoid = 1.0 / (1.0 + std::exp(-beta * a));
      CHECK(f.a == Approx(std::log1p(std::exp(beta * a)) / beta));
      CHECK(f.v[0] == Approx(sigmoid));
      CHECK(f.v[1] == Approx(sigmoid * a).margin(1e-15));
    }
  }
  // The stable form: e^(40 * 800) overflows a double, the rule does not.
  const D big = softplus(D::variable(800.0, 0), 40.0),
          small = softplus(D::variable(-800.0, 0), 40.0);
  CHECK(big.a == 800.0);
  CHECK(big.v[0] == 1.0);
  CHECK(small.a == 0.0);
  CHECK(small.v[0] == 0.0);
}

}  // namespace jsa
