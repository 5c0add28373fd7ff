// Lowering a chart's distortion without ever inverting a triangle: the
// symmetric Dirichlet energy (Smith & Schaefer 2015)
//     D = sum_T A_T (|J_T|_F^2 + |J_T^-1|_F^2) / sum_T A_T     (4 for an isometry)
// minimised by SLIM's local-global iterations (Rabinovich, Poranne, Panozzo,
// Sorkine-Hornung 2017, "Scalable Locally Injective Mappings"): the local step
// takes each triangle's closest rotation and reweights it from the energy's
// singular-value derivatives, the global step solves one sparse weighted
// least-squares system (sparse_spd.h: CHOLMOD or Eigen, pattern analysed once). The
// step along the result is capped at 0.8 of the largest that keeps every
// triangle's signed area positive (Smith & Schaefer 2015, Sec. 4: a quadratic in
// the step per triangle), then halved until the energy decreases. Started from
// an injective map it stays locally injective; the caller checks the boundary.
#pragma once
#include <functional>
#include <vector>

#include "io/geometry/mesh.h"
#include "io/geometry/triangle_frame.h"

namespace jsa {

struct SlimOptions {
  int max_iterations = 25;  // local-global iterations at most
  double max_seconds =
      20;  // wall-time cap per chart (a safety net; the iteration cap normally ends first)
  double tolerance = 1e-3;     // stop when an iteration lowers D by less than this fraction
  double step_fraction = 0.8;  // of the largest flip-free step
};

struct SlimReport {
  int iterations = 0;
  double energy_start = 0, energy_end = 0;  // D as above (infinite if a triangle is inverted)
  bool time_capped = false;
};

std::vector<TriangleFrame> triangle_frames(const Block<double>& positions, const Faces& local);

// D of uv on the chart; +infinity if some triangle has signed area <= 0.
double symmetric_dirichlet(const std::vector<TriangleFrame>& frames, const Faces& local,
                           const Block<double>& uv);

// The largest t in (0, inf] such that every triangle of uv + s d, 0 <= s < t,
// keeps a positive signed area (uv must have them all positive).
double max_injective_step(const Faces& local, const Block<double>& uv, const Block<double>& d);

// Minimises D in place from an injective uv (every triangle counter-clockwise).
// `accept`, if given, is asked about each new iterate: on false the iterations
// stop at the previous one (e.g. the chart's boundary started to overlap itself).
SlimReport slim_symmetric_dirichlet(const Block<double>& positions, const Faces& local,
                                    Block<double>& uv, const SlimOptions& options = {},
                                    const std::function<bool(const Block<double>&)>& accept = {});

}  // namespace jsa
