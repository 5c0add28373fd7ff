#include "model/atlas.h"

#include <algorithm>

#include "engine/ops.h"

namespace jsa {

template <class T>
Atlas<T>::Atlas(const AtlasOptions& o) : options_(o) {
  JSA_CHECK(o.shapes >= 1 && (o.shapes == 1 || o.code_size > 0), "bad collection size");
  const int d = o.shapes > 1 ? o.code_size : 0;
  domain = Domain<T>(params, DomainOptions{o.gaussians, o.gaussian_noise});
  JSA_CHECK(o.deform_layers >= 0, "deform_layers must be >= 0");
  if (d > 0 && o.deform_layers > 0)
    phi = Parametrization<T>(
        params, MlpShape{2, 3, o.width, o.hidden_layers, 0, 0, o.softplus_beta}, T(o.alpha),
        MlpShape{o.deform_domain ? 5 : 3, 3, o.width, o.deform_layers, d, o.code_layer,
                 o.softplus_beta});
  else
    phi = Parametrization<T>(
        params, MlpShape{2, 3, o.width, o.hidden_layers, d, o.code_layer, o.softplus_beta},
        T(o.alpha));
  JSA_CHECK(o.chart_width >= 0, "chart_width must be >= 0");
  JSA_CHECK(o.chart_fourier >= 0 && o.chart_fourier_sigma > 0,
            "chart_fourier must be >= 0 and chart_fourier_sigma > 0");
  psi = Chart<T>(params,
                 MlpShape{6 + 2 * o.chart_fourier, 2, o.chart_width > 0 ? o.chart_width : o.width,
                          o.hidden_layers, d, o.code_layer, o.softplus_beta},
                 o.chart_fourier, o.chart_fourier_sigma);
  if (d > 0) {
    phi_codes_ = params.add("codes.phi", o.shapes, d);
    psi_codes_ = params.add("codes.psi", o.shapes, d);
  }
  JSA_CHECK(o.deform_nodes >= 0, "deform_nodes must be >= 0");
  if (d > 0 && o.deform_nodes > 0) {
    // t_k,i for every shape, one n-row block per shape; the centres c_k and
    // the kernels' width sigma are placed once (Trainer::finish_template) and
    // read as constants, so Adam never moves them (their gradient is zero).
    phi_nodes_ = params.add("nodes.phi", Index(o.shapes) * o.deform_nodes, 3);
    phi.set_nodes(0, params.add("nodes.centres", o.deform_nodes, 2),
                  params.add("nodes.sigma", 1, 1));
  }
  JSA_CHECK(o.fine_nodes >= 0, "fine_nodes must be >= 0");
  if (d > 0 && o.fine_nodes > 0) {
    fine_nodes_ = params.add("nodes.fine.phi", Index(o.shapes) * o.fine_nodes, 3);
    phi.set_nodes(1, params.add("nodes.fine.centres", o.fine_nodes, 2),
                  params.add("nodes.fine.sigma", 1, 1));
  }
}

template <class T>
NodeFields Atlas<T>::phi_nodes(Tape<T>& t, int shape) {
  JSA_CHECK(shape >= 0 && shape < options_.shapes, "shape " << shape << " of " << options_.shapes);
  NodeFields fields;
  const int blocks[2] = {phi_nodes_, fine_nodes_};
  const Index counts[2] = {options_.deform_nodes, options_.fine_nodes};
  for (int f = 0; f < 2; ++f)
    if (blocks[f] >= 0)
      fields[size_t(f)] =
          slice_rows(t, params.on(t, blocks[f]), Index(shape) * counts[f], counts[f]);
  return fields;
}

template <class T>
Var Atlas<T>::phi_code(Tape<T>& t, int shape) {
  if (phi_codes_ < 0) return Var{};
  JSA_CHECK(shape >= 0 && shape < options_.shapes, "shape " << shape << " of " << options_.shapes);
  return slice_rows(t, params.on(t, phi_codes_), shape, 1);  // row `shape` (no index vector)
}

template <class T>
Var Atlas<T>::psi_code(Tape<T>& t, int shape) {
  if (psi_codes_ < 0) return Var{};
  JSA_CHECK(shape >= 0 && shape < options_.shapes, "shape " << shape << " of " << options_.shapes);
  return slice_rows(t, params.on(t, psi_codes_), shape, 1);  // row `shape` (no index vector)
}

template <class T>
void Atlas<T>::initialize(Rng& rng) {
  // Separate streams, so changing one network's size leaves the others' draws alone.
  Rng r_mu = rng.stream(1), r_phi = rng.stream(2), r_psi = rng.stream(3);
  domain.initialize(params, r_mu);
  phi.initialize(params, r_phi);
  psi.initialize(params, r_psi);
  if (phi_codes_ >= 0) {
    // DeepSDF's auto-decoder initialisation: small Gaussian codes.
    Rng r_codes = rng.stream(4);
    for (int b : {phi_codes_, psi_codes_}) {
      auto c = params.value(b);
      for (Index i = 0; i < c.size(); ++i) c.data()[i] = T(0.01 * r_codes.normal());
    }
  }
}

template class Atlas<float>;
template class Atlas<double>;

void evaluate_surface(Atlas<float>& atlas, const Block<double>& uv, Block<double>& points,
                      Block<double>& normals, int shape, Block<double>* du, Block<double>* dv) {
  points.resize(uv.rows(), 3);
  normals.resize(uv.rows(), 3);
  if (du) du->resize(uv.rows(), 3);
  if (dv) dv->resize(uv.rows(), 3);
  Tape<float> t;
  // 2048 rows a batch: the tape of one batch (value and two tangent rows per
  // point through every layer) is 32 MB at width 128; at 8192 it was 126 MB,
  // on top of the trainer's, and set the default fit's peak memory.
  const Index batch = 2048;
  for (Index b = 0; b < uv.rows(); b += batch) {
    const Index n = std::min(batch, uv.rows() - b);
    t.clear();
    Var x = t.constant(uv.middleRows(b, n).cast<float>());
    SurfacePoints s = atlas.phi.evaluate(t, atlas.params, x, true, atlas.phi_code(t, shape),
                                         atlas.phi_nodes(t, shape));
    points.middleRows(b, n) = t.value(s.points).cast<double>();
    normals.middleRows(b, n) = t.value(s.normals).cast<double>().rowwise().normalized();
    if (du) du->middleRows(b, n) = t.value(s.du).cast<double>();
    if (dv) dv->middleRows(b, n) = t.value(s.dv).cast<double>();
  }
}

void sample_reconstruction(Atlas<float>& atlas, Index count, Rng& rng, Block<double>& uv,
                           Block<double>& points, Block<double>& normals, int shape) {
  Tape<float> t;
  Var x = atlas.domain.sample(t, atlas.params, count, rng);
  uv = t.value(x).cast<double>();
  evaluate_surface(atlas, uv, points, normals, shape);
}

}  // namespace jsa
