// Chamfer distance, Eq. (6): a custom tape op. The forward pass is two
// nearest-neighbour searches; the pull-back touches only the matched pairs.
#include "losses/chamfer.h"

#include <cmath>

#include "engine/parallel.h"
#include "io/geometry/nearest.h"

namespace jsa {
namespace {

// Fills m with both associations; returns CD(x, y), summed in double, in order.
// x's matches are searched in `surface` when it is given (dense variant), else in y.
// The searches' scratch, when given, is reused (the op's, kept on its tape).
template <class T>
double match_both_ways(const Block<T>& x, const Block<T>& y, const NearestIndex<T>* surface,
                       ChamferMatches<T>& m, double coverage = 1,
                       NearestScratch<T>* x_search = nullptr,
                       NearestScratch<T>* y_search = nullptr) {
  JSA_CHECK(x.rows() > 0 && y.rows() > 0,
            "chamfer of an empty set: " << x.rows() << " and " << y.rows() << " points");
  JSA_CHECK(x.cols() == y.cols(), "chamfer: " << x.cols() << " vs " << y.cols() << " columns");
  if (surface) {
    surface->query(x, m.x_to_y, &m.x_squared_distance, x_search);
    nearest(y, x, m.y_to_x, &m.y_squared_distance, y_search);
  } else {
    nearest_both_ways(x, y, m.x_to_y, &m.x_squared_distance, m.y_to_x, &m.y_squared_distance,
                      x_search, y_search);
  }
  double sx = 0, sy = 0;
  for (T d : m.x_squared_distance) sx += double(d);
  for (T d : m.y_squared_distance) sy += double(d);
  return sx / double(x.rows()) + coverage * sy / double(y.rows());
}

// L = 1/N sum_i |x_i - z_{a_i}|^2 + w/M sum_j |y_j - x_{b_j}|^2, matches held
// fixed, where z = Y (Eq. 6) or the fixed pool S (dense variant, S constant).
// With r_i = x_i - z_{a_i} and s_j = y_j - x_{b_j}, and dL the incoming gradient:
//   dx_i     += 2 dL/N r_i      dy_{a_i} -= 2 dL/N r_i   (only when z = Y)
//   dy_j     += 2w dL/M s_j     dx_{b_j} -= 2w dL/M s_j     (w: the coverage weight, 1 in Eq. 6)
// The own-row terms write disjoint rows (parallel); the scatter-adds run serially
// in index order, so the sums are the same for every thread count.
template <class T>
Var chamfer_op(Tape<T>& t, Var x, Var y, const NearestIndex<T>* surface, ChamferMatches<T>* matches,
               double coverage = 1) {
  JSA_CHECK(coverage >= 0 && std::isfinite(coverage), "chamfer: coverage weight " << coverage);
  // The matches and the two searches' trees live on the tape until the next
  // step's same op reuses them (Tape::workspace): no allocation once warm.
  struct Scratch {
    ChamferMatches<T> matches;
    NearestScratch<T> x_search, y_search;
  };
  Scratch& scratch = t.template workspace<Scratch>();
  ChamferMatches<T>& m = matches ? *matches : scratch.matches;
  const double value = match_both_ways(t.value(x), t.value(y), surface, m, coverage,
                                       &scratch.x_search, &scratch.y_search);
  Var out = t.node(1, 1, {x, y});
  t.value(out)(0, 0) = T(value);
  if (!t.needs_grad(out)) return out;

  const int x_to_y = t.keep(m.x_to_y), y_to_x = t.keep(m.y_to_x);
  t.on_backward(out, [x, y, x_to_y, y_to_x, surface, coverage](Tape<T>& t, Var out) {
    const std::vector<int>& a = t.kept(x_to_y);
    const std::vector<int>& b = t.kept(y_to_x);
    const Block<T>& X = t.value(x);
    const Block<T>& Y = t.value(y);
    const Block<T>& Z = surface ? surface->points() : Y;
    const T dL = t.grad(out)(0, 0);
    const T cx = T(2) * dL / T(X.rows()), cy = T(2 * coverage) * dL / T(Y.rows());
    if (t.needs_grad(x)) {
      Block<T>& dX = t.grad(x);
      parallel_rows(X.rows(), [&](Index begin, Index end) {
        for (Index i = begin; i < end; ++i) dX.row(i) += cx * (X.row(i) - Z.row(a[i]));
      });
      for (Index j = 0; j < Y.rows(); ++j) dX.row(b[j]) -= cy * (Y.row(j) - X.row(b[j]));
    }
    if (t.needs_grad(y)) {
      Block<T>& dY = t.grad(y);
      parallel_rows(Y.rows(), [&](Index begin, Index end) {
        for (Index j = begin; j < end; ++j) dY.row(j) += cy * (Y.row(j) - X.row(b[j]));
      });
      if (!surface)
        for (Index i = 0; i < X.rows(); ++i) dY.row(a[i]) -= cx * (X.row(i) - Y.row(a[i]));
    }
  });
  return out;
}

}  // namespace

template <class T>
double chamfer_distance(const Block<T>& x, const Block<T>& y, ChamferMatches<T>* matches) {
  ChamferMatches<T> local;
  return match_both_ways(x, y, static_cast<const NearestIndex<T>*>(nullptr),
                         matches ? *matches : local);
}

template <class T>
Var chamfer(Tape<T>& t, Var x, Var y, ChamferMatches<T>* matches, double coverage) {
  return chamfer_op(t, x, y, static_cast<const NearestIndex<T>*>(nullptr), matches, coverage);
}

template <class T>
Var chamfer(Tape<T>& t, Var x, Var y, const NearestIndex<T>& surface, ChamferMatches<T>* matches,
            double coverage) {
  return chamfer_op(t, x, y, &surface, matches, coverage);
}

#define JSA_INSTANTIATE(T)                                                                         \
  template struct ChamferMatches<T>;                                                               \
  template Var chamfer<T>(Tape<T>&, Var, Var, ChamferMatches<T>*, double);                         \
  template Var chamfer<T>(Tape<T>&, Var, Var, const NearestIndex<T>&, ChamferMatches<T>*, double); \
  template double chamfer_distance<T>(const Block<T>&, const Block<T>&, ChamferMatches<T>*);
JSA_INSTANTIATE(float)
JSA_INSTANTIATE(double)

}  // namespace jsa
