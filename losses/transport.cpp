#include "losses/transport.h"

#include "losses/cycle.h"
#include "losses/metrics/assignment.h"

namespace jsa {

template <class T>
Var transport_loss(Tape<T>& t, Var x, const Block<T>& y) {
  const Index n = t.rows(x);
  JSA_CHECK(n >= 1 && y.rows() == n && y.cols() == t.cols(x),
            "transport_loss: " << n << " x " << t.cols(x) << " samples against " << y.rows()
                               << " x " << y.cols() << " targets");
  // sigma: the assignment of least total squared distance (Eq. 13's cost), in
  // double so that near-ties do not turn on float rounding.
  const Block<T>& xv = t.value(x);
  Block<double> cost(n, n);
  for (Index i = 0; i < n; ++i)
    for (Index j = 0; j < n; ++j)
      cost(i, j) =
          (xv.row(i).template cast<double>() - y.row(j).template cast<double>()).squaredNorm();
  const Assignment sigma = assign_lapjv(cost);
  const Var matched = t.constant(Block<T>(n, y.cols()));
  for (Index i = 0; i < n; ++i) t.value(matched).row(i) = y.row(sigma.column_of_row[size_t(i)]);
  return mean_squared_distance(t, x, matched);
}

template Var transport_loss<float>(Tape<float>&, Var, const Block<float>&);
template Var transport_loss<double>(Tape<double>&, Var, const Block<double>&);

}  // namespace jsa
