// L_iso, Eq. (10): keep the metric of phi close to the identity.
// With J = [J_u, J_v] the 3x2 Jacobian, the first fundamental form is
//   J^T J = [[E, F], [F, G]],  E = <J_u, J_u>, F = <J_u, J_v>, G = <J_v, J_v>,
// and L_iso = (1/M) sum_m |J^T J - I|_F^2 = (1/M) sum_m (E-1)^2 + 2F^2 + (G-1)^2.
// (Eq. 10 writes J J^T and an unsquared norm; the 2x2 metric J^T J is the one
// isometry constrains, and the authors' code uses this squared form.)
#pragma once
#include "engine/tape.h"

namespace jsa {

template <class T>
Var isometry_loss(Tape<T>& t, Var du, Var dv);

}  // namespace jsa
