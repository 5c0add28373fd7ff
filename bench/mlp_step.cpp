// One training step of the paper's parametrization phi (2-256-256-256-256-256-3,
// ReLU; Sec. 3) with stacked Jacobians on 3N rows, timed against plain Eigen
// SGEMMs of the same shapes in the same run. Validates before it times: the
// engine's value rows must equal a plain Eigen forward pass.
//
//   bench_mlp_step [--threads N] [--points N] [--runs N] [--width W] [--softplus BETA]
//
// --softplus BETA: softplus layers instead, each timed two ways in alternation
// with the SGEMMs, linear then softplus_stacked (two ops) and
// linear_softplus_stacked (one op, in row tiles); validated against each other.
//
// FLOPs counted (R = 3N rows, per layer in -> out):
//   forward   2 R in out
//   backward  2 R in out for dW, and 2 R in out for dX except on the first layer
// Elementwise work (bias, ReLU, the loss) is not counted: it is overhead.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <string>
#include <utility>
#include <vector>

#include "bench/timing.h"
#include "engine/ops.h"
#include "engine/parallel.h"
#include "engine/parameters.h"
#include "engine/rng.h"
#include "engine/tangents.h"

namespace {

using bench::Clock;
using jsa::Block;
using jsa::Index;
using jsa::Var;

std::vector<int> kWidths = {2, 256, 256, 256, 256, 256, 3};  // --width sets the hidden ones

using bench::median;
using bench::seconds_since;

struct Options {
  int threads = 0;  // 0: OpenMP's default
  Index points = 10000;
  int runs = 7;
  int width = 256;
  double softplus = 0;  // 0: ReLU
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> long {
      if (i + 1 >= argc) throw std::runtime_error(a + " needs a value");
      char* end = nullptr;
      const long v = std::strtol(argv[++i], &end, 10);
      if (*end != '\0' || v < 1)
        throw std::runtime_error(a + ": expected a positive integer, got '" + argv[i] + "'");
      return v;
    };
    if (a == "--threads")
      o.threads = int(next());
    else if (a == "--points")
      o.points = Index(next());
    else if (a == "--runs")
      o.runs = int(next());
    else if (a == "--width")
      o.width = int(next());
    else if (a == "--softplus" && i + 1 < argc)
      o.softplus = std::atof(argv[++i]);
    else
      throw std::runtime_error(
          "unknown flag '" + a +
          "' (flags: --threads N --points N --runs N --width W --softplus BETA)");
  }
  return o;
}

// The network's parameters, uniform fan-in initialization.
struct Phi {
  jsa::Parameters<float> p;
  std::vector<int> w, b;
  explicit Phi(uint64_t seed) {
    jsa::Rng rng(seed);
    for (size_t l = 0; l + 1 < kWidths.size(); ++l) {
      w.push_back(p.add("w" + std::to_string(l), kWidths[l], kWidths[l + 1]));
      b.push_back(p.add("b" + std::to_string(l), 1, kWidths[l + 1]));
      const double s = std::sqrt(6.0 / kWidths[l]);
      auto W = p.value(w.back());
      for (Index k = 0; k < W.size(); ++k) W.data()[k] = float(rng.uniform(-s, s));
      auto B = p.value(b.back());
      for (Index k = 0; k < B.size(); ++k) B.data()[k] = float(rng.uniform(-0.1, 0.1));
    }
  }
  int layers() const { return int(w.size()); }
};

// Seconds spent in each phase of one step (summed over layers).
struct Phases {
  double linear = 0, relu = 0, loss = 0, backward = 0;
  double forward() const { return linear + relu + loss; }
  double total() const { return forward() + backward; }
};

// A hidden layer's activation, and how the layer is made.
struct Activation {
  float softplus = 0;  // 0: linear then relu_masked
  bool fused = false;  // softplus: linear_softplus_stacked (else linear then softplus_stacked)
};

