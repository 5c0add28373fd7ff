// One training iteration of the full method (Table 1 row 11), timed as a whole
// and piece by piece, with the MLP work set against a plain Eigen SGEMM of the
// same shapes timed in the same run (the achievable ceiling).
//
//   bench_iteration [--points M] [--gaussians K] [--width W] [--depth D]
//                   [--threads T] [--runs R] [--csv FILE]
//
// Pieces (each on the tape, forward + backward, median of R after a warm-up):
//   phi+J    phi with stacked Jacobians on 2M points (x_P and psi(x_S)), 6M rows
//   psi      psi on 2M points (x_S and phi6(x_P))
//   chamfer  L_6D (M x M, 6D) and L_2D (M x M, 2D), search + backward
//   rep      L_rep on K means with the cut-off
//   adam     one update of every parameter
//   step     Trainer::step(): all of the above plus sampling and glue, with
//            the default dense L_6D, and again with the M-to-M L_6D of Eq. 7
//            (the CSV's step_ms is the M-to-M step, the work the PyTorch
//            peers do; dense_step_ms the default's), and the default fit's
//            step in its second half, L_even and L_EMD on (late_step_ms),
//            and with L_even alone (even_step_ms)
// Each kernel is validated against its oracle before it is timed.
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "engine/ops.h"
#include "engine/parallel.h"
#include "engine/tangents.h"
#include "io/geometry/nearest.h"
#include "losses/chamfer.h"
#include "losses/repulsion.h"
#include "model/tool/trainer.h"

using namespace jsa;
using Clock = std::chrono::steady_clock;

