#include "model/parametrize.h"

#include "engine/ops.h"
#include "engine/tangents.h"

namespace jsa {

namespace {

// sum_k w_k(x) t_k on stacked rows [x; dx_1; ...] (value block m rows; m < 0:
// values only), with the normalised kernels (a partition of unity, so a
// field the t_k share, a shift, is reproduced exactly wherever x lies)
//   w_k(x) = g_k(x) / sum_j g_j(x),   g_k(x) = exp(-|x - c_k|^2 / (2 sigma^2)).
// The tangent rows carry dw_k = grad w_k . dx, so the Jacobian of the
// displacement comes out of the same pass as phi's (Eq. 1): one kernel op
// (engine/ops_kernels.cpp), then one GEMM with the displacements t_k.
template <class T>
Var node_displacement(Tape<T>& t, Var x_rows, Index m, const Block<T>& centres, T sigma,
                      Var displacements) {
  return linear(t, gaussian_weights_stacked(t, x_rows, m, centres, sigma), displacements, Var{});
}

}  // namespace

template <class T>
SurfacePoints Parametrization<T>::evaluate(Tape<T>& t, Parameters<T>& params, Var x,
                                           bool with_jacobian, Var code,
                                           const NodeFields& nodes) const {
  SurfacePoints s;
  // y + sum over the placed fields of their displacements (value rows m; m < 0: values only)
  auto displaced = [&](Var y, Var x_rows, Index m) {
    for (size_t f = 0; f < fields_.size(); ++f) {
      const Field& field = fields_[f];
      if (!nodes[f].valid() || field.centres < 0) continue;
      const T sigma = params.value(field.sigma)(0, 0);
      if (sigma > 0)
        y = add(t, y,
                node_displacement(t, x_rows, m, Block<T>(params.value(field.centres)), sigma,
                                  nodes[f]));
    }
    return y;
  };
  // phi_i(x) = p + D(p, f_i), p = phi(x), when phi deforms one surface per shape
  // (D(p, x, f_i) when D also reads the domain point: x holds its rows' x).
  const bool reads_domain = deforms_ && deform_.shape().in == 5;
  auto deformed = [&](Var p, Var x_rows, Index value_rows) {
    const Var in = reads_domain ? concat_cols(t, {p, x_rows}) : p;
    return add(t, p, deform_.forward(t, params, in, value_rows, code));
  };
  const Var phi_code = deforms_ ? Var{} : code;
  if (!with_jacobian) {
    s.points = mlp_.forward(t, params, x, -1, phi_code);
    if (deforms_) s.points = deformed(s.points, x, -1);
    s.points = displaced(s.points, x, -1);
    return s;
  }
  // [x; e_u; e_v] -> [phi(x); J_u; J_v]: one pass, 3M rows (Eq. 1).
  const Index m = t.rows(x);
  const Var x3 = stack_tangents(t, x);
  Var y3 = mlp_.forward(t, params, x3, m, phi_code);
  if (deforms_) y3 = deformed(y3, x3, m);  // [p + D; (I + dD/dp) J_u (+ dD/du); ...]
  y3 = displaced(y3, x3, m);               // [.. + sum w_k t_k; .. + sum dw_k/du t_k; ...]
  Stacked y = unstack(t, y3);
  s.points = y.value;
  s.du = y.du;
  s.dv = y.dv;
  // n = alpha (J_u x J_v) / |J_u x J_v|   (Eq. 2)
  s.normals = scale(t, row_normalize(t, cross3(t, s.du, s.dv)), alpha_);
  // phi6(x) = [phi(x), n]   (Eq. 3)
  s.phi6 = concat_cols(t, {s.points, s.normals});
  return s;
}

template class Parametrization<float>;
template class Parametrization<double>;

}  // namespace jsa
