#include "model/tool/evaluate.h"

#include <functional>
#include <string>

#include "engine/check.h"
#include "io/geometry/surface_sampling.h"

namespace jsa {
namespace {

// One draw: M' fresh samples of the shape on each side (a, the reference; b,
// the floor's second sample) against the M' predicted points.
Evaluation evaluate_draw(const Block<double>& pp, const Block<double>& pn, const Mesh& shape,
                         const Normalization& normalization, Index samples, uint64_t seed) {
  Rng rng_a(seed, 11), rng_b(seed, 12);
  SurfaceSamples a = sample_surface(shape, samples, rng_a);
  SurfaceSamples b = sample_surface(shape, samples, rng_b);
  const Block<double> ap = normalization.to_unit(a.points), bp = normalization.to_unit(b.points);
  Evaluation e;
  const Block<double> an = normalization.normals_to_unit(a.normals),
                      bn = normalization.normals_to_unit(b.normals);
  e.fit = surface_metrics(pp, pn, ap, an);
  e.floor = surface_metrics(bp, bn, ap, an);
  e.fit_emd = emd_metrics(pp, pn, ap, an);
  e.floor_emd = emd_metrics(bp, bn, ap, an);
  return e;
}

void accumulate(SurfaceMetrics& sum, const SurfaceMetrics& m, double w) {
  sum.chamfer_spatial += w * m.chamfer_spatial;
  sum.chamfer_normal += w * m.chamfer_normal;
  sum.back_facing += w * m.back_facing;
}

void accumulate(EmdMetrics& sum, const EmdMetrics& m, double w) {
  sum.spatial += w * m.spatial;
  sum.spatial_squared += w * m.spatial_squared;
  sum.normal += w * m.normal;
  sum.seconds += m.seconds;  // the total time, not a mean
}

// The mean of every metric over o.draws draws, draw d from seed o.seed + d
// (so one draw is what a single evaluation with that seed gives).
Evaluation mean_over_draws(const EvaluationOptions& o,
                           const std::function<Evaluation(uint64_t)>& draw) {
  if (o.draws < 1)
    throw InputError("evaluation: draws must be at least 1, got " + std::to_string(o.draws));
  Evaluation mean;
  const double w = 1.0 / double(o.draws);
  for (int d = 0; d < o.draws; ++d) {
    const Evaluation e = draw(o.seed + uint64_t(d));
    accumulate(mean.fit, e.fit, w);
    accumulate(mean.floor, e.floor, w);
    accumulate(mean.fit_emd, e.fit_emd, w);
    accumulate(mean.floor_emd, e.floor_emd, w);
    mean.chamfer_ratio.push_back(e.fit.chamfer_spatial / e.floor.chamfer_spatial);
    mean.emd_ratio.push_back(e.fit_emd.spatial / e.floor_emd.spatial);
  }
  return mean;
}

}  // namespace

Evaluation evaluate_reconstruction(Atlas<float>& atlas, const Mesh& shape,
                                   const Normalization& normalization, const EvaluationOptions& o,
                                   int index) {
  return mean_over_draws(o, [&](uint64_t seed) {
    Rng rng_p(seed, 10);
    Block<double> uv, pp, pn;
    sample_reconstruction(atlas, o.samples, rng_p, uv, pp, pn, index);
    return evaluate_draw(pp, pn, shape, normalization, o.samples, seed);
  });
}

Evaluation evaluate_points(const Block<double>& pp, const Block<double>& pn, const Mesh& shape,
                           const Normalization& normalization, const EvaluationOptions& o) {
  return mean_over_draws(o, [&](uint64_t seed) {
    return evaluate_draw(pp, pn, shape, normalization, o.samples, seed);
  });
}

}  // namespace jsa
