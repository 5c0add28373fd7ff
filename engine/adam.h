// Adam (Kingma & Ba 2015) over a flat parameter buffer: one loop, no per-tensor
// bookkeeping. Bias-corrected moments:
//   m <- b1 m + (1 - b1) g ;  v <- b2 v + (1 - b2) g^2
//   θ <- θ - lr * (m / (1 - b1^t)) / (sqrt(v / (1 - b2^t)) + eps)
#pragma once
#include <cstdint>
#include <vector>

#include "engine/parameters.h"

namespace jsa {

struct AdamOptions {
  double lr = 1e-3;      // base learning rate
  double beta1 = 0.9;    // first-moment decay
  double beta2 = 0.999;  // second-moment decay
  double eps = 1e-8;     // added to sqrt(v) so a zero gradient moves nothing
};

template <class T>
class Adam {
 public:
  explicit Adam(AdamOptions options = {}) : options_(options) {}
  // One update with learning rate lr (the caller's schedule), using p.grads().
  void step(Parameters<T>& p, double lr);
  int64_t steps() const { return t_; }
  // State, for checkpoints.
  std::vector<T>& first_moment() { return m_; }
  std::vector<T>& second_moment() { return v_; }
  const std::vector<T>& first_moment() const { return m_; }
  const std::vector<T>& second_moment() const { return v_; }
  void set_steps(int64_t t) { t_ = t; }
  const AdamOptions& options() const { return options_; }

 private:
  AdamOptions options_;
  std::vector<T> m_, v_;
  int64_t t_ = 0;
};

// Step decay: lr * factor^(number of milestones already passed by `iter`).
double step_decay(double lr, int64_t iter, const std::vector<int64_t>& milestones, double factor);

}  // namespace jsa
