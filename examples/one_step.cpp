// Example: one training step of the method, unrolled (what Trainer::step does,
// model/tool/trainer.cpp): sample P, psi on the targets, phi with stacked
// tangents, the five losses of Eq. 5, backward, one Adam step. Prints each
// block's shape and each loss. Tiny sizes (M = 32 points, K = 64, 2 x 16 MLPs).
// Exits non-zero unless (1) the unrolled total equals the library's
// single_shape_objective on the same random draws and (2) the step lowers it.
#include <cmath>
#include <cstdio>
#include <exception>
#include <utility>

#include "engine/adam.h"
#include "engine/tangents.h"
#include "losses/chamfer.h"
#include "losses/cycle.h"
#include "losses/isometry.h"
#include "losses/repulsion.h"
#include "model/objective.h"

using namespace jsa;

// L_single (Eq. 5) on the tape, with the library's default weights (the
// paper's, as means; `jsatlas fit` lowers lambda_cycle to 0.1). rng is a copy:
// calling twice with the same rng gives the same draws.
Var step_loss(Tape<double>& t, Atlas<double>& a, const Block<double>& targets, Rng rng,
              bool print) {
  Parameters<double>& p = a.params;
  const Index m = targets.rows();
  auto show = [&](const char* what, Var v) {
    if (print) std::printf("  %-40s %3ld x %ld\n", what, long(t.rows(v)), long(t.cols(v)));
  };
  const Var x_p = a.domain.sample(t, p, m, rng);  // x_P = mu_i + e (Eq. 4): differentiable in mu
  const Var s6 = t.constant(targets);
  const Var u_s = a.psi.evaluate(t, p, s6);  // u_S = psi(x_S, alpha n_S)
  // phi on x_P and u_S in one pass (the 6D cycle needs phi6(u_S)), 3 row blocks each.
  const Var in = stack_tangents(t, concat_rows(t, {x_p, u_s}));
  const Var out = a.phi.mlp().forward(t, p, in, /*value_rows=*/2 * m);
  const Stacked y = unstack(t, out);
  const Var n = scale(t, row_normalize(t, cross3(t, y.du, y.dv)), a.phi.alpha());  // Eq. 2
  const Var phi6 = concat_cols(t, {y.value, n});                                   // Eq. 3
  const Var phi6_p = slice_rows(t, phi6, 0, m), phi6_s = slice_rows(t, phi6, m, m);
  const std::pair<const char*, Var> blocks[] = {{"x_P ~ P (Eq. 4)", x_p},
                                                {"targets [x_S, alpha n_S]", s6},
                                                {"u_S = psi(targets)", u_s},
                                                {"[x; e_u; e_v], x = [x_P; u_S]", in},
                                                {"[phi; J_u; J_v] = MLP(stacked rows)", out},
                                                {"phi6 = [phi, n]", phi6}};
  for (const auto& [what, v] : blocks) show(what, v);
  const LossWeights w;
  const double lambda[] = {w.surface, w.chart, w.cycle, w.cycle, w.isometry, w.repulsion};
  const Var terms[] = {
      chamfer(t, phi6_p, s6),                                                  // L_6D  (Eq. 7)
      chamfer(t, u_s, x_p),                                                    // L_2D  (Eq. 8)
      mean_squared_distance(t, x_p, a.psi.evaluate(t, p, phi6_p)),             // L_cycle 2D (Eq. 9)
      mean_squared_distance(t, s6, phi6_s),                                    // L_cycle 6D (Eq. 9)
      isometry_loss(t, slice_rows(t, y.du, 0, m), slice_rows(t, y.dv, 0, m)),  // L_iso (Eq. 10)
      repulsion(t, p.on(t, a.domain.means()), a.domain.sigma())};              // L_rep (Eq. 11)
  const char* names[] = {"L_6D", "L_2D", "L_cycle 2D", "L_cycle 6D", "L_iso", "L_rep"};
  Var total = scale(t, terms[0], lambda[0]);
  for (int k = 1; k < 6; ++k) total = add(t, total, scale(t, terms[k], lambda[k]));
  for (int k = 0; print && k < 6; ++k)
    std::printf("  %-10s %.6f  x lambda %g\n", names[k], t.scalar(terms[k]), lambda[k]);
  return total;
}

int main() try {
  AtlasOptions o;  // the library's defaults are the paper's; made tiny here
  o.gaussians = 64, o.width = 16, o.hidden_layers = 2, o.alpha = 0.08, o.softplus_beta = 40;
  Atlas<double> atlas(o);
  Rng rng(1);
  atlas.initialize(rng);
  Block<double> targets(32, 6);  // M points on the unit sphere: a point is its own normal
  for (Index i = 0; i < targets.rows(); ++i) {
    const double x = rng.normal(), y = rng.normal(), z = rng.normal(),
                 r = std::sqrt(x * x + y * y + z * z);
    targets.row(i) << x / r, y / r, z / r, o.alpha * x / r, o.alpha * y / r, o.alpha * z / r;
  }
  const Rng draws(7);  // the step's random draws, reused below
  Tape<double> t;
  const Var loss = step_loss(t, atlas, targets, draws, true);
  const double before = t.scalar(loss);
  std::printf("  %-10s %.6f   (%d tape nodes)\n", "L_single", before, int(t.size()));

  Tape<double> lib;  // (1) the library's objective on the same draws
  Rng same = draws;
  const double library =
      lib.scalar(single_shape_objective(lib, atlas, 0, targets, 32, same, {}, nullptr));
  atlas.params.zero_grad();
  t.backward(loss);  // every gradient lands in params.grads(), one flat buffer
  double g2 = 0;
  for (double g : atlas.params.grads()) g2 += g * g;
  Adam<double> adam;
  adam.step(atlas.params, 1e-3);
  Tape<double> again;  // (2) the same draws after the step
  const double after = again.scalar(step_loss(again, atlas, targets, draws, false));
  std::printf("|grad| %.4f over %zu parameters; library total %.6f; after one Adam step %.6f\n",
              std::sqrt(g2), atlas.params.size(), library, after);
  const bool ok = std::abs(library - before) < 1e-12 * before && after < before;
  std::printf("%s\n", ok ? "ok" : "FAILED");
  return ok ? 0 : 1;
} catch (const std::exception& e) {  // JSA_CHECK and InputError throw
  std::fprintf(stderr, "example_one_step: %s\n", e.what());
  return 1;
}
