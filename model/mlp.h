// A multi-layer perceptron: `hidden_layers` layers of `width` (ReLU, or softplus), then a
// linear output layer. The paper uses 5 hidden layers of 256 for both phi and
// psi, no batch norm (Sec. 3, implementation details).
//
// forward() runs on plain rows (N x in) or on stacked-tangent rows (3N x in,
// see engine/tangents.h): with value_rows = N the bias goes to the first N rows
// only and every ReLU takes its mask from them, so each layer is one GEMM that
// carries the value and both Jacobian columns at once.
//
// Latent codes (collections, Sec. 3.4): an MLP built with code_size = D > 0
// takes a 1 x D code f with every call. Concatenating f to each input row,
// [x, f] W = x W_x + f W_f, is the same as adding the row f W_f to the first
// layer's bias, so that is how it is computed: one 1 x D by D x width product
// per call instead of D extra columns in the first GEMM. As a bias, it touches
// only the value rows: the code does not change with (u, v).
// code_layer = 1 instead adds f W_f after the first layer (to the second
// layer's pre-activation): the other conditioning the paper's Sec. 3.4 leaves
// open. Both are measured in docs/results.md; input (0) is the default.
//
// Activation: ReLU as the paper, or softplus (softplus_beta > 0). With ReLU phi
// is piecewise linear, so its normals (Eq. 2) are piecewise constant and jump
// between the linear pieces; softplus makes them continuous. Measured against
// each other in docs/results.md.
#pragma once
#include <string>
#include <vector>

#include "engine/parameters.h"
#include "engine/rng.h"
#include "engine/tape.h"

namespace jsa {

struct MlpShape {
  int in = 2;             // input features
  int out = 3;            // output features
  int width = 256;        // units per hidden layer
  int hidden_layers = 5;  // activation layers before the linear output layer
  int code_size = 0;      // D: latent code width (0: no code)
  int code_layer = 0;     // the layer whose bias takes f W_f: 0 (= concatenation at the input) or 1
  double softplus_beta = 0;  // 0: ReLU (the paper); > 0: softplus log(1 + e^(beta z)) / beta
};

template <class T>
class Mlp {
 public:
  Mlp() = default;
  // Registers the weights "<name>.w<k>" (in x out) and biases "<name>.b<k>" (1 x out).
  Mlp(Parameters<T>& params, const std::string& name, const MlpShape& shape);
  // PyTorch's nn.Linear default, as the authors' code used: W, b ~ U(-1/sqrt(in), 1/sqrt(in)).
  void initialize(Parameters<T>& params, Rng& rng) const;
  // Multiplies the output layer's weights and bias (a residual branch that starts small).
  void scale_output_layer(Parameters<T>& params, T factor) const;
  // y = f(x) or f([x, code]). value_rows < 0: plain rows. value_rows = N: x is
  // [value; tangents...]. code: 1 x code_size (required iff code_size > 0).
  Var forward(Tape<T>& t, Parameters<T>& params, Var x, Index value_rows = -1, Var code = {}) const;
  const MlpShape& shape() const { return shape_; }
  // Multiply-adds of one forward pass over `rows` rows (for GFLOP/s reports).
  double flops(Index rows) const;

 private:
  MlpShape shape_;
  std::vector<int> weight_, bias_;  // parameter indices per layer
  int code_weight_ = -1;            // W_f (code_size x width)
};

}  // namespace jsa
