#include "losses/isometry.h"

#include <cmath>

#include "engine/ops.h"

namespace jsa {

template <class T>
Var isometry_loss(Tape<T>& t, Var du, Var dv) {
  const Var e = offset(t, row_dot(t, du, du), T(-1));  // E - 1
  const Var g = offset(t, row_dot(t, dv, dv), T(-1));  // G - 1
  const Var f = row_dot(t, du, dv);                    // F
  const Var per_point = add(t, add(t, square(t, e), square(t, g)), scale(t, square(t, f), T(2)));
  return mean(t, per_point);
}

template <class T>
Var metric_mismatch(Tape<T>& t, Var du_a, Var dv_a, Var du_b, Var dv_b) {
  const Var e = sub(t, row_dot(t, du_a, du_a), row_dot(t, du_b, du_b));  // E_a - E_b
  const Var g = sub(t, row_dot(t, dv_a, dv_a), row_dot(t, dv_b, dv_b));  // G_a - G_b
  const Var f = sub(t, row_dot(t, du_a, dv_a), row_dot(t, du_b, dv_b));  // F_a - F_b
  const Var per_point = add(t, add(t, square(t, e), square(t, g)), scale(t, square(t, f), T(2)));
  return mean(t, per_point);
}

template <class T>
Var conformal_metric_mismatch(Tape<T>& t, Var du_a, Var dv_a, Var du_b, Var dv_b) {
  const T root2 = T(std::sqrt(2.0));
  auto form = [&](Var du, Var dv) {  // g = (E, sqrt2 F, G) / |(E, sqrt2 F, G)|, N x 3
    return row_normalize(t, concat_cols(t, {row_dot(t, du, du), scale(t, row_dot(t, du, dv), root2),
                                            row_dot(t, dv, dv)}));
  };
  const Var d = sub(t, form(du_a, dv_a), form(du_b, dv_b));
  return mean(t, row_dot(t, d, d));
}

template Var conformal_metric_mismatch<float>(Tape<float>&, Var, Var, Var, Var);
template Var conformal_metric_mismatch<double>(Tape<double>&, Var, Var, Var, Var);
template Var metric_mismatch<float>(Tape<float>&, Var, Var, Var, Var);
template Var metric_mismatch<double>(Tape<double>&, Var, Var, Var, Var);
template Var isometry_loss<float>(Tape<float>&, Var, Var);
template Var isometry_loss<double>(Tape<double>&, Var, Var);

}  // namespace jsa
