// psi: R^6 -> R^2, the chart-mapping (Sec. 3.1). Its input is a surface point
// and its normal scaled to norm alpha, so two nearby points on opposite sides of
// a thin part are far apart in R^6 and need not land together in 2D.
#pragma once
#include "model/mlp.h"

namespace jsa {

template <class T>
class Chart {
 public:
  Chart() = default;
  // in = 6, out = 2 (code_size: the latent code width in a collection).
  Chart(Parameters<T>& params, const MlpShape& shape) : mlp_(params, "psi", shape) {}
  void initialize(Parameters<T>& params, Rng& rng) const { mlp_.initialize(params, rng); }
  // x: M x 6 rows [point, alpha n] -> M x 2 domain coordinates; code: f_psi,i (1 x D) or none.
  Var evaluate(Tape<T>& t, Parameters<T>& params, Var x, Var code = {}) const {
    return mlp_.forward(t, params, x, -1, code);
  }
  const Mlp<T>& mlp() const { return mlp_; }

 private:
  Mlp<T> mlp_;
};

}  // namespace jsa
