#include "model/mlp.h"

#include <cmath>

#include "engine/ops.h"

namespace jsa {

template <class T>
Mlp<T>::Mlp(Parameters<T>& params, const std::string& name, const MlpShape& shape) : shape_(shape) {
  JSA_CHECK(shape.in > 0 && shape.out > 0 && shape.width > 0 && shape.hidden_layers >= 0,
            "bad MLP shape");
  int in = shape.in;
  for (int k = 0; k <= shape.hidden_layers; ++k) {
    const int out = k == shape.hidden_layers ? shape.out : shape.width;
    weight_.push_back(params.add(name + ".w" + std::to_string(k), in, out));
    bias_.push_back(params.add(name + ".b" + std::to_string(k), 1, out));
    in = out;
  }
  JSA_CHECK(shape.softplus_beta >= 0,
            "softplus beta must be >= 0 (0: ReLU), got " << shape.softplus_beta);
  JSA_CHECK(shape.code_layer == 0 || (shape.code_layer == 1 && shape.hidden_layers >= 1),
            "the code enters at layer 0 or 1 (after the first), got " << shape.code_layer);
  if (shape.code_size > 0) {
    const int out = shape.code_layer < shape.hidden_layers ? shape.width : shape.out;
    code_weight_ = params.add(name + ".wf", shape.code_size, out);
  }
}

template <class T>
void Mlp<T>::initialize(Parameters<T>& params, Rng& rng) const {
  for (size_t k = 0; k < weight_.size(); ++k) {
    auto w = params.value(weight_[k]);
    auto b = params.value(bias_[k]);
    const double bound = 1.0 / std::sqrt(double(w.rows()));
    for (Index i = 0; i < w.size(); ++i) w.data()[i] = T(rng.uniform(-bound, bound));
    for (Index i = 0; i < b.size(); ++i) b.data()[i] = T(rng.uniform(-bound, bound));
  }
  if (code_weight_ >= 0) {
    // As if W_f were the code's rows of one (in + D) x out layer.
    auto w = params.value(code_weight_);
    const int in = shape_.code_layer == 0 ? shape_.in : shape_.width;
    const double bound = 1.0 / std::sqrt(double(in + shape_.code_size));
    for (Index i = 0; i < w.size(); ++i) w.data()[i] = T(rng.uniform(-bound, bound));
  }
}

template <class T>
void Mlp<T>::scale_output_layer(Parameters<T>& params, T factor) const {
  params.value(weight_.back()) *= factor;
  params.value(bias_.back()) *= factor;
}

template <class T>
Var Mlp<T>::forward(Tape<T>& t, Parameters<T>& params, Var x, Index value_rows, Var code) const {
  const Index rows = t.rows(x);
  if (value_rows < 0) value_rows = rows;
  JSA_CHECK(t.cols(x) == shape_.in,
            "MLP expects " << shape_.in << " input columns, got " << t.cols(x));
  JSA_CHECK(code.valid() == (code_weight_ >= 0),
            "a latent code is needed iff the MLP has code_size > 0");
  Var h = x;
  for (size_t k = 0; k < weight_.size(); ++k) {
    Var bias = params.on(t, bias_[k]);
    // [h, f] W = h W_h + f W_f: the code enters as part of layer code_layer's bias.
    if (int(k) == shape_.code_layer && code.valid())
      bias = add(t, bias, linear(t, code, params.on(t, code_weight_), Var{}));
    Var w = params.on(t, weight_[k]);
    const T beta = T(shape_.softplus_beta);
    if (k + 1 == weight_.size())
      h = linear(t, h, w, bias, value_rows);
    else if (beta > 0 && value_rows < rows)  // stacked rows: one op, in row tiles
      h = linear_softplus_stacked(t, h, w, bias, value_rows, beta);
    else if (beta > 0)  // plain rows (psi): two ops, faster there (docs/performance.md)
      h = softplus_stacked(t, linear(t, h, w, bias, value_rows), value_rows, beta);
    else
      h = relu_masked(t, linear(t, h, w, bias, value_rows), value_rows);
  }
  return h;
}

template <class T>
double Mlp<T>::flops(Index rows) const {
  double f = 0;
  int in = shape_.in;
  for (int k = 0; k <= shape_.hidden_layers; ++k) {
    const int out = k == shape_.hidden_layers ? shape_.out : shape_.width;
    f += 2.0 * double(rows) * in * out;
    in = out;
  }
  return f;
}

template class Mlp<float>;
template class Mlp<double>;

}  // namespace jsa
