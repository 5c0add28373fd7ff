// The atlas of one shape (or, with latent codes, of a collection): the domain
// P (mu), the parametrization phi and the chart-mapping psi, with every
// learnable number in one Parameters buffer.
#pragma once
#include <memory>

#include "model/chart.h"
#include "model/domain.h"
#include "model/parametrize.h"

namespace jsa {

struct AtlasOptions {
  int gaussians = 10000;  // K, the number of Gaussians in P (paper: 10^4)
  int width = 256;        // hidden units of phi and psi (paper: 256)
  int hidden_layers = 5;  // hidden layers of phi and psi (paper: 5)
  // Hidden units of psi alone when > 0 (beyond the paper, which sizes both
  // alike): psi must invert phi everywhere, thin parts included, and the
  // chart rule trails the nearest-sample rule where it cannot (issue 19,
  // docs/collections.md, twenty-third round). 0: width.
  int chart_width = 0;
  // psi's input widened by random Fourier features of the point (beyond the
  // paper; Tancik et al., NeurIPS 2020): [p, alpha n, sin(p B), cos(p B)], B a
  // fixed 3 x F matrix of N(0, sigma^2) entries. A ReLU MLP of low-frequency
  // inputs bends slowly; the features let a narrow psi fold where phi's inverse
  // folds (two legs side by side in 3D, apart in the domain) for the cost of a
  // wider first layer (issue 19, docs/collections.md, twenty-fourth round).
  // 0: none, the paper's psi.
  int chart_fourier = 0;
  double chart_fourier_sigma = 4;
  double alpha = 0.01;         // norm of the normals fed to psi and produced by phi6 (paper: 0.01)
  bool gaussian_noise = true;  // sample P (true) or the means alone (Table 1 rows 6-8)
  int shapes = 1;              // N shapes sharing the domain (Sec. 3.4); > 1 adds latent codes
  int code_size = 256;         // D, width of f_phi,i and f_psi,i when shapes > 1 (paper: 256)
  int code_layer =
      0;  // where codes enter phi and psi: 0 the input (concatenation), 1 after the first layer
  double softplus_beta =
      0;  // activation of phi and psi: 0 ReLU (paper), > 0 softplus of that sharpness
  // Collections (beyond the paper): > 0 makes phi_i a deformation of one shared
  // surface, phi_i(x) = phi(x) + D(phi(x), f_phi,i), D an MLP of this many hidden
  // layers taking the code; phi itself then takes none (model/parametrize.h).
  // 0: the paper's phi(x, f_phi,i).
  int deform_layers = 0;
  // With deform_layers: D also reads the domain point, D(phi(x), x, f_phi,i), so
  // two sheets that touch in 3D (an arm folded on a chest) can move apart; a
  // function of the 3D point alone must move them together. false: D(phi(x), f).
  bool deform_domain = false;
  // Collections (beyond the paper): > 0 adds to phi_i a displacement with
  // local support in the domain, sum_k w_k(x) t_k,i over this many normalised
  // Gaussian kernels w_k centred in the domain (model/parametrize.h, "node
  // displacement"). A hand folded on a chest is far from the chest in the
  // domain, so a node can move it alone; D, a smooth function of the 3D
  // point, cannot. The centres are placed after the template start
  // (Trainer::finish_template); until then the term is off. 0: none.
  int deform_nodes = 0;
  // A second field of nodes next to the first (model/parametrize.h), with its
  // own centres and width, started from zero whatever the first starts from:
  // the first can carry a registration held fixed while this one learns the
  // local changes (issue 19, docs/collections.md "Two fields of nodes"). 0: none.
  int fine_nodes = 0;
};

template <class T>
class Atlas {
 public:
  explicit Atlas(const AtlasOptions& options);
  Atlas(const Atlas&) = delete;  // tape closures point into params: the atlas stays put
  Atlas& operator=(const Atlas&) = delete;

  void initialize(Rng& rng);  // mu ~ U[0,1]^2, MLPs as PyTorch's default, codes ~ N(0, 0.01^2)

  bool has_codes() const { return options_.shapes > 1; }
  int shapes() const { return options_.shapes; }
  // f_phi,i and f_psi,i (1 x D) of shape i on the tape; invalid Vars for a single shape.
  Var phi_code(Tape<T>& t, int shape);
  Var psi_code(Tape<T>& t, int shape);
  // t_k,i of shape i (n x 3) on the tape, one per field of nodes
  // (AtlasOptions::deform_nodes, fine_nodes); invalid Vars without them.
  NodeFields phi_nodes(Tape<T>& t, int shape);

  const AtlasOptions& options() const { return options_; }
  Parameters<T> params;
  Domain<T> domain;
  Parametrization<T> phi;
  Chart<T> psi;

 private:
  AtlasOptions options_;
  int phi_codes_ = -1, psi_codes_ = -1;   // N x D parameter blocks
  int phi_nodes_ = -1, fine_nodes_ = -1;  // (N n) x 3: t_k,i of each field
};

// The reconstruction (Sec. 3): phi of shape `shape` at the rows of uv (V x 2),
// in batches: points (V x 3, unit frame) and unit normals (V x 3); with du, dv
// also the Jacobian's columns dphi/du, dphi/dv (V x 3 each, Eq. 2's J).
void evaluate_surface(Atlas<float>& atlas, const Block<double>& uv, Block<double>& points,
                      Block<double>& normals, int shape = 0, Block<double>* du = nullptr,
                      Block<double>* dv = nullptr);

// `count` points of the reconstruction: uv ~ P, points = phi(uv), unit normals.
void sample_reconstruction(Atlas<float>& atlas, Index count, Rng& rng, Block<double>& uv,
                           Block<double>& points, Block<double>& normals, int shape = 0);

}  // namespace jsa
