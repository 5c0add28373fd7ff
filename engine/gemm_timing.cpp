#include "engine/gemm_timing.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <tuple>

#include "engine/check.h"
#include "engine/rng.h"

namespace jsa {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

double fastest(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }

// A list's distinct products (first appearance order) and how often each runs.
struct Counted {
  GemmCall call;
  int count = 0;
};
std::vector<Counted> distinct(const std::vector<GemmCall>& calls) {
  std::vector<Counted> out;
  std::map<std::tuple<bool, bool, bool, Index, Index, Index>, size_t> at;
  for (const GemmCall& g : calls) {
    const auto key = std::make_tuple(g.transpose_a, g.transpose_b, g.accumulate, g.m, g.n, g.k);
    const auto [it, fresh] = at.emplace(key, out.size());
    if (fresh) out.push_back({g, 0});
    ++out[it->second].count;
  }
  return out;
}

// Operands for a list of products: each as large as the largest it serves,
// filled once with values in [-1, 1) (a step's layers, too, run one after
// the other on blocks of a few sizes), and a second C for the check.
struct Operands {
  std::vector<float> a, b, c, c2;
  Operands(const std::vector<Counted>& products, uint64_t seed) {
    size_t na = 0, nb = 0, nc = 0;
    for (const Counted& p : products) {
      na = std::max(na, size_t(p.call.m * p.call.k));
      nb = std::max(nb, size_t(p.call.k * p.call.n));
      nc = std::max(nc, size_t(p.call.m * p.call.n));
    }
    Rng rng(seed);
    a.resize(na);
    b.resize(nb);
    c.assign(nc, 0.0f);
    for (float& v : a) v = float(rng.uniform(-1, 1));
    for (float& v : b) v = float(rng.uniform(-1, 1));
  }
  double seconds(Gemm backend, const GemmCall& g) {
    const auto t0 = Clock::now();
    sgemm(backend, g, a.data(), b.data(), c.data());
    return seconds_since(t0);
  }
  // Each product through both backends back to back (which goes first
  // alternates with `flip`), weighted by its count: the list's time by each.
  // Without a BLAS, Eigen alone.
  std::pair<double, double> time(const std::vector<Counted>& products, bool flip) {
    const bool with_blas = blas_built_in();
    double eigen = 0, blas = 0;
    for (const Counted& p : products) {
      if (with_blas && flip) blas += p.count * seconds(Gemm::blas, p.call);
      eigen += p.count * seconds(Gemm::eigen, p.call);
      if (with_blas && !flip) blas += p.count * seconds(Gemm::blas, p.call);
    }
    return {eigen, blas};
  }
  // Both backends agree on every product (as a first writer: beta = 0).
  void check(const std::vector<Counted>& products) {
    c2.resize(c.size());
    for (const Counted& p : products) {
      GemmCall g = p.call;
      g.accumulate = false;
      sgemm(Gemm::eigen, g, a.data(), b.data(), c.data());
      sgemm(Gemm::blas, g, a.data(), b.data(), c2.data());
      float largest = 0, error = 0;
      for (size_t i = 0; i < size_t(g.m * g.n); ++i) {
        largest = std::max(largest, std::abs(c[i]));
        error = std::max(error, std::abs(c[i] - c2[i]));
      }
      JSA_CHECK(error <= 1e-4f * std::max(largest, 1.0f),
                "the BLAS's product (" << g.m << "x" << g.k << " by " << g.k << "x" << g.n
                                       << ") differs from Eigen's by " << error << " of "
                                       << largest);
    }
  }
};

}  // namespace

GemmTiming time_gemm_calls(const std::vector<GemmCall>& calls, int repeats) {
  const auto start = Clock::now();
  GemmTiming t;
  t.repeats = repeats;
  if (calls.empty() || repeats < 1) return t;
  const bool blas = blas_built_in();
  // The products made outside a parallel region, and those made in a team:
  // per team size, each thread's.
  std::vector<GemmCall> serial_calls;
  std::map<int, std::vector<std::vector<GemmCall>>> team_calls;
  for (const GemmCall& g : calls) {
    if (g.team <= 1) {
      serial_calls.push_back(g);
      continue;
    }
    std::vector<std::vector<GemmCall>>& own = team_calls[g.team];
    own.resize(size_t(g.team));
    own[size_t(std::min(g.thread, g.team - 1))].push_back(g);
  }
  const std::vector<Counted> serial = distinct(serial_calls);
  Operands serial_operands(serial, 1);
  struct Team {
    int size;
    std::vector<std::vector<Counted>> products;  // per thread
    std::vector<Operands> operands;
  };
  std::vector<Team> teams;
  for (const auto& [size, lists] : team_calls) {
    Team team{size, {}, {}};
    for (size_t w = 0; w < lists.size(); ++w) {
      team.products.push_back(distinct(lists[w]));
      team.operands.emplace_back(team.products.back(), 2 + w);
    }
    teams.push_back(std::move(team));
  }
  if (blas) {
    serial_operands.check(serial);
    for (Team& team : teams)
      for (size_t w = 0; w < team.products.size(); ++w) team.operands[w].check(team.products[w]);
  }
  // Round 0 warms both up (the BLAS's buffers and threads, the operands'
  // pages) and is not counted. A team's time is its slowest thread's.
  std::vector<double> eigen, other;
  for (int r = 0; r <= repeats; ++r) {
    const bool flip = r % 2 == 1;
    auto [e, b] = serial_operands.time(serial, flip);
    for (Team& team : teams) {
      std::vector<std::pair<double, double>> each(size_t(team.size), {0.0, 0.0});
#pragma omp parallel for num_threads(team.size) schedule(static, 1)
      for (int w = 0; w < team.size; ++w)
        each[size_t(w)] = team.operands[size_t(w)].time(team.products[size_t(w)], flip);
      double slowest_e = 0, slowest_b = 0;
      for (const auto& [te, tb] : each) {
        slowest_e = std::max(slowest_e, te);
        slowest_b = std::max(slowest_b, tb);
      }
      e += slowest_e;
      b += slowest_b;
    }
    if (r == 0) continue;
    eigen.push_back(e);
    other.push_back(b);
  }
  t.eigen_seconds = fastest(eigen);
  t.blas_seconds = blas ? fastest(other) : 0;
  t.wall_seconds = seconds_since(start);
  return t;
}

Gemm faster_gemm(const GemmTiming& t, double margin) {
  const bool blas = blas_built_in() && t.blas_seconds > 0;
  return blas && t.eigen_seconds >= margin * t.blas_seconds ? Gemm::blas : Gemm::eigen;
}

}  // namespace jsa
