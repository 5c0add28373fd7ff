// Beyond the paper: a closed starting shape for phi and psi instead of the
// paper's random start; one switch, FitOptions::wrap_steps (--wrap, 0 = off,
// the default).
//
// A starting shape for phi and psi: a closed wrap around the target.
//
// The paper starts from PyTorch's random weights, where phi maps the domain to a
// small, nearly flat sheet. Chamfer (Eq. 7) then drapes that sheet over the
// shape: it covers the side the sheet faced first and reaches the other side by
// folding. On a blob (a teddy) the fold is a narrow seam; on thin parts (an
// ant's legs) a leg's top and bottom come from one folded strip of the domain,
// half of it back-facing, and no small gradient step undoes a fold. This
// orientation error is a topological one, so we remove it at the start: before
// training, phi is fitted to a map W of the unit square onto an ellipsoid around
// the shape that covers it once, outward-facing everywhere, and psi to its inverse.
// Training then shrinks a closed surface onto the shape instead of unfolding an
// open one.
//
// W (the octahedral map): s = 2u - 1, t = 2v - 1 in [-1, 1]^2;
//   |s| + |t| <= 1:  o = (s, t, 1 - |s| - |t|)                      (upper half)
//   otherwise:       o = (sgn s (1 - |t|), sgn t (1 - |s|), 1 - |s| - |t|)
// then d = o / |o| on the unit sphere and W(u, v) = c + R diag(a) d, with c the
// targets' mean, R their principal axes (a rotation) and a = sqrt(3 lambda)
// (the half-widths of a box with the same second moments), each at least a
// fifth of the largest so the ellipsoid never flattens to a disc. The map is
// continuous, one-to-one inside the square, folds the square's four edges onto
// four seams, and J_u x J_v points outward on every face (tested).
//
// The fit is plain regression, no Chamfer: phi(u, v) -> W(u, v) and
// psi(W(u, v), alpha n_W) -> (u, v), mean squared error, u, v uniform in the
// square, `steps` Adam steps with their own moments. In a collection each
// shape's code is fitted to its own ellipsoid.
#pragma once
#include <functional>
#include <vector>

#include "model/atlas.h"

namespace jsa {

// W(u, v) and its outward unit normal for the unit sphere (c = 0, R = I, a = 1).
void octahedral_sphere(double u, double v, double point[3], double normal[3]);

// The ellipsoid of one target pool (rows [x, n], any normal scale).
struct Ellipsoid {
  double center[3] = {0, 0, 0};
  double axes[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};  // columns: principal directions, det = +1
  double radii[3] = {1, 1, 1};
  void map(double u, double v, double point[3], double normal[3]) const;
};
Ellipsoid enclosing_ellipsoid(const Block<float>& pool);

struct WrapReport {
  double phi_error = 0;  // final RMS |phi - W| (unit frame)
  double psi_error = 0;  // final RMS |psi - (u, v)|
  int steps = 0;         // steps taken (fewer than asked if cancelled)
};

// Fits phi and psi of `atlas` to the wraps of `pools` (one per shape), as above.
// `cancelled`, if given, is asked before every step (Ctrl-C in the CLI).
WrapReport wrap_initialize(Atlas<float>& atlas, const std::vector<Block<float>>& pools, int steps,
                           Index points, double lr, Rng& rng,
                           const std::function<bool()>& cancelled = {});

}  // namespace jsa
