// Exercise 3: the gradient of a loss by hand: L_iso (Eq. 10 as implemented,
// losses/isometry.cpp) with respect to the Jacobian's two columns. The tape
// computes the same thing from row_dot, offset, square and mean; the test
// compares. Solution: solutions/isometry_grad.cpp.
#include "examples/exercises/exercises.h"

namespace jsa::exercise {

double isometry_grad(const Block<double>& du, const Block<double>& dv, Block<double>& d_du,
                     Block<double>& d_dv) {
  const Index n = du.rows();
  d_du.setZero(n, 3);
  d_dv.setZero(n, 3);
  double loss = 0;
  for (Index i = 0; i < n; ++i) {
    const double e = du.row(i).dot(du.row(i)), f = du.row(i).dot(dv.row(i)),
                 g = dv.row(i).dot(dv.row(i));
    loss += (e - 1) * (e - 1) + 2 * f * f + (g - 1) * (g - 1);
    // TODO(exercise 3): d_du.row(i) and d_dv.row(i). Chain rule through E, F, G:
    // dE/dJ_u = 2 J_u, dF/dJ_u = J_v, ... and do not forget the 1/N.
  }
  return loss / double(n);
}

}  // namespace jsa::exercise
