// The loss and evaluation kernels on their own, at the sizes, each
// validated against its oracle before it is timed:
//   Chamfer 6D   N x N rows [x, alpha n] (L_6D, Eq. 7): targets on the unit
//                sphere against a noisy sphere (a fitted surface), both directions,
//                kd-tree builds included; nearest() == brute force, index for index
//   Chamfer 2D   N x N points in [0, 1]^2 (L_2D, Eq. 8), the same way
//   repulsion    L_rep at K means in [0, 1]^2 (Eq. 11), value and gradient; the
//                cut-off against the exact O(K^2) sum
//   assignment   exact n x n assignment of squared-distance costs (the EMD,
//                Eq. 13); LAPJV against the independent auction on the same
//                integer matrix, then LAPJV timed on the double matrix
//
//   bench_kernels [--points N] [--gaussians K] [--n N'] [--runs R] [--threads T] [--dump DIR]
//
// --dump DIR writes the inputs for bench/peer_scipy.py, each as a raw
// little-endian file: int64 rows, int64 cols, then rows x cols float64 row-major
// (chamfer6_x.bin, chamfer6_y.bin, chamfer2_x.bin, chamfer2_y.bin,
// assignment_cost.bin), and our values and medians as "name value" lines in
// ours.txt, for the peer to check against and compare with.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench/timing.h"
#include "engine/parallel.h"
#include "engine/rng.h"
#include "io/geometry/nearest.h"
#include "losses/chamfer.h"
#include "losses/metrics/assignment.h"
#include "losses/metrics/assignment_auction.h"
#include "losses/metrics/emd.h"
#include "losses/repulsion.h"

namespace {

using bench::Clock;
using bench::median;
using bench::seconds_since;
using jsa::Block;
using jsa::Index;

struct Options {
  int points = 10000;     // N, both Chamfer sets
  int gaussians = 10000;  // K, repulsion
  int n = 2000;           // assignment size (M' of the paper's evaluation)
  int runs = 5;
  int threads = 0;  // 0: OpenMP's default
  std::string dump;
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (i + 1 >= argc) throw std::runtime_error(a + " needs a value");
    const std::string value = argv[++i];
    auto number = [&]() -> int {
      char* end = nullptr;
      const long v = std::strtol(value.c_str(), &end, 10);
      if (*end != '\0' || v < 1 || v > 1000000)
        throw std::runtime_error(a + ": expected an integer in [1, 1000000], got '" + value + "'");
      return int(v);
    };
    if (a == "--points")
      o.points = number();
    else if (a == "--gaussians")
      o.gaussians = number();
    else if (a == "--n")
      o.n = number();
    else if (a == "--runs")
      o.runs = number();
    else if (a == "--threads")
      o.threads = number();
    else if (a == "--dump")
      o.dump = value;
    else
      throw std::runtime_error(
          "unknown flag '" + a +
          "' (flags: --points N --gaussians K --n N' --runs R --threads T --dump DIR)");
  }
  return o;
}

// Median seconds of `runs` calls after one untimed call.
double median_seconds(int runs, const std::function<void()>& f) {
  f();
  std::vector<double> t;
  for (int r = 0; r < runs; ++r) {
    const auto t0 = Clock::now();
    f();
    t.push_back(seconds_since(t0));
  }
  return median(t);
}

// n rows [p, alpha p] with p uniform on the unit sphere, p pushed off it by N(0, noise^2) per
// coordinate.
Block<float> sphere6(Index n, double noise, jsa::Rng& rng) {
  Block<float> b(n, 6);
  for (Index i = 0; i < n; ++i) {
    double p[3] = {rng.normal(), rng.normal(), rng.normal()};
    const double r = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    for (int c = 0; c < 3; ++c) {
      b(i, c) = float(p[c] / r + noise * rng.normal());
      b(i, 3 + c) = float(0.01 * p[c] / r);
    }
  }
  return b;
}

Block<float> uniform(Index n, Index cols, jsa::Rng& rng) {
  Block<float> b(n, cols);
  for (Index i = 0; i < b.size(); ++i) b.data()[i] = float(rng.uniform());
  return b;
}

template <class T>
void write_matrix(const std::string& path, const Block<T>& m) {
  const uint16_t probe = 1;
  if (*reinterpret_cast<const unsigned char*>(&probe) != 1)
    throw std::runtime_error("--dump writes little-endian files: not on this machine");
  std::ofstream out(path, std::ios::binary);
  const int64_t shape[2] = {int64_t(m.rows()), int64_t(m.cols())};
  out.write(reinterpret_cast<const char*>(shape), sizeof shape);
  const Block<double> d = m.template cast<double>();  // row-major, like every Block
  out.write(reinterpret_cast<const char*>(d.data()), std::streamsize(d.size() * sizeof(double)));
  if (!out) throw std::runtime_error("cannot write " + path);
}

