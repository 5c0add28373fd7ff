// Example: fit an atlas of the unit sphere with the Trainer (model/tool/trainer.h).
// FitOptions holds every setting, each with a documented default; here the sizes
// are made small (K = 256 Gaussians, 3 x 32 MLPs, M = 256 points) so the fit takes
// a few seconds. Everything else is inherited from FitOptions, i.e. `jsatlas fit`'s
// defaults, not the paper's (docs/method.md, "Defaults"): alpha = 0.08, softplus
// beta = 40, lambda_cycle = 0.1 (the other lambdas the paper's), the dense L_6D
// over the whole pool, the orientation check every 100 steps, lr x 0.1 at 75% and
// 90% of the iterations, M ramped from a quarter of its value in four levels
// until 75% (model/tool/schedule.h). The library never prints: the loop below reports
// progress itself. Exits non-zero if L_6D (Eq. 7) does not drop tenfold.
#include <cmath>
#include <cstdio>
#include <exception>

#include "engine/parallel.h"
#include "model/tool/trainer.h"

using namespace jsa;

int main() try {
  // The training targets: P x 6 rows [x_S, n_S] with unit normals. On the unit
  // sphere a point is its own normal.
  Rng rng(1);
  Block<double> pool(20000, 6);
  for (Index i = 0; i < pool.rows(); ++i) {
    const double x = rng.normal(), y = rng.normal(), z = rng.normal();  // isotropic direction
    const double r = std::sqrt(x * x + y * y + z * z);
    pool.row(i) << x / r, y / r, z / r, x / r, y / r, z / r;
  }

  FitOptions o;
  o.atlas.gaussians = 256;    // K (paper: 10^4)
  o.atlas.width = 32;         // hidden units of phi and psi (paper: 256)
  o.atlas.hidden_layers = 3;  // (paper: 5)
  o.points = 256;             // M, points per step on P and on the shape (paper: 10^4)
  o.iterations = 400;
  o.lr = 1e-3;
  // Blocks this small are not worth splitting, and on a busy machine an OpenMP
  // team waiting at barriers costs more than the work. The library reads the
  // thread count from OpenMP; applying FitOptions::threads is the caller's job.
  o.threads = 1;
  set_threads(o.threads);
  Trainer trainer(o, pool);

  double first = 0, last = 0;  // L_6D at the first step; mean over the last 50
  while (!trainer.finished()) {
    trainer.step();
    const LossTerms& l = trainer.last();
    if (trainer.iteration() == 1) first = l.surface;
    if (trainer.iteration() > o.iterations - 50) last += l.surface / 50;
    if (trainer.iteration() % 50 == 0 || trainer.iteration() == 1)
      std::printf("iter %4lld lr %.0e | total %.4f L_6D %.4f L_2D %.4f cycle %.4f %.4f iso %.2f\n",
                  static_cast<long long>(trainer.iteration()), trainer.learning_rate(), l.total,
                  l.surface, l.chart, l.cycle_2d, l.cycle_6d, l.isometry);
  }
  std::printf("L_6D: %.4f at the first step, %.4f over the last 50\n", first, last);
  const bool ok = last < 0.1 * first && last < 0.1;
  std::printf("%s\n", ok ? "ok" : "FAILED");
  return ok ? 0 : 1;
} catch (const std::exception& e) {  // JSA_CHECK and InputError throw
  std::fprintf(stderr, "example_fit_sphere: %s\n", e.what());
  return 1;
}
