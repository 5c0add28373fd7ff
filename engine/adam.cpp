#include "engine/adam.h"

#include <cmath>

#include "engine/parallel.h"

namespace jsa {

template <class T>
void Adam<T>::step(Parameters<T>& p, double lr) {
  const size_t n = p.size();
  if (m_.size() != n) {
    m_.assign(n, T(0));
    v_.assign(n, T(0));
  }
  ++t_;
  const double b1 = options_.beta1, b2 = options_.beta2;
  const T c1 = T(1.0 / (1.0 - std::pow(b1, double(t_))));
  const T c2 = T(1.0 / (1.0 - std::pow(b2, double(t_))));
  const T a = T(lr), e = T(options_.eps), tb1 = T(b1), tb2 = T(b2);
  T* theta = p.values().data();
  const T* g = p.grads().data();
  T* m = m_.data();
  T* v = v_.data();
  parallel_rows(
      Index(n),
      [&](Index i0, Index i1) {
        for (Index i = i0; i < i1; ++i) {
          m[i] = tb1 * m[i] + (T(1) - tb1) * g[i];
          v[i] = tb2 * v[i] + (T(1) - tb2) * g[i] * g[i];
          theta[i] -= a * (m[i] * c1) / (std::sqrt(v[i] * c2) + e);
        }
      },
      1 << 16);
}

double step_decay(double lr, int64_t iter, const std::vector<int64_t>& milestones, double factor) {
  for (int64_t m : milestones)
    if (iter >= m) lr *= factor;
  return lr;
}

template class Adam<float>;
template class Adam<double>;

}  // namespace jsa