// Chamfer of x and y: nearest() against brute force both ways, then timed.
// Returns {value, median seconds}.
std::pair<double, double> chamfer_kernel(const char* name, const Block<float>& x,
                                         const Block<float>& y, int runs) {
  jsa::ChamferMatches<float> m;
  const double value = jsa::chamfer_distance(x, y, &m);
  std::vector<int> x_to_y, y_to_x;
  auto t0 = Clock::now();
  jsa::nearest_brute_force(x, y, x_to_y);
  jsa::nearest_brute_force(y, x, y_to_x);
  const double brute = seconds_since(t0);
  if (x_to_y != m.x_to_y || y_to_x != m.y_to_x)
    throw std::runtime_error(std::string(name) + ": nearest() differs from brute force");
  const double s = median_seconds(runs, [&]() { jsa::chamfer_distance(x, y); });
  std::printf("%-11s %6lld x %-6lld %dD  CD %.9g  == brute force (%.2f s)  median %.4f s\n", name,
              (long long)x.rows(), (long long)y.rows(), int(x.cols()), value, brute, s);
  return {value, s};
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const Options o = parse(argc, argv);
    jsa::set_threads(o.threads);
    std::printf("bench_kernels: threads %d, median of %d runs after a warm-up\n",
                jsa::max_threads(), o.runs);
    std::vector<std::pair<std::string, double>> ours;  // for ours.txt

    // ---- Chamfer, 6D and 2D ----
    jsa::Rng rng(7);
    const Block<float> x6 = sphere6(o.points, 0.0, rng), y6 = sphere6(o.points, 0.01, rng);
    const Block<float> x2 = uniform(o.points, 2, rng), y2 = uniform(o.points, 2, rng);
    const auto c6 = chamfer_kernel("chamfer6", x6, y6, o.runs);
    const auto c2 = chamfer_kernel("chamfer2", x2, y2, o.runs);
    ours.insert(ours.end(), {{"chamfer6_value", c6.first},
                             {"chamfer6_s", c6.second},
                             {"chamfer2_value", c2.first},
                             {"chamfer2_s", c2.second}});

    // ---- repulsion: the cut-off against every pair ----
    {
      const Block<float> mu = uniform(o.gaussians, 2, rng);
      const float sigma = float(1.0 / std::sqrt(double(o.gaussians)));
      Block<float> g_cut, g_exact;
      const double cut = jsa::repulsion_cutoff(mu, sigma, &g_cut);
      const auto t0 = Clock::now();
      const double exact = jsa::repulsion_exact(mu, sigma, &g_exact);
      const double exact_s = seconds_since(t0);
      const double value_err = std::abs(cut - exact) / exact;
      const double grad_err =
          double((g_cut - g_exact).cwiseAbs().maxCoeff() / g_exact.cwiseAbs().maxCoeff());
      if (value_err > 1e-5 || grad_err > 1e-4)
        throw std::runtime_error("repulsion: the cut-off is off the exact sum");
      const double s = median_seconds(o.runs, [&]() { jsa::repulsion_cutoff(mu, sigma, &g_cut); });
      std::printf(
          "%-11s K = %-8d    L %.9g  vs exact (%.2f s): value %.1e, gradient %.1e relative  median "
          "%.4f s\n",
          "repulsion", o.gaussians, cut, exact_s, value_err, grad_err, s);
      ours.insert(ours.end(),
                  {{"repulsion_value", cut}, {"repulsion_error", value_err}, {"repulsion_s", s}});
    }

    // ---- exact assignment: LAPJV against the auction, then LAPJV timed ----
    Block<double> p(o.n, 3), q(o.n, 3);
    for (Index i = 0; i < p.size(); ++i) p.data()[i] = rng.uniform(-1, 1);
    for (Index i = 0; i < q.size(); ++i) q.data()[i] = rng.uniform(-1, 1);
    const Block<double> cost = jsa::squared_distance_costs(p, q);
    {
      const Block<int64_t> integer = jsa::integer_costs(cost, 1e6);
      const jsa::Assignment lapjv = jsa::assign_lapjv(integer.cast<double>());
      const jsa::IntegerAssignment auction = jsa::assign_auction(integer);
      if (double(auction.cost) != lapjv.cost)
        throw std::runtime_error("assignment: LAPJV and the auction disagree on round(1e6 cost)");
    }
    jsa::Assignment a;
    const double assign_s = median_seconds(o.runs, [&]() { a = jsa::assign_lapjv(cost); });
    if (!jsa::check_certificate(cost, a).proves_optimal(1e-12))
      throw std::runtime_error("assignment: LAPJV's duals do not certify its matching");
    std::printf(
        "%-11s %6d x %-6d    cost %.12g  == auction (integer costs), certified  median %.4f s\n",
        "assignment", o.n, o.n, a.cost, assign_s);
    ours.insert(ours.end(), {{"assignment_cost", a.cost}, {"assignment_s", assign_s}});

    if (!o.dump.empty()) {
      const std::string d = o.dump + "/";
      write_matrix(d + "chamfer6_x.bin", x6);
      write_matrix(d + "chamfer6_y.bin", y6);
      write_matrix(d + "chamfer2_x.bin", x2);
      write_matrix(d + "chamfer2_y.bin", y2);
      write_matrix(d + "assignment_cost.bin", cost);
      std::ofstream out(d + "ours.txt");
      out << "threads " << jsa::max_threads() << "\n";
      char line[96];
      for (const auto& [name, value] : ours) {
        std::snprintf(line, sizeof line, "%s %.17g\n", name.c_str(), value);
        out << line;
      }
      if (!out) throw std::runtime_error("cannot write " + d + "ours.txt");
      std::printf("inputs and results written to %s\n", o.dump.c_str());
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_kernels: %s\n", e.what());
    return 1;
  }
}
