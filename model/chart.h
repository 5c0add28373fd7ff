// psi: R^6 -> R^2, the chart-mapping (Sec. 3.1). Its input is a surface point
// and its normal scaled to norm alpha, so two nearby points on opposite sides of
// a thin part are far apart in R^6 and need not land together in 2D.
#pragma once
#include "engine/ops.h"
#include "engine/rng.h"
#include "model/mlp.h"

namespace jsa {

template <class T>
class Chart {
 public:
  Chart() = default;
  // in = 6 + 2 fourier, out = 2 (code_size: the latent code width in a
  // collection). fourier > 0: F random Fourier features of the point, their
  // frequencies B (3 x F) drawn with sigma from a fixed seed, so a checkpoint
  // needs only F and sigma to rebuild them (AtlasOptions::chart_fourier).
  Chart(Parameters<T>& params, const MlpShape& shape, int fourier = 0, double sigma = 1)
      : mlp_(params, "psi", shape) {
    if (fourier <= 0) return;
    frequencies_.resize(3, fourier);
    Rng rng(0x6368617274ULL);  // "chart": the same B in every run with the same F and sigma
    for (Index i = 0; i < 3; ++i)
      for (Index j = 0; j < fourier; ++j) frequencies_(i, j) = T(sigma * rng.normal());
  }
  void initialize(Parameters<T>& params, Rng& rng) const { mlp_.initialize(params, rng); }
  // x: M x 6 rows [point, alpha n] -> M x 2 domain coordinates; code: f_psi,i (1 x D) or none.
  Var evaluate(Tape<T>& t, Parameters<T>& params, Var x, Var code = {}) const {
    if (frequencies_.size() > 0) {
      // [p, alpha n] -> [p, alpha n, sin(p B), cos(p B)]; B is a constant.
      Var phase = linear(t, slice_cols(t, x, 0, 3), t.constant(frequencies_), Var{});
      x = concat_cols(t, {x, sin_cos(t, phase)});
    }
    return mlp_.forward(t, params, x, -1, code);
  }
  const Mlp<T>& mlp() const { return mlp_; }

 private:
  Mlp<T> mlp_;
  Block<T> frequencies_;  // B, 3 x F (empty: no features)
};

}  // namespace jsa
