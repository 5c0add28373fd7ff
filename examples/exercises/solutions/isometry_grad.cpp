// Solution of exercise 3 (examples/exercises/isometry_grad.cpp).
#include "examples/exercises/exercises.h"

namespace jsa::exercise {

// l_i = (E-1)^2 + 2 F^2 + (G-1)^2,  E = J_u.J_u, F = J_u.J_v, G = J_v.J_v
// dl/dJ_u = 2 (E-1) dE/dJ_u + 4 F dF/dJ_u = 4 (E-1) J_u + 4 F J_v
// dl/dJ_v = 4 F J_u + 4 (G-1) J_v;  L = (1/N) sum_i l_i, so both get 1/N.
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
    d_du.row(i) = (4 * (e - 1) * du.row(i) + 4 * f * dv.row(i)) / double(n);
    d_dv.row(i) = (4 * f * du.row(i) + 4 * (g - 1) * dv.row(i)) / double(n);
  }
  return loss / double(n);
}

}  // namespace jsa::exercise
