#include "model/tool/evaluate.h"

#include "io/geometry/surface_sampling.h"

namespace jsa {

Evaluation evaluate_reconstruction(Atlas<float>& atlas, const Mesh& shape,
                                   const Normalization& normalization, const EvaluationOptions& o,
                                   int index) {
  Rng rng_p(o.seed, 10);
  Block<double> uv, pp, pn;
  sample_reconstruction(atlas, o.samples, rng_p, uv, pp, pn, index);
  return evaluate_points(pp, pn, shape, normalization, o);
}

Evaluation evaluate_points(const Block<double>& pp, const Block<double>& pn, const Mesh& shape,
                           const Normalization& normalization, const EvaluationOptions& o) {
  Rng rng_a(o.seed, 11), rng_b(o.seed, 12);
  SurfaceSamples a = sample_surface(shape, o.samples, rng_a);
  SurfaceSamples b = sample_surface(shape, o.samples, rng_b);
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

}  // namespace jsa