namespace {

double median_ms(int runs, const std::function<void()>& f) {
  f();  // warm-up: first-touch allocations
  std::vector<double> t;
  for (int r = 0; r < runs; ++r) {
    const auto t0 = Clock::now();
    f();
    t.push_back(1e3 * std::chrono::duration<double>(Clock::now() - t0).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

Block<float> random_block(Index n, Index c, Rng& rng, double scale = 1) {
  Block<float> b(n, c);
  for (Index i = 0; i < b.size(); ++i) b.data()[i] = float(scale * rng.normal());
  return b;
}

// Forward + backward FLOPs of an MLP on `rows` rows (first layer has no dX).
double mlp_flops(const Mlp<float>& mlp, Index rows) {
  return 3.0 * mlp.flops(rows) - 2.0 * rows * mlp.shape().in * mlp.shape().width;
}

// The same GEMMs as an MLP step, in plain Eigen: Y = X W, dW = X^T dY, dX = dY W^T,
// into preallocated outputs (noalias), so the bound is the GEMM kernels alone.
double sgemm_ms(const std::vector<int>& widths, Index rows, int runs) {
  Rng rng(3);
  std::vector<Block<float>> x, w, y, dw, dx;
  for (size_t l = 0; l + 1 < widths.size(); ++l) {
    x.push_back(random_block(rows, widths[l], rng));
    w.push_back(random_block(widths[l], widths[l + 1], rng, 0.05));
    y.emplace_back(rows, widths[l + 1]);
    dw.emplace_back(widths[l], widths[l + 1]);
    dx.emplace_back(rows, widths[l]);
  }
  return median_ms(runs, [&]() {
    for (size_t l = 0; l < w.size(); ++l) {
      y[l].noalias() = x[l] * w[l];
      dw[l].noalias() = x[l].transpose() * y[l];
      if (l > 0) dx[l].noalias() = y[l] * w[l].transpose();
    }
  });
}

}  // namespace

int main(int argc, char** argv) {
  FitOptions o;
  o.schedule.kind = "step";  // every timed step at the full M
  // ReLU unless --softplus BETA: the peers (bench/peer_torch.py) run the
  // paper's ReLU MLPs, and the comparison is like for like.
  o.atlas.softplus_beta = 0;
  int threads = 0, runs = 5;
  std::string csv;
  for (int i = 1; i < argc + (argc % 2 == 0 ? 1 : 0); ++i)
    if (i == argc || std::string(argv[i]) == "--help" ||
        std::string(argv[i]) == "-h") {  // help, or a flag without its value
      std::printf(
          "usage: bench_iteration [--points M] [--gaussians K] [--width W] [--depth D] [--softplus "
          "BETA] [--threads T] [--runs R] [--csv FILE]\n");
      return i == argc ? 2 : 0;
    }
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string f = argv[i];
    const long v = std::atol(argv[i + 1]);
    if (f == "--points")
      o.points = v;
    else if (f == "--gaussians")
      o.atlas.gaussians = int(v);
    else if (f == "--width")
      o.atlas.width = int(v);
    else if (f == "--depth")
      o.atlas.hidden_layers = int(v);
    else if (f == "--softplus")
      o.atlas.softplus_beta = std::atof(argv[i + 1]);
    else if (f == "--threads")
      threads = int(v);
    else if (f == "--runs")
      runs = int(v);
    else if (f == "--csv")
      csv = argv[i + 1];
    else {
      std::fprintf(stderr, "unknown flag %s\n", f.c_str());
      return 2;
    }
    if (f != "--csv" && v <= 0 && f != "--threads") {
      std::fprintf(stderr, "%s needs a positive value\n", f.c_str());
      return 2;
    }
  }
  set_threads(threads);
  const Index m = o.points;
  Rng rng(1);

  // ---- validate the kernels against their oracles ----
  {
    const Block<float> a = random_block(2000, 6, rng), b = random_block(2000, 6, rng);
    std::vector<int> fast, slow;
    nearest(a, b, fast);
    nearest_brute_force(a, b, slow);
    Block<float> mu(2000, 2);
    for (Index i = 0; i < mu.size(); ++i) mu.data()[i] = float(rng.uniform());
    const double cut = repulsion_cutoff<float>(mu, 1.0f / std::sqrt(2000.0f), nullptr);
    const double exact = repulsion_exact<float>(mu, 1.0f / std::sqrt(2000.0f), nullptr);
    if (fast != slow || std::abs(cut - exact) > 1e-5 * exact) {
      std::fprintf(stderr, "validation failed: nearest %s, repulsion %g vs %g\n",
                   fast == slow ? "ok" : "differs", cut, exact);
      return 1;
    }
    std::printf(
        "validated: nearest == brute force (2000 x 2000, 6D); repulsion cut-off %.9g vs exact "
        "%.9g\n",
        cut, exact);
  }

  // A pool on the unit sphere is enough to time: the cost does not depend on the shape.
  Block<double> pool(200000, 6);
  for (Index i = 0; i < pool.rows(); ++i) {
    Eigen::RowVector3d p(rng.normal(), rng.normal(), rng.normal());
    p.normalize();
    // Per coordinate: GCC 12 warns (-Warray-bounds) on Eigen's AVX-512 copy of a 3-vector row.
    for (int k = 0; k < 3; ++k) pool(i, k) = pool(i, 3 + k) = p(k);
  }
  Trainer trainer(o, pool);
  for (int i = 0; i < 3; ++i) trainer.step();  // move off the initialisation
  Atlas<float>& atlas = trainer.atlas();
  Tape<float> t;

  const Block<float> x2 = random_block(2 * m, 2, rng, 0.3);
  const Block<float> x6 = random_block(2 * m, 6, rng, 0.3);
  const Block<float> a6 = random_block(m, 6, rng), b6 = random_block(m, 6, rng);
  const Block<float> a2 = random_block(m, 2, rng), b2 = random_block(m, 2, rng);

  auto backward_sum = [&](Var y) {
    Var l = sum(t, y);
    atlas.params.zero_grad();
    t.backward(l);
  };
  const double phi_ms = median_ms(runs, [&]() {
    t.clear();
    SurfacePoints s = atlas.phi.evaluate(t, atlas.params, t.constant(x2), true);
    backward_sum(concat_cols(t, {s.phi6, s.du, s.dv}));
  });
  const double psi_ms = median_ms(runs, [&]() {
    t.clear();
    backward_sum(atlas.psi.evaluate(t, atlas.params, t.constant(x6)));
  });
  const double ch6_ms = median_ms(runs, [&]() {
    t.clear();
    t.backward(chamfer(t, t.variable(a6), t.variable(b6)));
  });
  const double ch2_ms = median_ms(runs, [&]() {
    t.clear();
    t.backward(chamfer(t, t.variable(a2), t.variable(b2)));
  });
  const double rep_ms = median_ms(runs, [&]() {
    t.clear();
    t.backward(repulsion(t, atlas.params.on(t, atlas.domain.means()), atlas.domain.sigma()));
  });
  Adam<float> adam;
  const double adam_ms = median_ms(runs, [&]() { adam.step(atlas.params, 1e-9); });
  const double step_ms = median_ms(runs, [&]() { trainer.step(); });
  FitOptions sparse_options = o;
  sparse_options.dense_surface = !o.dense_surface;
  Trainer other(sparse_options, pool);
  for (int i = 0; i < 3; ++i) other.step();
  const double other_ms = median_ms(runs, [&]() { other.step(); });
  const double dense_ms = o.dense_surface ? step_ms : other_ms;
  const double sparse_ms = o.dense_surface ? other_ms : step_ms;
  // The second half of a default fit: L_even and L_EMD join the objective
  // there (from half the run; here from the first step), on the dense L_6D;
  // and L_even alone, for what L_EMD adds. Timed one trainer after the other
  // like the steps above: taking turns step by step was tried and made every
  // trainer's step dearer by a different amount (each evicts the others'
  // data from the caches), L_even's step then timing below the dense one's.
  FitOptions late_options = o;
  late_options.dense_surface = true;
  late_options.evenness_from = 0;
  late_options.transport_from = 0;
  Trainer late(late_options, pool);
  for (int i = 0; i < 3; ++i) late.step();
  const double late_ms = median_ms(runs, [&]() { late.step(); });
  FitOptions even_options = late_options;
  even_options.weights.transport = 0;
  Trainer even(even_options, pool);
  for (int i = 0; i < 3; ++i) even.step();
  const double even_ms = median_ms(runs, [&]() { even.step(); });
  const double late_x = late_ms / dense_ms, even_x = even_ms / dense_ms;

  // The MLP GEMM ceiling: phi on 6M stacked rows and psi on 2M rows.
  std::vector<int> phi_w{2}, psi_w{6};
  for (int l = 0; l < o.atlas.hidden_layers; ++l) {
    phi_w.push_back(o.atlas.width);
    psi_w.push_back(o.atlas.width);
  }
  phi_w.push_back(3);
  psi_w.push_back(2);
  const double gemm_ms = sgemm_ms(phi_w, 6 * m, runs) + sgemm_ms(psi_w, 2 * m, runs);
  const double flops = mlp_flops(atlas.phi.mlp(), 6 * m) + mlp_flops(atlas.psi.mlp(), 2 * m);
  struct rusage ru;
  getrusage(RUSAGE_SELF, &ru);

  std::printf("\nfull method, M = %lld, K = %d, MLPs %dx%d, threads = %d, median of %d\n",
              (long long)m, o.atlas.gaussians, o.atlas.hidden_layers, o.atlas.width, max_threads(),
              runs);
  std::printf("  %-34s %9s\n", "piece", "ms");
  std::printf("  %-34s %9.1f\n", "phi + Jacobians, 2M points (f+b)", phi_ms);
  std::printf("  %-34s %9.1f\n", "psi, 2M points (f+b)", psi_ms);
  std::printf("  %-34s %9.1f\n", "Chamfer 6D, M x M (f+b)", ch6_ms);
  std::printf("  %-34s %9.1f\n", "Chamfer 2D, M x M (f+b)", ch2_ms);
  std::printf("  %-34s %9.1f\n", "repulsion, K means (f+b)", rep_ms);
  std::printf("  %-34s %9.1f\n", "Adam", adam_ms);
  std::printf("  %-34s %9.1f\n", "one training step (all)", step_ms);
  std::printf("  %-34s %9.1f   (the dense L_6D step costs x%.2f the M-to-M one)\n",
              o.dense_surface ? "same, M-to-M L_6D (Eq. 7)" : "same, dense L_6D", other_ms,
              dense_ms / sparse_ms);
  std::printf("  %-34s %9.1f   (x%.2f the dense step; w_even %g, w_EMD %g on %lld points)\n",
              "same, second half (L_even, L_EMD)", late_ms, late_x, late_options.weights.evenness,
              late_options.weights.transport,
              (long long)std::min<Index>(late_options.transport_points, m));
  std::printf("  %-34s %9.1f   (x%.2f the dense step)\n", "same, second half, L_even alone",
              even_ms, even_x);
  std::printf(
      "  MLP work %.1f GFLOP: %.0f GFLOP/s in the step's MLPs (phi+psi pieces), SGEMM of the same "
      "shapes "
      "%.1f ms = %.0f GFLOP/s (ratio %.0f%%)\n",
      flops * 1e-9, flops * 1e-6 / (phi_ms + psi_ms), gemm_ms, flops * 1e-6 / gemm_ms,
      100.0 * gemm_ms / (phi_ms + psi_ms));
  std::printf("  peak resident memory %.0f MB\n", ru.ru_maxrss / 1024.0);
  if (!csv.empty()) {
    const bool fresh = !std::ifstream(csv).good();
    std::ofstream out(csv, std::ios::app);
    if (fresh)
      out << "points,gaussians,width,depth,threads,phi_ms,psi_ms,chamfer6_ms,chamfer2_ms,repulsion_"
             "ms,adam_ms,step_ms,gemm_ms,gflop,peak_mb,dense_step_ms,late_step_ms,even_step_ms\n";
    out << m << "," << o.atlas.gaussians << "," << o.atlas.width << "," << o.atlas.hidden_layers
        << "," << max_threads() << "," << phi_ms << "," << psi_ms << "," << ch6_ms << "," << ch2_ms
        << "," << rep_ms << "," << adam_ms << "," << sparse_ms << "," << gemm_ms << ","
        << flops * 1e-9 << "," << ru.ru_maxrss / 1024.0 << "," << dense_ms << "," << late_ms << ","
        << even_ms << "\n";
  }
  return 0;
}
