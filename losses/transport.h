// L_EMD, a transport term (beyond the paper; issue 21, docs/results.md, "A
// transport term"): the EMD of the paper's evaluation (Eq. 13) as a training
// term, on n of the step's points. The n samples phi(x_P) and n targets x_S
// are matched one to one by the exact assignment of least total squared
// distance, sigma (losses/metrics/assignment.h; a constant of the step, as the
// nearest neighbours are for the Chamfer terms), and
//   L_EMD = (1/n) sum_i |phi(x_i) - x_S,sigma(i)|^2.
// Chamfer (Eq. 6) lets many samples share one target, so a thin part that phi
// covers with too few samples costs it nothing as long as each of its targets
// has one sample near; the assignment gives every target a sample of its own,
// and pulls samples into such a part from where they crowd.
#pragma once
#include "engine/tape.h"

namespace jsa {

// x: n x C samples on the tape; y: n x C targets, a constant on it, the same
// n >= 1. The value of L_EMD; its gradient reaches x through the matched
// pairs. The cost matrix, sigma and the solver's lists are the tape's
// workspace (Tape::workspace): a step allocates nothing for them once warm.
template <class T>
Var transport_loss(Tape<T>& t, Var x, Var y);

}  // namespace jsa
