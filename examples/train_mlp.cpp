// Example: the engine on its own. A 1-32-1 ReLU network learns y = sin(3x) on
// [-1, 1] with Adam over a flat Parameters buffer, then check_gradients compares
// the tape's gradient of the same graph with central differences.
// Exits non-zero if the fit is poor or the gradient check fails.
#include <cmath>
#include <cstdio>
#include <exception>
#include <vector>

#include "engine/adam.h"
#include "engine/gradcheck.h"
#include "engine/ops.h"
#include "engine/rng.h"

using namespace jsa;

// The network, written once and used both for training and for the check:
// y = relu(x W1 + b1) W2 + b2. x: N x 1, W1: 1 x 32, W2: 32 x 1, y: N x 1.
template <class T>
Var network(Tape<T>& t, Var x, Var w1, Var b1, Var w2, Var b2) {
  return linear(t, relu(t, linear(t, x, w1, b1)), w2, b2);
}

int main() try {
  const Index n = 64;  // N training points
  Block<double> x(n, 1), y(n, 1);
  for (Index i = 0; i < n; ++i) {
    x(i, 0) = -1.0 + 2.0 * double(i) / double(n - 1);
    y(i, 0) = std::sin(3.0 * x(i, 0));
  }
  Parameters<double> p;
  const int w1 = p.add("w1", 1, 32), b1 = p.add("b1", 1, 32);
  const int w2 = p.add("w2", 32, 1), b2 = p.add("b2", 1, 1);
  Rng rng(42);
  for (double& v : p.values()) v = rng.uniform(-1.0, 1.0);

  Tape<double> t;
  Adam<double> adam;
  double loss = 0;
  for (int step = 0; step <= 2000; ++step) {
    t.clear();  // forget the graph, keep the storage
    const Var out = network(t, t.constant(x), p.on(t, w1), p.on(t, b1), p.on(t, w2), p.on(t, b2));
    const Var l = mean(t, square(t, sub(t, out, t.constant(y))));  // mean squared error
    loss = t.scalar(l);
    p.zero_grad();
    t.backward(l);  // the gradients land in p.grads()
    adam.step(p, 1e-2);
    if (step % 500 == 0) std::printf("step %4d  mse %.5f\n", step, loss);
  }

  // One gradient check of the trained graph with respect to every input block.
  const GraphBuilder f = [](Tape<double>& t, const std::vector<Var>& in) {
    return network(t, in[0], in[1], in[2], in[3], in[4]);
  };
  const GradCheckResult check =
      check_gradients(f, {x, p.value(w1), p.value(b1), p.value(w2), p.value(b2)});
  std::printf("gradient check: %d entries, worst relative error %.2e\n", check.checked,
              check.worst_relative);
  if (!check.ok) std::printf("%s\n", check.report.c_str());
  const bool ok = loss < 0.01 && check.ok;
  std::printf("%s\n", ok ? "ok" : "FAILED");
  return ok ? 0 : 1;
} catch (const std::exception& e) {  // JSA_CHECK and InputError throw
  std::fprintf(stderr, "example_train_mlp: %s\n", e.what());
  return 1;
}
