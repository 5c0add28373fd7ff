// Paper Fig. 4 as a number: fit the unit cube with the full method and with
// repulsion off, map the Gaussian means mu_k through phi, and report the
// fraction landing on each of the six faces. With L_rep the density should be
// even (~1/6 each); without it one face tends to take most of the means.
//   bench_cube_faces [--iters N] [--points M] [--gaussians K] [--width W] [--seed S]
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "engine/parallel.h"
#include "model/tool/domain_mesh.h"
#include "model/tool/shape_input.h"
#include "model/tool/trainer.h"

using namespace jsa;

static std::array<double, 6> face_fractions(Atlas<float>& atlas) {
  const Block<double> mu = atlas.params.value(atlas.domain.means()).cast<double>();
  Block<double> p, n;
  evaluate_surface(atlas, mu, p, n);
  std::array<double, 6> count{};
  for (Index i = 0; i < p.rows(); ++i) {
    Index axis;
    p.row(i).cwiseAbs().maxCoeff(&axis);
    count[size_t(2 * axis + (p(i, axis) > 0 ? 1 : 0))] += 1;
  }
  for (double& c : count) c /= double(p.rows());
  return count;
}

int main(int argc, char** argv) {
  FitOptions o;
  o.iterations = 1500;
  o.points = 2500;
  o.atlas.gaussians = 2500;
  o.atlas.width = 128;
  int threads = 0;
  for (int i = 1; i < argc + (argc % 2 == 0 ? 1 : 0); ++i)
    if (i == argc || std::strcmp(argv[i], "--help") == 0 ||
        std::strcmp(argv[i], "-h") == 0) {  // help, or a flag without its value
      std::printf(
          "usage: bench_cube_faces [--iters N] [--points M] [--gaussians K] [--width W] [--seed S] "
          "[--threads T]\n");
      return i == argc ? 2 : 0;
    }
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string f = argv[i];
    const char* v = argv[i + 1];
    if (f == "--iters")
      o.iterations = std::atoll(v);
    else if (f == "--points")
      o.points = std::atoll(v);
    else if (f == "--gaussians")
      o.atlas.gaussians = std::atoi(v);
    else if (f == "--width")
      o.atlas.width = std::atoi(v);
    else if (f == "--seed")
      o.seed = std::strtoull(v, nullptr, 10);
    else if (f == "--threads")
      threads = std::atoi(v);
    else {
      std::fprintf(stderr, "unknown flag %s\n", f.c_str());
      return 2;
    }
  }
  set_threads(threads);
  const RunInput cube = load_run_input("builtin:cube", 200000, o.seed);
  std::printf("cube, %lld iterations, M = %lld, K = %d, MLP %dx%d, seed %llu\n",
              (long long)o.iterations, (long long)o.points, o.atlas.gaussians,
              o.atlas.hidden_layers, o.atlas.width, (unsigned long long)o.seed);
  std::printf("%-16s %6s %6s %6s %6s %6s %6s   max   L_6D\n", "method", "-x", "+x", "-y", "+y",
              "-z", "+z");
  for (bool repulsion : {true, false}) {
    FitOptions run = o;
    run.components.repulsion = repulsion;
    Trainer t(run, cube.pool);
    while (!t.finished()) t.step();
    const auto f = face_fractions(t.atlas());
    double mx = 0;
    for (double x : f) mx = std::max(mx, x);
    std::printf("%-16s %6.3f %6.3f %6.3f %6.3f %6.3f %6.3f  %5.3f  %.2e\n",
                repulsion ? "full (row 11)" : "no repulsion", f[0], f[1], f[2], f[3], f[4], f[5],
                mx, t.last().surface);
  }
  return 0;
}
