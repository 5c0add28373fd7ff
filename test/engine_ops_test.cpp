// Tests of engine/ops_*.cpp: every op's pull-back against central finite
// differences (engine/gradcheck.h, double precision), gradient accumulation when
// one block feeds several ops, and the forward values of a few ops by hand.
//
// Tolerances: check_gradients' defaults, rtol 1e-5 and atol 1e-8 per entry
// (|analytic - numeric| <= atol + rtol max(|analytic|, |numeric|)), relative
// step 1e-6. Central differences on these smooth, O(1) graphs are accurate to
// ~1e-9, so the margin is wide.
#include <catch2/catch.hpp>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <tuple>

#include "engine/gemm.h"
#include "engine/ops.h"
#include "engine/tangents.h"
#include "test/engine_gradcheck_cases.h"

namespace jsa::test {

std::vector<GradCase> op_cases() {
  // N x C = 5 x 4 unless stated. Inputs that reach relu / sqrt / a norm come from
  // signed_block (|x| >= 0.2) or are positive: no ReLU kink and no sqrt(0) lies
  // within a finite-difference step of them, on purpose.
  Rng rng(2024);
  const Index n = 5, c = 4;
  std::vector<GradCase> cases;
  auto add_case = [&](std::string op, GraphBuilder f, std::vector<Block<double>> inputs) {
    cases.push_back({std::move(op), std::move(f), std::move(inputs)});
  };
  using T = Tape<double>;
  using Vs = std::vector<Var>;

  // ---- linear ----
  add_case("linear (bias)", [](T& t, const Vs& x) { return linear(t, x[0], x[1], x[2]); },
           {signed_block(rng, n, 3), signed_block(rng, 3, c), signed_block(rng, 1, c)});
  add_case("linear (no bias)", [](T& t, const Vs& x) { return linear(t, x[0], x[1], Var{}); },
           {signed_block(rng, n, 3), signed_block(rng, 3, c)});
  // 3N rows, the bias on the first N (the stacked-tangent convention).
  add_case("linear (bias_rows = N of 3N)",
           [n](T& t, const Vs& x) { return linear(t, x[0], x[1], x[2], n); },
           {signed_block(rng, 3 * n, 3), signed_block(rng, 3, c), signed_block(rng, 1, c)});
  add_case("relu", [](T& t, const Vs& x) { return relu(t, x[0]); }, {signed_block(rng, n, c)});
  // Value rows away from 0 (the mask); the tangent rows may be anything.
  add_case("relu_masked", [n](T& t, const Vs& x) { return relu_masked(t, x[0], n); },
           {signed_block(rng, 3 * n, c)});
  // Smooth, so no kink to keep away from; beta = 3 puts the inputs in the curved
  // part, where the second derivative (the tangent rows' pull-back into z) matters.
  add_case("softplus_stacked", [n](T& t, const Vs& x) { return softplus_stacked(t, x[0], n, 3.0); },
           {signed_block(rng, 3 * n, c)});
  add_case("softplus_stacked (plain rows)",
           [n](T& t, const Vs& x) { return softplus_stacked(t, x[0], n, 0.5); },
           {signed_block(rng, n, c)});
  // The fused layer linear_softplus_stacked, checked in H (value and tangent
  // rows), W and b at once, with the tolerances above. Tiles of 3 and 2 points
  // over 7 and 5 points: several tiles, and a short last one. Inputs in
  // +-[0.2, 1) over 3 channels keep z = H W + b within a few units, where
  // beta = 3 leaves softplus curved (its second derivative, the tangent rows'
  // pull-back into z, matters) and s' = -expm1(-beta y_0) is far from 0 and 1.
  const Index p = 7;
  add_case(
      "linear_softplus_stacked (3 blocks, tiles of 3)",
      [p](T& t, const Vs& x) { return linear_softplus_stacked(t, x[0], x[1], x[2], p, 3.0, 3); },
      {signed_block(rng, 3 * p, 3), signed_block(rng, 3, c), signed_block(rng, 1, c)});
  add_case(
      "linear_softplus_stacked (plain rows, tiles of 2)",
      [n](T& t, const Vs& x) { return linear_softplus_stacked(t, x[0], x[1], x[2], n, 0.5, 2); },
      {signed_block(rng, n, 3), signed_block(rng, 3, c), signed_block(rng, 1, c)});
  add_case("linear_softplus_stacked (no bias, automatic tiles)",
           [p](T& t, const Vs& x) { return linear_softplus_stacked(t, x[0], x[1], Var{}, p, 3.0); },
           {signed_block(rng, 3 * p, 3), signed_block(rng, 3, c)});

  // ---- elementwise, all four broadcast shapes of b ----
  struct Shape {
    const char* name;
    Index rows, cols;
  };
  const Shape shapes[] = {{"same", n, c}, {"1xC", 1, c}, {"Nx1", n, 1}, {"1x1", 1, 1}};
  for (const Shape& s : shapes) {
    add_case(std::string("add ") + s.name, [](T& t, const Vs& x) { return add(t, x[0], x[1]); },
             {signed_block(rng, n, c), signed_block(rng, s.rows, s.cols)});
    add_case(std::string("sub ") + s.name, [](T& t, const Vs& x) { return sub(t, x[0], x[1]); },
             {signed_block(rng, n, c), signed_block(rng, s.rows, s.cols)});
    add_case(std::string("mul ") + s.name, [](T& t, const Vs& x) { return mul(t, x[0], x[1]); },
             {signed_block(rng, n, c), signed_block(rng, s.rows, s.cols)});
  }
  add_case("scale", [](T& t, const Vs& x) { return scale(t, x[0], -2.5); },
           {signed_block(rng, n, c)});
  add_case("offset", [](T& t, const Vs& x) { return offset(t, x[0], 0.7); },
           {signed_block(rng, n, c)});
  add_case("square", [](T& t, const Vs& x) { return square(t, x[0]); }, {signed_block(rng, n, c)});
  // x in [0.5, 2): far from sqrt's singular derivative at 0.
  add_case("sqrt", [](T& t, const Vs& x) { return sqrt(t, x[0]); },
           {uniform_block(rng, n, c, 0.5, 2.0)});
  add_case("exp", [](T& t, const Vs& x) { return exp(t, x[0]); }, {signed_block(rng, n, c)});
  // x in [0.2, 2): away from log's pole at 0.
  add_case("log", [](T& t, const Vs& x) { return log(t, x[0]); },
           {uniform_block(rng, n, c, 0.2, 2.0)});
  // x over several periods: both halves' derivatives change sign.
  add_case("sin_cos", [](T& t, const Vs& x) { return sin_cos(t, x[0]); },
           {uniform_block(rng, n, c, -7.0, 7.0)});

  // ---- rows and columns ----
  add_case("concat_cols", [](T& t, const Vs& x) { return concat_cols(t, x); },
           {signed_block(rng, n, 2), signed_block(rng, n, 3), signed_block(rng, n, 1)});
  add_case("slice_cols", [](T& t, const Vs& x) { return slice_cols(t, x[0], 1, 2); },
           {signed_block(rng, n, c)});
  add_case("concat_rows", [](T& t, const Vs& x) { return concat_rows(t, x); },
           {signed_block(rng, 2, c), signed_block(rng, 4, c), signed_block(rng, 1, c)});
  add_case("slice_rows", [](T& t, const Vs& x) { return slice_rows(t, x[0], 1, 3); },
           {signed_block(rng, n, c)});
  // Row 2 is gathered three times and row 3 never: the pull-back must add three
  // gradients into row 2 and leave row 3 at zero.
  add_case("gather_rows (repeats)",
           [](T& t, const Vs& x) {
             return gather_rows(t, x[0], {2, 0, 2, 4, 2, 1});
           },
           {signed_block(rng, n, c)});

  // ---- reductions and per-row geometry ----
  add_case("sum", [](T& t, const Vs& x) { return sum(t, x[0]); }, {signed_block(rng, n, c)});
  add_case("mean", [](T& t, const Vs& x) { return mean(t, x[0]); }, {signed_block(rng, n, c)});
  add_case("row_sum", [](T& t, const Vs& x) { return row_sum(t, x[0]); },
           {signed_block(rng, n, c)});
  add_case("row_dot", [](T& t, const Vs& x) { return row_dot(t, x[0], x[1]); },
           {signed_block(rng, n, c), signed_block(rng, n, c)});
  // Rows with every |x_ij| >= 0.2 have norm >= 0.4: far from the kink at 0.
  add_case("row_norm", [](T& t, const Vs& x) { return row_norm(t, x[0]); },
           {signed_block(rng, n, c)});
  add_case("row_normalize", [](T& t, const Vs& x) { return row_normalize(t, x[0]); },
           {signed_block(rng, n, 3)});
  add_case("cross3", [](T& t, const Vs& x) { return cross3(t, x[0], x[1]); },
           {signed_block(rng, n, 3), signed_block(rng, n, 3)});
  add_case("stack_tangents", [](T& t, const Vs& x) { return stack_tangents(t, x[0]); },
           {signed_block(rng, n, 3)});
  // Six centres over the points' square and sigma = 0.6: every weight between
  // about 1e-3 and 0.9, so each kernel and the normalisation matter; the
  // tangent rows are arbitrary directions, not only e_u and e_v.
  const Block<double> centres = uniform_block(rng, 6, 2, -1.0, 1.0);
  add_case("gaussian_weights_stacked (3 blocks)",
           [n, centres](T& t, const Vs& x) {
             return gaussian_weights_stacked(t, x[0], n, centres, 0.6);
           },
           {signed_block(rng, 3 * n, 2)});
  add_case("gaussian_weights_stacked (plain rows)",
           [centres](T& t, const Vs& x) {
             return gaussian_weights_stacked(t, x[0], Index(-1), centres, 0.6);
           },
           {signed_block(rng, n, 2)});
  return cases;
}

// One line: the op, its worst relative error, entries checked, pass/fail.
std::string table_line(const std::string& op, const GradCheckResult& r) {
  std::ostringstream s;
  s << "  " << std::left << std::setw(40) << op << std::right << std::setw(12) << std::scientific
    << std::setprecision(2) << r.worst_relative << std::setw(9) << r.checked << "   "
    << (r.ok ? "pass" : "FAIL");
  return s.str();
}

TEST_CASE("every op passes check_gradients", "[ops][gradcheck]") {
  for (const GradCase& g : op_cases()) {
    DYNAMIC_SECTION(g.op) {
      const GradCheckResult r = check_gradients(g.f, g.inputs, g.options);
      INFO(table_line(g.op, r));
      INFO(r.report);
      CHECK(r.checked > 0);
      CHECK(r.ok);
    }
  }
}

// The table the closing note quotes: every op, then the Jacobian losses.
TEST_CASE("gradient check table", "[ops][gradcheck][table]") {
  std::vector<GradCase> cases = op_cases();
  for (GradCase& g : jacobian_cases()) cases.push_back(std::move(g));
  std::ostringstream table;
  table << "\n  gradient check (double, central differences, rel. step 1e-6)\n"
        << "  op                                        worst rel.  entries   result\n";
  bool all_ok = true;
  for (const GradCase& g : cases) {
    const GradCheckResult r = check_gradients(g.f, g.inputs, g.options);
    table << table_line(g.op, r) << "\n";
    if (!r.ok) table << r.report;
    all_ok = all_ok && r.ok;
  }
  std::cout << table.str() << std::endl;
  INFO(table.str());
  CHECK(all_ok);
}

// ---- accumulation: a block used more than once gets the sum of all paths ----

TEST_CASE("a block used twice accumulates both gradients", "[ops][accumulation]") {
  Rng rng(5);
  const Block<double> x0 = signed_block(rng, 4, 3);

  SECTION("mul(x, x) + add(x, x): d/dx sum = 2x + 2, exactly") {
    Tape<double> t;
    Var x = t.variable(x0);
    Var loss = sum(t, add(t, mul(t, x, x), add(t, x, x)));
    t.backward(loss);
    const Block<double> expected = (2.0 * x0.array() + 2.0).matrix();
    CHECK((t.grad(x) - expected).cwiseAbs().maxCoeff() < 1e-15);
  }
  SECTION("the same, and row_dot(x, x), linear(x, W) twice, through check_gradients") {
    const Block<double> w0 = signed_block(rng, 3, 3);
    auto f = [](Tape<double>& t, const std::vector<Var>& v) {
      Var x = v[0], w = v[1];
      Var a = add(t, mul(t, x, x), add(t, x, x));
      Var b = mul(t, x, row_dot(t, x, x));  // N x 1 broadcast over columns
      Var c = linear(t, linear(t, x, w, Var{}), w, Var{});
      return add(t, add(t, a, b), c);
    };
    const GradCheckResult r = check_gradients(f, {x0, w0});
    INFO(r.report);
    CHECK(r.ok);
  }
  SECTION("a constant input gets no gradient and costs no pull-back") {
    Tape<double> t;
    Var x = t.variable(x0);
    Var k = t.constant(x0);
    Var y = mul(t, k, k);
    CHECK_FALSE(t.needs_grad(y));
    Var loss = sum(t, mul(t, x, y));
    t.backward(loss);
    CHECK((t.grad(x) - x0.cwiseProduct(x0)).cwiseAbs().maxCoeff() < 1e-15);
  }
}

// ---- forward values, by hand ----

TEST_CASE("forward values of a few ops", "[ops][forward]") {
  Tape<double> t;
  Block<double> a(2, 3), w(3, 2), b(1, 2);
  a << 1, -2, 3,  //
      -1, 0.5, 2;
  w << 1, 0,  //
      0, 1,   //
      1, 1;
  b << 10, 20;
  Var va = t.constant(a), vw = t.constant(w), vb = t.constant(b);

  Block<double> y = t.value(linear(t, va, vw, vb));
  Block<double> expect(2, 2);
  expect << 14, 21,  //
      11, 22.5;
  CHECK(y.isApprox(expect));
  // bias on the first row only
  Block<double> y1 = t.value(linear(t, va, vw, vb, 1));
  expect.row(1) << 1, 2.5;
  CHECK(y1.isApprox(expect));

  // relu_masked: mask from row block 0 applies to block 1.
  Block<double> s(4, 2);
  s << 1, -1,  //
      -2, 3,   //
      5, 6,    //
      7, 8;
  Block<double> m = t.value(relu_masked(t, t.constant(s), 2));
  Block<double> mexp(4, 2);
  mexp << 1, 0,  //
      0, 3,      //
      5, 0,      //
      0, 8;
  CHECK(m == mexp);

  Block<double> p(1, 3), q(1, 3);
  p << 1, 0, 0;
  q << 0, 1, 0;
  Block<double> z = t.value(cross3(t, t.constant(p), t.constant(q)));
  CHECK(z(0, 0) == 0);
  CHECK(z(0, 1) == 0);
  CHECK(z(0, 2) == 1);

  Block<double> r(1, 2);
  r << 3, 4;
  CHECK(t.value(row_norm(t, t.constant(r), 0.0))(0, 0) == Approx(5.0));
  Block<double> rn = t.value(row_normalize(t, t.constant(r), 0.0));
  CHECK(rn(0, 0) == Approx(0.6));
  CHECK(rn(0, 1) == Approx(0.8));
  CHECK(t.value(mean(t, t.constant(a)))(0, 0) == Approx(3.5 / 6));

  // Gather with repeats and broadcasting shapes.
  Block<double> g = t.value(gather_rows(t, t.constant(a), {1, 1, 0}));
  CHECK(g.row(0) == a.row(1));
  CHECK(g.row(1) == a.row(1));
  CHECK(g.row(2) == a.row(0));
  Block<double> col(2, 1);
  col << 2, -1;
  Block<double> mc = t.value(mul(t, va, t.constant(col)));
  CHECK(mc.row(0) == 2 * a.row(0));
  CHECK(mc.row(1) == -a.row(1));
}

TEST_CASE("shape errors are programmer errors", "[ops][errors]") {
  Tape<double> t;
  Var a = t.constant(Block<double>::Ones(3, 4));
  CHECK_THROWS_AS(add(t, a, t.constant(Block<double>::Ones(2, 4))), InternalError);
  CHECK_THROWS_AS(linear(t, a, t.constant(Block<double>::Ones(3, 2)), Var{}), InternalError);
  CHECK_THROWS_AS(
      linear(t, a, t.constant(Block<double>::Ones(4, 2)), t.constant(Block<double>::Ones(1, 2)), 5),
      InternalError);  // bias on more rows than there are
  CHECK_THROWS_AS(relu_masked(t, a, 2), InternalError);
  CHECK_THROWS_AS(slice_cols(t, a, 2, 3), InternalError);
  CHECK_THROWS_AS(gather_rows(t, a, {0, 3}), InternalError);
  CHECK_THROWS_AS(cross3(t, a, a), InternalError);
}

}  // namespace jsa::test

