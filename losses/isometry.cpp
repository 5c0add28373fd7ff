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

template Var isometry_loss<float>(Tape<float>&, Var, Var);
template Var isometry_loss<double>(Tape<double>&, Var, Var);

}  // namespace jsa
