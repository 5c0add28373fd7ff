#include "losses/cycle.h"

#include "engine/ops.h"

namespace jsa {

template <class T>
Var mean_squared_distance(Tape<T>& t, Var a, Var b) {
  JSA_CHECK(t.rows(a) == t.rows(b) && t.cols(a) == t.cols(b),
            "mean_squared_distance: shapes differ");
  const T inv_m = T(1) / T(std::max<Index>(1, t.rows(a)));
  return scale(t, sum(t, square(t, sub(t, a, b))), inv_m);
}

template Var mean_squared_distance<float>(Tape<float>&, Var, Var);
template Var mean_squared_distance<double>(Tape<double>&, Var, Var);

}  // namespace jsa