// Forward with stacked Jacobians, a loss on the value and Jacobian rows, backward.
// Loss: mean |phi(x) - target|^2 + 1e-3 mean((E-1)^2 + (G-1)^2 + 2F^2).
// A fused layer's time counts as linear.
float engine_step(jsa::Tape<float>& t, Phi& phi, const Block<float>& x, const Block<float>& target,
                  Phases* ph, Activation act = {}) {
  const Index n = x.rows();
  auto t0 = Clock::now();
  auto lap = [&t0](double& into) {
    const auto now = Clock::now();
    into += std::chrono::duration<double>(now - t0).count();
    t0 = now;
  };
  Phases local;
  t.clear();
  Var h = jsa::stack_tangents(t, t.constant(x));
  for (int l = 0; l < phi.layers(); ++l) {
    const bool hidden = l + 1 < phi.layers();
    if (hidden && act.fused) {
      h = jsa::linear_softplus_stacked(t, h, phi.p.on(t, phi.w[l]), phi.p.on(t, phi.b[l]), n,
                                       act.softplus);
      lap(local.linear);
      continue;
    }
    h = jsa::linear(t, h, phi.p.on(t, phi.w[l]), phi.p.on(t, phi.b[l]), n);
    lap(local.linear);
    if (hidden)
      h = act.softplus > 0 ? jsa::softplus_stacked(t, h, n, act.softplus)
                           : jsa::relu_masked(t, h, n);
    lap(local.relu);
  }
  const jsa::Stacked s = jsa::unstack(t, h);
  Var fit = jsa::mean(t, jsa::square(t, jsa::sub(t, s.value, t.constant(target))));
  Var e = jsa::row_dot(t, s.du, s.du), f = jsa::row_dot(t, s.du, s.dv),
      g = jsa::row_dot(t, s.dv, s.dv);
  Var iso = jsa::add(t,
                     jsa::add(t, jsa::square(t, jsa::offset(t, e, -1.0f)),
                              jsa::square(t, jsa::offset(t, g, -1.0f))),
                     jsa::scale(t, jsa::square(t, f), 2.0f));
  Var loss = jsa::add(t, fit, jsa::scale(t, jsa::mean(t, iso), 1e-3f));
  lap(local.loss);
  phi.p.zero_grad();
  t.backward(loss);
  lap(local.backward);
  if (ph) *ph = local;
  return t.scalar(loss);
}

// The same GEMMs with plain Eigen: forward X_l W_l for every layer, then in
// reverse dW_l = X_l^T dY_l and (l > 0) dX_l = dY_l W_l^T. No bias, no ReLU.
struct GemmOnly {
  std::vector<Block<float>> x, dy, dw;  // x[l]: layer l's input; dy[l]: grad of its output
  GemmOnly(const Block<float>& input, const Phi& phi) {
    const Index r = input.rows();
    x.push_back(input);
    for (int l = 0; l < phi.layers(); ++l) {
      x.emplace_back(r, kWidths[l + 1]);
      dy.push_back(Block<float>::Constant(r, kWidths[l + 1], 1e-3f));
      dw.emplace_back(kWidths[l], kWidths[l + 1]);
    }
  }
  // Returns {forward seconds, backward seconds}.
  std::pair<double, double> step(const Phi& phi) {
    const int layers = phi.layers();
    const auto t0 = Clock::now();
    for (int l = 0; l < layers; ++l) x[l + 1].noalias() = x[l] * phi.p.value(phi.w[l]);
    const double f = seconds_since(t0);
    const auto t1 = Clock::now();
    for (int l = layers - 1; l >= 0; --l) {
      dw[l].noalias() = x[l].transpose() * dy[l];
      if (l > 0) dy[l - 1].noalias() = dy[l] * phi.p.value(phi.w[l]).transpose();
    }
    return {f, seconds_since(t1)};
  }
};

// Plain forward (value rows only) for the validation.
Block<float> plain_forward(const Phi& phi, const Block<float>& x) {
  Block<float> h = x;
  for (int l = 0; l < phi.layers(); ++l) {
    Block<float> z = h * phi.p.value(phi.w[l]);
    z.rowwise() += phi.p.value(phi.b[l]).row(0);
    h = l + 1 < phi.layers() ? Block<float>(z.cwiseMax(0.0f)) : z;
  }
  return h;
}

// n domain points x in [-1, 1]^2 and a smooth surface's points over them.
void draw_inputs(Index n, Block<float>& x, Block<float>& target) {
  jsa::Rng rng(1);
  x.resize(n, 2);
  target.resize(n, 3);
  for (Index i = 0; i < n; ++i) {
    const double u = rng.uniform(-1, 1), v = rng.uniform(-1, 1);
    x.row(i) << float(u), float(v);
    target.row(i) << float(u), float(v), float(0.5 * std::sin(3 * u) * std::cos(2 * v));
  }
}

// The stacked rows [x; e_u; e_v] (3n x 2) phi's first layer reads.
Block<float> stacked_input(const Block<float>& x) {
  const Index n = x.rows();
  Block<float> stacked = Block<float>::Zero(3 * n, 2);
  stacked.topRows(n) = x;
  stacked.middleRows(n, n).col(0).setOnes();
  stacked.bottomRows(n).col(1).setOnes();
  return stacked;
}

