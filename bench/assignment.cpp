// The exact assignment behind the EMD metric (Eq. 13) on the paper's size:
// M' = 2000 random 3D points against 2000 others, squared-distance costs.
// Validates before it times: on the same integer-scaled matrix (round(1e6 c)),
// LAPJV and the independent auction must reach exactly the same optimal cost,
// and LAPJV's duals must certify its double-precision answer.
//
//   bench_assignment [--n N] [--runs R] [--threads T]
//
// Times n/4, n/2 and n points; per size, the median of R runs of the cost
// matrix (parallel) and of the LAPJV solve (serial), on the same sets each run
// (every run must return the same matching).
#include "losses/metrics/assignment.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench/timing.h"
#include "engine/check.h"
#include "engine/parallel.h"
#include "engine/rng.h"
#include "losses/metrics/assignment_auction.h"
#include "losses/metrics/emd.h"

namespace {

using bench::Clock;
using jsa::Block;
using jsa::Index;

using bench::median;
using bench::seconds_since;

struct Options {
  int threads = 0;  // 0: OpenMP's default
  int n = 2000;     // M', the paper's evaluation size
  int runs = 5;
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> int {
      if (i + 1 >= argc) throw std::runtime_error(a + " needs a value");
      char* end = nullptr;
      const long v = std::strtol(argv[++i], &end, 10);
      if (*end != '\0' || v < 1 || v > 100000)
        throw std::runtime_error(a + ": expected an integer in [1, 100000], got '" + argv[i] + "'");
      return int(v);
    };
    if (a == "--threads")
      o.threads = next();
    else if (a == "--n")
      o.n = next();
    else if (a == "--runs")
      o.runs = next();
    else
      throw std::runtime_error("unknown flag '" + a + "' (flags: --n N --runs R --threads T)");
  }
  return o;
}

Block<double> random_points(Index n, uint64_t seed) {
  jsa::Rng rng(seed);
  Block<double> p(n, 3);
  for (Index k = 0; k < p.size(); ++k) p.data()[k] = rng.uniform(-1, 1);
  return p;
}

// LAPJV against the auction on one integer matrix, and LAPJV's certificate on
// the double matrix. Throws if either fails.
void validate(int n) {
  const Block<double> x = random_points(n, 1), y = random_points(n, 2);
  const Block<double> cost = jsa::squared_distance_costs(x, y);
  const Block<int64_t> integer = jsa::integer_costs(cost, 1e6);
  auto t0 = Clock::now();
  const jsa::Assignment exact = jsa::assign_lapjv(integer.cast<double>());
  const double lapjv_seconds = seconds_since(t0);
  t0 = Clock::now();
  const jsa::IntegerAssignment auction = jsa::assign_auction(integer);
  const double auction_seconds = seconds_since(t0);
  std::printf("validate n = %d, costs round(1e6 |x - y|^2):\n", n);
  std::printf("  LAPJV   %.3f s  cost %lld\n", lapjv_seconds, (long long)exact.cost);
  std::printf("  auction %.3f s  cost %lld  (%d phases, %lld bids)\n", auction_seconds,
              (long long)auction.cost, auction.phases, (long long)auction.bids);
  if (double(auction.cost) != exact.cost)
    throw std::runtime_error("LAPJV and auction disagree on the optimal cost");
  const jsa::Assignment real = jsa::assign_lapjv(cost);
  const jsa::AssignmentCertificate cert = jsa::check_certificate(cost, real);
  std::printf("  certificate (double costs): dual violation %.2e, slackness %.2e, gap <= %.2e\n",
              cert.max_dual_violation, cert.max_slackness_violation, cert.cost_gap_bound);
  if (!cert.proves_optimal(1e-12)) throw std::runtime_error("LAPJV duals do not certify");
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const Options o = parse(argc, argv);
    jsa::set_threads(o.threads);
    std::printf("threads %d, runs %d (median)\n", jsa::max_threads(), o.runs);
    validate(o.n);

    std::printf("\n%8s %12s %12s %12s %14s\n", "n", "costs s", "LAPJV s", "total s",
                "EMD (mean d^2)");
    std::vector<int> sizes = {o.n / 4, o.n / 2, o.n};
    sizes.erase(std::remove(sizes.begin(), sizes.end(), 0), sizes.end());
    for (int n : sizes) {
      const Block<double> x = random_points(n, 10 + n), y = random_points(n, 20 + n);
      std::vector<double> build, solve, total;
      std::vector<int> first;
      double cost = 0;
      for (int r = 0; r < o.runs; ++r) {
        const auto t0 = Clock::now();
        const Block<double> c = jsa::squared_distance_costs(x, y);
        const auto t1 = Clock::now();
        const jsa::Assignment a = jsa::assign_lapjv(c);
        build.push_back(std::chrono::duration<double>(t1 - t0).count());
        solve.push_back(seconds_since(t1));
        total.push_back(seconds_since(t0));
        if (r == 0) first = a.column_of_row;
        if (a.column_of_row != first) throw std::runtime_error("runs returned different matchings");
        cost = a.cost;
      }
      std::printf("%8d %12.4f %12.4f %12.4f %14.6f\n", n, median(build), median(solve),
                  median(total), cost / n);
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_assignment: %s\n", e.what());
    return 1;
  }
}
