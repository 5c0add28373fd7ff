// Example: backpropagating through a Jacobian, the engine's central idea.
// A 2-8-8-3 softplus MLP f maps (u, v) to R^3. Stacked tangent rows give
// J = [df/du, df/dv] as ordinary tape values (engine/tangents.h), so a loss ON J
//   L = mean_i [ (E-1)^2 + 2 F^2 + (G-1)^2 ] + mean_i n_i.z,   E, F, G = entries of J^T J,
//   n = (J_u x J_v) / |J_u x J_v|    (the isometry of Eq. 10 and the normal of Eq. 2)
// has an exact gradient in the weights from one backward(). The oracle shares no
// code with the tape: L evaluated point by point with Dual<double, 2>
// (engine/dual.h), differentiated in every weight by central differences.
// The output bias b3 shifts phi but not J: its gradient is exactly zero.
// Engine only. Exits non-zero if any weight's gradient disagrees.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "engine/dual.h"
#include "engine/rng.h"
#include "engine/tangents.h"

using namespace jsa;
using D = Dual<double, 2>;
constexpr double kBeta = 4;  // softplus sharpness: curved enough that J varies with (u, v)

// The loss on the tape. x: N x 2 points; w = {W1, b1, W2, b2, W3, b3}.
Var loss_on_tape(Tape<double>& t, Var x, const std::vector<Var>& w) {
  const Index n = t.rows(x);
  Var h = stack_tangents(t, x);  // [x; e_u; e_v], 3N x 2
  for (int l = 0; l < 3; ++l) {
    h = linear(t, h, w[2 * l], w[2 * l + 1], /*bias_rows=*/n);  // bias on the value rows only
    if (l < 2) h = softplus_stacked(t, h, n, kBeta);            // tangents times sigmoid(beta z)
  }
  const Stacked j = unstack(t, h);  // f, J_u, J_v: N x 3 each
  const Var e = offset(t, row_dot(t, j.du, j.du), -1.0),
            g = offset(t, row_dot(t, j.dv, j.dv), -1.0);
  const Var f = row_dot(t, j.du, j.dv);
  const Var iso = mean(t, add(t, add(t, square(t, e), square(t, g)), scale(t, square(t, f), 2.0)));
  const Var n_z = slice_cols(t, row_normalize(t, cross3(t, j.du, j.dv)), 2, 1);
  return add(t, iso, mean(t, n_z));
}

// The same loss with duals, one point at a time: the independent forward.
double loss_with_duals(const Block<double>& x, const std::vector<Block<double>>& w) {
  double iso = 0, n_z = 0;
  for (Index i = 0; i < x.rows(); ++i) {
    std::vector<D> h = {D::variable(x(i, 0), 0), D::variable(x(i, 1), 1)};
    for (int l = 0; l < 3; ++l) {
      std::vector<D> out(size_t(w[2 * l].cols()));
      for (Index c = 0; c < w[2 * l].cols(); ++c) {
        D z(w[2 * l + 1](0, c));
        for (Index r = 0; r < w[2 * l].rows(); ++r) z += h[size_t(r)] * D(w[2 * l](r, c));
        out[size_t(c)] = l < 2 ? softplus(z, kBeta) : z;
      }
      h = out;
    }
    const Eigen::Vector3d ju(h[0].v[0], h[1].v[0], h[2].v[0]), jv(h[0].v[1], h[1].v[1], h[2].v[1]);
    const double e = ju.dot(ju) - 1, f = ju.dot(jv), g = jv.dot(jv) - 1;
    iso += e * e + 2 * f * f + g * g;
    const Eigen::Vector3d c = ju.cross(jv);
    n_z += c[2] / std::sqrt(c.squaredNorm() + 1e-12);  // row_normalize's guard, engine/ops.h
  }
  return (iso + n_z) / double(x.rows());
}

int main() {
  Rng rng(3);
  const int widths[] = {2, 8, 8, 3};
  std::vector<Block<double>> w;
  for (int l = 0; l < 3; ++l) {
    w.push_back(Block<double>(widths[l], widths[l + 1]));
    w.push_back(Block<double>(1, widths[l + 1]));
    for (Block<double>* b : {&w[w.size() - 2], &w.back()})
      for (Index k = 0; k < b->size(); ++k) b->data()[k] = rng.uniform(-1.0, 1.0);
  }
  Block<double> x(16, 2);
  for (Index k = 0; k < x.size(); ++k) x.data()[k] = rng.uniform(-1.0, 1.0);

  Tape<double> t;
  std::vector<Var> wv;
  for (const Block<double>& b : w) wv.push_back(t.variable(b));
  const Var l = loss_on_tape(t, t.constant(x), wv);
  t.backward(l);
  std::printf("L = %.6f (tape), %.6f (duals); %d tape nodes\n", t.scalar(l), loss_with_duals(x, w),
              t.size());

  // Central differences through the dual forward, every weight. Error budget:
  // truncation ~h^2 f''' ~ 1e-11, round-off ~1e-16 / h ~ 1e-10.
  const double h = 1e-6;
  double worst = 0;
  int checked = 0;
  for (size_t b = 0; b < w.size(); ++b)
    for (Index k = 0; k < w[b].size(); ++k, ++checked) {
      const double keep = w[b].data()[k];
      w[b].data()[k] = keep + h;
      const double up = loss_with_duals(x, w);
      w[b].data()[k] = keep - h;
      const double down = loss_with_duals(x, w);
      w[b].data()[k] = keep;
      const double fd = (up - down) / (2 * h), tape = t.grad(wv[b]).data()[k];
      worst = std::max(worst, std::abs(tape - fd) / (1e-6 + std::abs(fd)));
      if (k == 0)
        std::printf("  dL/d%s%d[0]: tape % .8f  central difference % .8f\n", b % 2 ? "b" : "W",
                    int(b / 2) + 1, tape, fd);
    }
  std::printf("%d weights, worst |tape - fd| / (1e-6 + |fd|) = %.2e\n", checked, worst);
  const bool ok = worst < 1e-5;
  std::printf("%s\n", ok ? "ok" : "FAILED");
  return ok ? 0 : 1;
}