// --softplus: the two-op layers and the fused one against the same SGEMMs,
// the three timed in alternation (a round each, so load falls on all alike).
int run_softplus(const Options& o) {
  const Index n = o.points, rows = 3 * n;
  Block<float> x, target;
  draw_inputs(n, x, target);
  Phi phi(2);
  double flops = 0;
  for (size_t l = 0; l + 1 < kWidths.size(); ++l)
    flops += (l == 0 ? 2.0 : 3.0) * 2.0 * double(rows) * kWidths[l] * kWidths[l + 1];
  const Activation two{float(o.softplus), false}, one{float(o.softplus), true};

  // Validate: the same loss and parameter gradient both ways (float rounding).
  jsa::Tape<float> t2, t1;
  const float l2 = engine_step(t2, phi, x, target, nullptr, two);
  const std::vector<float> g2 = phi.p.grads();
  const float l1 = engine_step(t1, phi, x, target, nullptr, one);
  const std::vector<float> g1 = phi.p.grads();
  double gerr = 0, gmax = 0;
  for (size_t k = 0; k < g1.size(); ++k) {
    gerr = std::max(gerr, double(std::abs(g1[k] - g2[k])));
    gmax = std::max(gmax, double(std::abs(g2[k])));
  }
  std::printf("validate: loss %.7g (two ops) vs %.7g (fused), max |grad diff| %.2e of %.2e\n",
              double(l2), double(l1), gerr, gmax);
  if (!(std::abs(l1 - l2) <= 1e-5f * std::abs(l2)) || !(gerr <= 1e-4 * gmax)) {
    std::fprintf(stderr, "validation failed\n");
    return 1;
  }

  const Block<float> stacked = stacked_input(x);
  GemmOnly gemm(stacked, phi);
  std::vector<double> t_two, t_one, t_gemm;
  for (int i = 0; i < o.runs + 2; ++i) {
    Phases a, b;
    engine_step(t2, phi, x, target, &a, two);
    engine_step(t1, phi, x, target, &b, one);
    const auto g = gemm.step(phi);
    if (i < 2) continue;
    t_two.push_back(a.total());
    t_one.push_back(b.total());
    t_gemm.push_back(g.first + g.second);
  }
  const double m2 = median(t_two), m1 = median(t_one), mg = median(t_gemm);
  std::printf(
      "\nphi 2-%dx%d-3 softplus beta %g, N = %ld points (%ld stacked rows), threads = %d, "
      "median of %d alternated runs\n",
      o.width, int(kWidths.size()) - 2, o.softplus, long(n), long(rows), jsa::max_threads(),
      o.runs);
  std::printf("%-44s %10s %10s %10s\n", "", "median ms", "GFLOP/s", "/ SGEMM");
  auto line = [&](const char* name, double m) {
    std::printf("%-44s %10.1f %10.1f %10.3f\n", name, m * 1e3, flops / m * 1e-9, m / mg);
  };
  line("engine step, linear + softplus_stacked", m2);
  line("engine step, linear_softplus_stacked", m1);
  line("Eigen SGEMM of the same shapes", mg);
  std::printf("two ops / fused: %.3f\n", m2 / m1);
  std::printf("tape memory: two ops %.1f MB, fused %.1f MB\n", double(t2.bytes()) / (1 << 20),
              double(t1.bytes()) / (1 << 20));
  return 0;
}

