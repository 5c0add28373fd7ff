#include "losses/transport.h"

#include "losses/cycle.h"
#include "losses/metrics/assignment.h"

namespace jsa {

template <class T>
Var transport_loss(Tape<T>& t, Var x, Var y) {
  const Index n = t.rows(x);
  JSA_CHECK(n >= 1 && t.rows(y) == n && t.cols(y) == t.cols(x),
            "transport_loss: " << n << " x " << t.cols(x) << " samples against " << t.rows(y)
                               << " x " << t.cols(y) << " targets");
  struct Scratch {
    Block<double> cost;
    Assignment sigma;
    AssignmentWorkspace solver;
  };
  Scratch& s = t.template workspace<Scratch>();
  // sigma: the assignment of least total squared distance (Eq. 13's cost), in
  // double so that near-ties do not turn on float rounding.
  const Block<T>& xv = t.value(x);
  const Block<T>& yv = t.value(y);
  s.cost.resize(n, n);
  for (Index i = 0; i < n; ++i)
    for (Index j = 0; j < n; ++j)
      s.cost(i, j) =
          (xv.row(i).template cast<double>() - yv.row(j).template cast<double>()).squaredNorm();
  assign_lapjv(s.cost, s.sigma, s.solver);
  // The matched targets, a constant: gathered after the node is made (making
  // it may move the tape's blocks, so yv is read again through t.value).
  const Var matched = t.constant(Block<T>::Zero(n, t.cols(y)));
  for (Index i = 0; i < n; ++i)
    t.value(matched).row(i) = t.value(y).row(s.sigma.column_of_row[size_t(i)]);
  return mean_squared_distance(t, x, matched);
}

template Var transport_loss<float>(Tape<float>&, Var, Var);
template Var transport_loss<double>(Tape<double>&, Var, Var);

}  // namespace jsa
