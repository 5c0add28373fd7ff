// Forward-mode dual numbers, the independent oracle for the stacked-tangent
// Jacobians (the engine itself never uses them in training).
//
// A Dual<T, N> carries a value a and N derivatives v: a + v·ε with ε^2 = 0.
// Evaluating f on (x + e_k ε) gives f(x) + (∂f/∂x_k) ε, so one pass with N = 2
// tangent directions yields both columns of a 3x2 Jacobian. Each rule below is
// preceded by the identity it encodes. Fixed size, no heap (after Ceres' Jet).
#pragma once
#include <array>
#include <cmath>

namespace jsa {

template <class T, int N>
struct Dual {
  T a{};                 // value
  std::array<T, N> v{};  // derivatives along the N tangent directions

  Dual() = default;
  Dual(T value) : a(value) {}  // a constant: zero derivatives
  static Dual variable(T value, int k) {
    Dual d(value);
    d.v[k] = T(1);
    return d;
  }
};

// (a + u ε) + (b + w ε) = (a + b) + (u + w) ε
template <class T, int N>
Dual<T, N> operator+(const Dual<T, N>& x, const Dual<T, N>& y) {
  Dual<T, N> r(x.a + y.a);
  for (int k = 0; k < N; ++k) r.v[k] = x.v[k] + y.v[k];
  return r;
}
// (a + u ε) - (b + w ε) = (a - b) + (u - w) ε
template <class T, int N>
Dual<T, N> operator-(const Dual<T, N>& x, const Dual<T, N>& y) {
  Dual<T, N> r(x.a - y.a);
  for (int k = 0; k < N; ++k) r.v[k] = x.v[k] - y.v[k];
  return r;
}
// (a + u ε)(b + w ε) = ab + (a w + u b) ε
template <class T, int N>
Dual<T, N> operator*(const Dual<T, N>& x, const Dual<T, N>& y) {
  Dual<T, N> r(x.a * y.a);
  for (int k = 0; k < N; ++k) r.v[k] = x.a * y.v[k] + x.v[k] * y.a;
  return r;
}
// (a + u ε) / (b + w ε) = a/b + (u b - a w) / b^2 ε
template <class T, int N>
Dual<T, N> operator/(const Dual<T, N>& x, const Dual<T, N>& y) {
  Dual<T, N> r(x.a / y.a);
  for (int k = 0; k < N; ++k) r.v[k] = (x.v[k] * y.a - x.a * y.v[k]) / (y.a * y.a);
  return r;
}
template <class T, int N>
Dual<T, N>& operator+=(Dual<T, N>& x, const Dual<T, N>& y) {
  return x = x + y;
}

// sqrt(a + u ε) = sqrt(a) + u / (2 sqrt(a)) ε
template <class T, int N>
Dual<T, N> sqrt(const Dual<T, N>& x) {
  Dual<T, N> r(std::sqrt(x.a));
  for (int k = 0; k < N; ++k) r.v[k] = x.v[k] / (T(2) * r.a);
  return r;
}
// exp(a + u ε) = exp(a) + exp(a) u ε
template <class T, int N>
Dual<T, N> exp(const Dual<T, N>& x) {
  Dual<T, N> r(std::exp(x.a));
  for (int k = 0; k < N; ++k) r.v[k] = r.a * x.v[k];
  return r;
}
// relu(a + u ε) = relu(a) + [a > 0] u ε
template <class T, int N>
Dual<T, N> relu(const Dual<T, N>& x) {
  return x.a > T(0) ? x : Dual<T, N>(T(0));
}

// softplus_beta(a + u ε) = softplus_beta(a) + sigmoid(beta a) u ε,
//   softplus_beta(z) = log(1 + e^(beta z)) / beta,  d/dz = sigmoid(beta z).
// The default activation of phi and psi (engine/ops_linear.cpp, softplus_stacked);
// written with e = e^(-|beta a|) <= 1 so that neither term overflows.
template <class T, int N>
Dual<T, N> softplus(const Dual<T, N>& x, T beta) {
  using std::exp;
  using std::log1p;
  const T bz = beta * x.a;
  const T e = exp(-(bz < T(0) ? -bz : bz));
  const T sigmoid = bz >= T(0) ? T(1) / (T(1) + e) : e / (T(1) + e);
  Dual<T, N> r(((bz > T(0) ? bz : T(0)) + log1p(e)) / beta);
  for (int k = 0; k < N; ++k) r.v[k] = sigmoid * x.v[k];
  return r;
}

}  // namespace jsa