int run(const Options& o) {
  jsa::set_threads(o.threads);
  for (size_t l = 1; l + 1 < kWidths.size(); ++l) kWidths[l] = o.width;
  if (o.softplus > 0) return run_softplus(o);
  const Index n = o.points, rows = 3 * n;
  Block<float> x, target;
  draw_inputs(n, x, target);
  Phi phi(2);

  // FLOPs of one step.
  double fwd = 0, bwd = 0;
  for (size_t l = 0; l + 1 < kWidths.size(); ++l) {
    const double layer = 2.0 * double(rows) * kWidths[l] * kWidths[l + 1];
    fwd += layer;
    bwd += l == 0 ? layer : 2 * layer;
  }
  const double flops = fwd + bwd;

  // Validate: the engine's value rows equal the plain forward pass.
  jsa::Tape<float> tape;
  const float loss = engine_step(tape, phi, x, target, nullptr);
  {
    jsa::Tape<float> t;
    Var h = jsa::stack_tangents(t, t.constant(x));
    for (int l = 0; l < phi.layers(); ++l) {
      h = jsa::linear(t, h, t.constant(Block<float>(phi.p.value(phi.w[l]))),
                      t.constant(Block<float>(phi.p.value(phi.b[l]))), n);
      if (l + 1 < phi.layers()) h = jsa::relu_masked(t, h, n);
    }
    const Block<float> plain = plain_forward(phi, x);
    const double err = (t.value(h).topRows(n) - plain).cwiseAbs().maxCoeff();
    const double scale = plain.cwiseAbs().maxCoeff();
    std::printf(
        "validate: max |engine - plain Eigen| = %.2e (values up to %.2e), loss %.5f, |grad| %.3e\n",
        err, scale, double(loss),
        double(
            Eigen::Map<const Eigen::VectorXf>(phi.p.grads().data(), Index(phi.p.size())).norm()));
    if (!(err <= 1e-4 * std::max(1.0, scale)) || !std::isfinite(loss)) {
      std::fprintf(stderr, "validation failed\n");
      return 1;
    }
  }

  // Time the engine step and the GEMMs alone in alternation, so that load from
  // other processes on the machine falls on both alike. Two warm-up rounds.
  const Block<float> stacked = stacked_input(x);
  GemmOnly gemm(stacked, phi);
  std::vector<Phases> eng;
  std::vector<std::pair<double, double>> gem;
  for (int i = 0; i < o.runs + 2; ++i) {
    Phases ph;
    engine_step(tape, phi, x, target, &ph);
    const auto g = gemm.step(phi);
    if (i >= 2) {
      eng.push_back(ph);
      gem.push_back(g);
    }
  }
  auto column = [](const auto& v, auto get) {
    std::vector<double> c;
    for (const auto& e : v) c.push_back(get(e));
    return c;
  };
  const auto e_total = column(eng, [](const Phases& p) { return p.total(); });
  const auto g_total =
      column(gem, [](const std::pair<double, double>& p) { return p.first + p.second; });
  const double te = median(e_total), tg = median(g_total);
  const double ge = flops / te * 1e-9, gg = flops / tg * 1e-9;

  std::printf(
      "\nphi 2-256x5-3, N = %ld points (%ld stacked rows), threads = %d, median of %d runs\n",
      long(n), long(rows), jsa::max_threads(), o.runs);
  std::printf("FLOPs per step: forward %.2f G, backward %.2f G, total %.2f G\n\n", fwd * 1e-9,
              bwd * 1e-9, flops * 1e-9);
  std::printf("%-36s %10s %10s %10s %10s\n", "", "median ms", "min ms", "max ms", "GFLOP/s");
  auto line = [&](const char* name, const std::vector<double>& t, double f) {
    const double m = median(t);
    std::printf("%-36s %10.1f %10.1f %10.1f", name, m * 1e3,
                *std::min_element(t.begin(), t.end()) * 1e3,
                *std::max_element(t.begin(), t.end()) * 1e3);
    if (f > 0) std::printf(" %10.1f", f / m * 1e-9);
    std::printf("\n");
  };
  line("engine: linear (GEMM + bias)", column(eng, [](const Phases& p) { return p.linear; }), fwd);
  line("engine: relu_masked", column(eng, [](const Phases& p) { return p.relu; }), 0);
  line("engine: loss (value + J^T J)", column(eng, [](const Phases& p) { return p.loss; }), 0);
  line("engine: forward total", column(eng, [](const Phases& p) { return p.forward(); }), fwd);
  line("engine: backward", column(eng, [](const Phases& p) { return p.backward; }), bwd);
  line("engine: step (fwd + loss + bwd)", e_total, flops);
  line("Eigen SGEMM: forward",
       column(gem, [](const std::pair<double, double>& p) { return p.first; }), fwd);
  line("Eigen SGEMM: backward (dW, dX)",
       column(gem, [](const std::pair<double, double>& p) { return p.second; }), bwd);
  line("Eigen SGEMM: step", g_total, flops);
  std::printf("\nengine / GEMM throughput (step medians): %.1f%%  (target >= 60%%): %s\n",
              100.0 * ge / gg, ge >= 0.6 * gg ? "met" : "NOT met");
  std::printf("tape memory: %.1f MB\n", double(tape.bytes()) / (1 << 20));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(parse(argc, argv));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_mlp_step: %s\n", e.what());
    return 1;
  }
}
