#include "losses/isometry.h"

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

template Var metric_mismatch<float>(Tape<float>&, Var, Var, Var, Var);
template Var metric_mismatch<double>(Tape<double>&, Var, Var, Var, Var);
template Var isometry_loss<float>(Tape<float>&, Var, Var);
template Var isometry_loss<double>(Tape<double>&, Var, Var);

}  // namespace jsa