namespace jsa::test {

// The gradient checks above use blocks far below parallel_rows' grain (2048
// rows), so they run serially. Here blocks are tall enough to be split across
// threads; each result must equal a plain loop exactly (disjoint rows, same
// arithmetic, so not even round-off differs).
TEST_CASE("tall blocks (parallel path) equal a plain loop", "[ops][parallel]") {
  const Index m = 5000, c = 7;  // 3 stacked blocks of 5000 rows
  Rng rng(17);
  const Block<double> x0 = signed_block(rng, 3 * m, c), w0 = signed_block(rng, c, c),
                      b0 = signed_block(rng, 1, c), dy0 = signed_block(rng, 3 * m, c);

  SECTION("relu_masked") {
    Tape<double> t;
    Var x = t.variable(x0);
    Var y = relu_masked(t, x, m);
    t.backward(sum(t, mul(t, y, t.constant(dy0))));
    Block<double> y_ref(3 * m, c), dx_ref(3 * m, c);
    for (Index k = 0; k < 3; ++k)
      for (Index i = 0; i < m; ++i)
        for (Index j = 0; j < c; ++j) {
          const bool on = x0(i, j) > 0;
          y_ref(k * m + i, j) = on ? x0(k * m + i, j) : 0.0;
          dx_ref(k * m + i, j) = on ? dy0(k * m + i, j) : 0.0;
        }
    CHECK(t.value(y) == y_ref);
    CHECK(t.grad(x) == dx_ref);
  }
  SECTION("linear with the bias on the first N rows") {
    Tape<double> t;
    Var x = t.variable(x0), w = t.variable(w0), b = t.variable(b0);
    Var y = linear(t, x, w, b, m);
    t.backward(sum(t, mul(t, y, t.constant(dy0))));
    Block<double> y_ref = x0 * w0;
    RowVector<double> db_ref = RowVector<double>::Zero(c);
    for (Index i = 0; i < m; ++i) {
      y_ref.row(i) += b0.row(0);
      db_ref += dy0.row(i);
    }
    CHECK((t.value(y) - y_ref).cwiseAbs().maxCoeff() < 1e-13);
    CHECK((t.grad(b) - db_ref).cwiseAbs().maxCoeff() < 1e-10);
    CHECK((t.grad(w) - x0.transpose() * dy0).cwiseAbs().maxCoeff() < 1e-10);
    CHECK((t.grad(x) - dy0 * w0.transpose()).cwiseAbs().maxCoeff() < 1e-13);
  }
}

// float and double instantiations compute the same thing (to float precision).
// With the BLAS backend selected the float linear ops go through it (double
// stays on Eigen), so this is also the gradient check of the BLAS's pull-backs:
// against the double ones check_gradients verifies.
void float_and_double_agree() {
  Rng rng(23);
  const Block<double> x0 = signed_block(rng, 9, 3), w0 = signed_block(rng, 3, 3),
                      b0 = signed_block(rng, 1, 3);
  auto run = [&](auto scalar) {
    using S = decltype(scalar);
    Tape<S> t;
    Var x = t.variable(x0.cast<S>());
    Var h = relu_masked(
        t, linear(t, stack_tangents(t, x), t.constant(w0.cast<S>()), t.constant(b0.cast<S>()), 9),
        9);
    Var loss = mean(t, row_norm(t, cross3(t, slice_rows(t, h, 9, 9), slice_rows(t, h, 18, 9))));
    loss =
        add(t, loss, mean(t, exp(t, scale(t, row_normalize(t, slice_rows(t, h, 0, 9)), S(0.5)))));
    t.backward(loss);
    return std::make_pair(double(t.scalar(loss)), Block<double>(t.grad(x).template cast<double>()));
  };
  const auto [lf, gf] = run(0.0f);
  const auto [ld, gd] = run(0.0);
  CHECK(lf == Approx(ld).epsilon(1e-5));
  CHECK((gf - gd).cwiseAbs().maxCoeff() < 1e-5 * std::max(1.0, gd.cwiseAbs().maxCoeff()));
}

TEST_CASE("float ops agree with double ops", "[ops][float]") { float_and_double_agree(); }

// The engine's checks with the GEMMs on the BLAS (engine/gemm.h), when the
// build has one: the gradient checks (double, so still Eigen's products: the
// other ops must not care which backend is selected) and the float-double
// agreement, whose float side now runs on the BLAS.
TEST_CASE("with the BLAS backend selected the gradient checks and float ops still pass",
          "[ops][gradcheck][gemm]") {
  if (!blas_built_in()) {
    CHECK_THROWS_AS(set_gemm(Gemm::blas), InputError);
    return;
  }
  set_gemm(Gemm::blas);
  for (const GradCase& g : op_cases()) {
    const GradCheckResult r = check_gradients(g.f, g.inputs, g.options);
    INFO(table_line(g.op, r) << "\n" << r.report);
    CHECK(r.ok);
  }
  for (const GradCase& g : jacobian_cases()) {
    const GradCheckResult r = check_gradients(g.f, g.inputs, g.options);
    INFO(table_line(g.op, r) << "\n" << r.report);
    CHECK(r.ok);
  }
  float_and_double_agree();
  set_gemm(Gemm::eigen);
}

}  // namespace jsa::test

