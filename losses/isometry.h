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

// L_metric (collections; beyond the paper, docs/collections.md): two shapes'
// first fundamental forms at the same domain points, (J_u^a, J_v^a) and
// (J_u^b, J_v^b) row by row, should agree:
//   L_metric = (1/M) sum_m |J_a^T J_a - J_b^T J_b|_F^2
//            = (1/M) sum_m (E_a - E_b)^2 + 2 (F_a - F_b)^2 + (G_a - G_b)^2.
// L_iso pulls every phi_i towards an isometry of the flat domain, which a closed
// surface cannot be; this pulls the shapes towards isometries of each other,
// which articulated poses of one shape are, so a region of the domain covers
// the same part (the same lengths and angles) on every shape.
template <class T>
Var metric_mismatch(Tape<T>& t, Var du_a, Var dv_a, Var du_b, Var dv_b);

// L_metric's conformal variant (`--metric conformal`): the two forms compared
// up to a scale at each point. With g = (E, sqrt2 F, G) (|g| is then the
// Frobenius norm of J^T J),
//   L_conf = (1/M) sum_m | g_a / |g_a| - g_b / |g_b| |^2,
// which is 0 exactly where J_a^T J_a = c J_b^T J_b, c > 0: a conformal map
// between the two shapes. Lengths may change from shape to shape (a larger
// bear, a longer leg), angles and the shape of the stretch may not.
template <class T>
Var conformal_metric_mismatch(Tape<T>& t, Var du_a, Var dv_a, Var du_b, Var dv_b);

}  // namespace jsa
