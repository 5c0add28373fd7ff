#include "engine/gradcheck.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "engine/ops.h"
#include "engine/rng.h"

namespace jsa {
namespace {

struct Entry {
  int input;
  Index row, col;
  double analytic, numeric, ratio;
};

}  // namespace

GradCheckResult check_gradients(const GraphBuilder& f, std::vector<Block<double>> inputs,
                                const GradCheckOptions& o) {
  Tape<double> tape;
  Block<double> weights;  // R, drawn once the output shape is known

  // L(x) = sum R * f(x); also returns the Vars so gradients can be read.
  auto evaluate = [&](std::vector<Var>* vars) {
    tape.clear();
    std::vector<Var> xs;
    for (const auto& x : inputs) xs.push_back(tape.variable(x));
    Var y = f(tape, xs);
    if (weights.size() == 0) {
      Rng rng(o.seed);
      weights.resize(tape.rows(y), tape.cols(y));
      for (Index i = 0; i < weights.size(); ++i) weights.data()[i] = rng.uniform(0.5, 1.5);
    }
    JSA_CHECK(weights.rows() == tape.rows(y) && weights.cols() == tape.cols(y),
              "the graph's output changed shape between evaluations");
    Var loss = sum(tape, mul(tape, y, tape.constant(weights)));
    if (vars) *vars = xs;
    return loss;
  };

  std::vector<Var> xs;
  Var loss = evaluate(&xs);
  tape.backward(loss);
  std::vector<Block<double>> analytic;
  for (Var x : xs) analytic.push_back(tape.grad(x));

  GradCheckResult result;
  std::vector<Entry> entries;
  for (size_t k = 0; k < inputs.size(); ++k) {
    for (Index i = 0; i < inputs[k].rows(); ++i) {
      for (Index j = 0; j < inputs[k].cols(); ++j) {
        double& x = inputs[k](i, j);
        const double x0 = x, h = o.step * std::max(1.0, std::abs(x0));
        x = x0 + h;
        const double lp = tape.scalar(evaluate(nullptr));
        x = x0 - h;
        const double lm = tape.scalar(evaluate(nullptr));
        x = x0;
        const double num = (lp - lm) / (2 * h), ana = analytic[k](i, j);
        const double diff = std::abs(ana - num), mag = std::max(std::abs(ana), std::abs(num));
        const double ratio = diff / (o.atol + o.rtol * mag);
        if (mag > o.atol) result.worst_relative = std::max(result.worst_relative, diff / mag);
        result.worst_ratio = std::max(result.worst_ratio, ratio);
        entries.push_back({int(k), i, j, ana, num, ratio});
        ++result.checked;
      }
    }
  }
  result.ok = result.worst_ratio <= 1.0;
  std::sort(entries.begin(), entries.end(),
            [](const Entry& a, const Entry& b) { return a.ratio > b.ratio; });
  std::ostringstream s;
  s << "gradient check: " << result.checked << " entries, worst relative error "
    << result.worst_relative << ", worst error/tolerance " << result.worst_ratio << "\n";
  s << "  input  row  col      analytic       numeric   err/tol\n";
  for (int e = 0; e < std::min<int>(o.worst, int(entries.size())); ++e)
    s << "  " << entries[e].input << "  " << entries[e].row << "  " << entries[e].col << "  "
      << entries[e].analytic << "  " << entries[e].numeric << "  " << entries[e].ratio << "\n";
  result.report = s.str();
  return result;
}

}  // namespace jsa