namespace jsa::test {

// Same inputs and thread count -> the same bits (STYLE: no float atomics, no
// order-dependent reductions), on blocks tall enough to run threaded.
TEST_CASE("the same graph twice gives bitwise-identical gradients", "[ops][determinism]") {
  Rng rng(31);
  const Index n = 4000;
  const Block<float> x0 = signed_block(rng, n, 2).cast<float>(),
                     w1 = signed_block(rng, 2, 64).cast<float>(),
                     b1 = signed_block(rng, 1, 64).cast<float>(),
                     w2 = signed_block(rng, 64, 3).cast<float>();
  auto run = [&] {
    Tape<float> t;
    Var w = t.variable(w1), b = t.variable(b1), v = t.variable(w2);
    Var h = relu_masked(t, linear(t, stack_tangents(t, t.constant(x0)), w, b, n), n);
    const Stacked s = unstack(t, linear(t, h, v, Var{}, n));
    Var loss = add(t, mean(t, row_norm(t, cross3(t, s.du, s.dv))), mean(t, square(t, s.value)));
    t.backward(loss);
    return std::make_tuple(Block<float>(t.grad(w)), Block<float>(t.grad(b)),
                           Block<float>(t.grad(v)));
  };
  const auto first = run(), second = run();
  CHECK(std::get<0>(first) == std::get<0>(second));
  CHECK(std::get<1>(first) == std::get<1>(second));
  CHECK(std::get<2>(first) == std::get<2>(second));
}

}  // namespace jsa::test

