// A reusable gradient checker: reverse-mode gradients against central finite
// differences, in double precision.
//
// f builds a graph from its input Vars and returns any block y. The checker
// reduces y to a scalar L = sum_ij R_ij y_ij with fixed random weights R, so
// every entry of y (not just their sum) is exercised, then compares dL/dx from
// backward() with (L(x + h e) - L(x - h e)) / 2h, h = step * max(1, |x|).
// An entry passes when |analytic - numeric| <= atol + rtol * max(|analytic|, |numeric|).
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "engine/tape.h"

namespace jsa {

struct GradCheckOptions {
  double step = 1e-6;  // relative finite-difference step
  double rtol = 1e-5;  // relative tolerance
  double atol = 1e-8;  // absolute tolerance (entries whose gradient is ~0)
  int worst = 5;       // entries listed in the report on failure
  uint64_t seed = 7;   // seed of the reduction weights R
};

struct GradCheckResult {
  bool ok = true;
  double worst_relative = 0;  // max |a - n| / max(|a|, |n|) over entries with max(|a|,|n|) > atol
  double worst_ratio = 0;     // max |a - n| / (atol + rtol max(|a|, |n|)); <= 1 passes
  int checked = 0;            // entries compared
  std::string report;         // the worst entries, one per line
};

using GraphBuilder = std::function<Var(Tape<double>&, const std::vector<Var>&)>;

GradCheckResult check_gradients(const GraphBuilder& f, std::vector<Block<double>> inputs,
                                const GradCheckOptions& options = {});

}  // namespace jsa
