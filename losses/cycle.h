// The cycle-consistency term, Eq. (9): each direction is a mean squared
// distance between points and their images after a round trip,
//   (1/M) sum_x |x - psi(phi6(x))|^2   and   (1/M) sum_(p,n) |(p,n) - phi6(psi(p,n))|^2.
#pragma once
#include "engine/tape.h"

namespace jsa {

// (1/M) sum_m |a_m - b_m|^2 for two M x C blocks.
template <class T>
Var mean_squared_distance(Tape<T>& t, Var a, Var b);

}  // namespace jsa