namespace jsa::test {

// linear_softplus_stacked is linear followed by softplus_stacked, computed in
// another order: Z in row tiles (each tile's GEMM on its own rows), s' from
// the output in the pull-back (-expm1(-beta y_0), not from z), dW summed per
// thread. In float on a block tall enough for several tiles and both threads
// (1000 points: 4 tiles at width 64; 3 blocks), the value and every gradient
// must agree with the two ops to 1e-5 of the largest entry (float rounding
// over sums of 64 and 3000 terms; measured about 1e-7), and twice the same
// graph must give the same bits.
TEST_CASE("linear_softplus_stacked equals linear then softplus_stacked", "[ops][float]") {
  Rng rng(41);
  const Index m = 1000, cin = 48, c = 64;
  const float beta = 40.0f;  // the default fit's sharpness: many s' near 0 and 1
  const Block<float> h0 = signed_block(rng, 3 * m, cin, 0.0, 0.3).cast<float>(),
                     w0 = signed_block(rng, cin, c, 0.0, 0.3).cast<float>(),
                     b0 = signed_block(rng, 1, c, 0.0, 0.3).cast<float>(),
                     r0 = signed_block(rng, 3 * m, c).cast<float>();
  auto run = [&](bool fused) {
    Tape<float> t;
    Var h = t.variable(h0), w = t.variable(w0), b = t.variable(b0);
    Var y = fused ? linear_softplus_stacked(t, h, w, b, m, beta)
                  : softplus_stacked(t, linear(t, h, w, b, m), m, beta);
    t.backward(sum(t, mul(t, y, t.constant(r0))));
    return std::vector<Block<float>>{t.value(y), t.grad(h), t.grad(w), t.grad(b)};
  };
  const auto fused = run(true), twice = run(true), separate = run(false);
  const char* names[] = {"Y", "dH", "dW", "db"};
  for (size_t k = 0; k < fused.size(); ++k) {
    INFO(names[k]);
    const float scale = separate[k].cwiseAbs().maxCoeff();
    CHECK(scale > 0);
    CHECK((fused[k] - separate[k]).cwiseAbs().maxCoeff() <= 1e-5f * scale);
    CHECK(fused[k] == twice[k]);
  }
}

}  // namespace jsa::test
