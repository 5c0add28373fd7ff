// Beyond the paper: see model/heuristics/orientation.h (one switch in FitOptions).
#include "model/heuristics/orientation.h"

#include <string>
#include <utility>

#include "io/geometry/nearest.h"

namespace jsa {
namespace {

// Swaps rows a and b (or, with columns = true, columns a and b) of parameter
// `index` in the flat buffer `values`, which is laid out like params.values().
template <class T>
void swap_in(const Parameters<T>& params, int index, std::vector<T>& values, bool columns) {
  const auto& e = params.entry(index);
  Eigen::Map<Block<T>> m(values.data() + e.offset, e.rows, e.cols);
  if (columns)
    m.col(0).swap(m.col(1));
  else
    m.row(0).swap(m.row(1));
}

}  // namespace

template <class T>
void mirror_domain(Atlas<T>& atlas, const std::vector<std::vector<T>*>& aligned) {
  Parameters<T>& p = atlas.params;
  const int psi_out = atlas.options().hidden_layers;
  const int phi_w0 = p.find("phi.w0"), psi_w = p.find("psi.w" + std::to_string(psi_out)),
            psi_b = p.find("psi.b" + std::to_string(psi_out)), mu = atlas.domain.means();
  JSA_CHECK(phi_w0 >= 0 && psi_w >= 0 && psi_b >= 0, "mirror_domain: the atlas lacks phi or psi");
  // With latent codes, f W_f is added to the pre-activation of layer code_layer
  // (model/mlp.h). When that layer is psi's output layer (depth 1 with
  // code_layer 1, or depth 0), W_f's columns are psi's outputs (u, v) too.
  const int psi_wf =
      atlas.has_codes() && atlas.options().code_layer == psi_out ? p.find("psi.wf") : -1;
  JSA_CHECK(psi_wf >= 0 || !atlas.has_codes() || atlas.options().code_layer < psi_out,
            "mirror_domain: the atlas lacks psi's code weights");
  std::vector<std::vector<T>*> buffers{&p.values()};
  for (std::vector<T>* b : aligned)
    if (b && !b->empty()) buffers.push_back(b);  // Adam's moments are empty before the first step
  for (std::vector<T>* b : buffers) {
    JSA_CHECK(b->size() == p.size(), "mirror_domain: a buffer does not match the parameters");
    swap_in(p, phi_w0, *b, false);  // phi's inputs (u, v): rows of W_0
    swap_in(p, mu, *b, true);       // mu_k = (u, v): columns of K x 2
    swap_in(p, psi_w, *b, true);    // psi's outputs (u, v): columns of the last layer
    swap_in(p, psi_b, *b, true);
    if (psi_wf >= 0) swap_in(p, psi_wf, *b, true);
  }
}

double back_facing_fraction(Atlas<float>& atlas, const Block<float>& targets, Index count, Rng& rng,
                            int shape) {
  JSA_CHECK(targets.cols() == 6 && targets.rows() > 0, "targets must be M x 6");
  Block<double> uv, points, normals;
  sample_reconstruction(atlas, count, rng, uv, points, normals, shape);
  const Block<double> target_points = targets.leftCols(3).cast<double>();
  std::vector<int> nn;
  nearest(points, target_points, nn);
  Index back = 0;
  for (Index i = 0; i < points.rows(); ++i)
    back += normals.row(i).dot(targets.row(nn[size_t(i)]).rightCols(3).cast<double>()) < 0 ? 1 : 0;
  return double(back) / double(points.rows());
}

template void mirror_domain<float>(Atlas<float>&, const std::vector<std::vector<float>*>&);
template void mirror_domain<double>(Atlas<double>&, const std::vector<std::vector<double>*>&);

}  // namespace jsa
