// Beyond the paper: what changes over a fit, as a function of the iteration i
// of n. The paper trains at a fixed M with step decays of the learning rate
// ("step", kept as `--schedule step`). The default "ramp" spends the start of
// the run, when phi is far from the surface and a coarse gradient is as good
// as a fine one, on cheap steps: M starts at a fraction of its final value and
// grows to it in a few equal levels (each level change reallocates the tape
// once, so a step within a level allocates nothing). The learning rate keeps
// the step decays; a short linear warm-up is optional. M depends on i and n
// only, so a resumed run (the schedule is in its settings) and every MPI rank
// (all at the same i) draw the same M. The measurements behind the defaults
// are in docs/results.md ("Quality against time").
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "engine/adam.h"
#include "engine/block.h"

namespace jsa {

struct ScheduleOptions {
  // "ramp" (default) or "step" (M fixed, the paper's and the default before the ramp).
  std::string kind = "ramp";
  double points_start = 0.25;  // ramp: M at the start, as a fraction of the final M
  double ramp_until = 0.75;    // ramp: fraction of the run by which M is final (the first decay)
  int levels = 4;              // ramp: M grows in this many equal steps
  double warmup = 0;           // fraction of the run over which lr rises linearly from lr/10
  // From this fraction of the run on, lr *= drop (0: never): the surface found
  // at a high rate, its details and L_even's spreading at a lower one.
  double drop_at = 0;
  double drop = 1;
};

// The work of a step that does not grow with M, in points' worth (L_rep over
// the K means, Adam, the lower GEMM rate of the small first levels): an
// estimate, used only to turn the ramp into a cost (scheduled_cost_ratio).
constexpr double kStepOverheadPoints = 250;

// M at iteration i of n: `points` under "step"; under "ramp" level
// l = floor(levels * i / (ramp_until n)) (capped at levels - 1) gets
// points * (points_start + (1 - points_start) l / (levels - 1)), at least 16.
inline Index scheduled_points(const ScheduleOptions& s, Index points, int64_t i, int64_t n) {
  if (s.kind != "ramp" || s.levels <= 1 || s.points_start >= 1 || n <= 0) return points;
  const double f = double(i) / (std::max(1e-9, s.ramp_until) * double(n));
  const int l = std::min(s.levels - 1, int(std::floor(f * s.levels)));
  const double frac = s.points_start + (1 - s.points_start) * double(l) / double(s.levels - 1);
  return std::max<Index>(16, Index(std::llround(frac * double(points))));
}

// The learning rate at iteration i of n: the step decays (lr *= decay at each
// fraction of decay_at) and the drop (lr *= drop from drop_at n on), times a
// linear warm-up from lr/10 over the first warmup * n iterations.
inline double scheduled_lr(const ScheduleOptions& s, double lr, const std::vector<double>& decay_at,
                           double decay, int64_t i, int64_t n) {
  // step_decay over the milestones round(f n), counted in place (the trainer
  // asks every step, and a step allocates nothing).
  double r = lr;
  for (double f : decay_at)
    if (i >= int64_t(std::llround(f * double(n)))) r *= decay;
  if (s.drop_at > 0 && i >= int64_t(std::llround(s.drop_at * double(n)))) r *= s.drop;
  const double w = s.warmup * double(n);
  if (w >= 1 && double(i) < w) r *= 0.1 + 0.9 * double(i) / w;
  return r;
}

// A loss weight that moves over the run (collections' L_metric,
// FitOptions::metric_end): `start` at iteration 0 to `end` at iteration
// `until` * n, then `end`. Geometric when both are positive (a weight's scale
// is what matters, and 1e-2 -> 1e-1 should spend as long near each decade),
// linear otherwise; end < 0 keeps `start` throughout.
inline double scheduled_weight(double start, double end, double until, int64_t i, int64_t n) {
  if (end < 0 || n <= 0) return start;
  const double f = std::min(1.0, double(i) / (std::max(1e-9, until) * double(n)));
  if (start > 0 && end > 0) return start * std::pow(end / start, f);
  return start + (end - start) * f;
}

// The mean cost of the steps [i0, i1) of a run of n, with a step's cost
// modelled as overhead + M_i (in points).
inline double scheduled_mean_cost(const ScheduleOptions& s, Index points, double overhead,
                                  int64_t i0, int64_t i1, int64_t n) {
  if (i1 <= i0) return overhead + double(scheduled_points(s, points, i0, n));
  double sum = 0;
  for (int64_t i = i0; i < i1; ++i) sum += overhead + double(scheduled_points(s, points, i, n));
  return sum / double(i1 - i0);
}

// The mean cost of a step over a whole run: the levels are fractions of the
// run, so any long n gives it. Used to size a run to a time budget from steps
// timed at its start (`jsatlas fit --minutes`).
inline double scheduled_run_cost(const ScheduleOptions& s, Index points, double overhead) {
  const int64_t n = 10000;
  return scheduled_mean_cost(s, points, overhead, 0, n, n);
}

// The same relative to a step at iteration 0: how much dearer the run's mean
// step is than its first. Sizes the template start of a collection to its
// share of the run's cost (model/tool/trainer.h).
inline double scheduled_cost_ratio(const ScheduleOptions& s, Index points, double overhead) {
  return scheduled_run_cost(s, points, overhead) /
         (overhead + double(scheduled_points(s, points, 0, 10000)));
}

// Keeping a time budget mid-run (`jsatlas fit --minutes`): at iteration i of
// a run of n, with `seconds_per_cost` measured over the last steps (seconds
// per unit of modelled cost, overhead + M) and `seconds_left` of the budget,
// the length the run should have:
//   - i when the budget is spent;
//   - n past the first decay (`first_decay`, an iteration), since moving the
//     decays then would break the schedule;
//   - shorter when the rest does not fit (more than 102% of what is left):
//     the longest length whose rest fits in 97% of it (at least i + 1);
//   - longer when the steps have become cheaper than planned (the rest needs
//     under 85% of what is left): the longest length whose rest fits in 92% of
//     what is left, at most four times the rest, and under the ramp no longer
//     than keeps M at iteration i on its level (a longer run would take M back
//     down; on the first level nothing does). The margins keep a stretch's
//     timing noise, about 10%, from shortening the run again at the next check.
//     (The ramp's first steps, the first estimate, are dearer per unit of cost
//     than the later ones: without this a `--minutes 1` ramp run ended at 43-55 s.)
//   - else n.
// The first estimate of a run is made from its first steps, and a machine
// whose load drops afterwards (or steps that get cheaper as the model
// trains) would otherwise leave part of the budget unused.
inline int64_t budgeted_iterations(const ScheduleOptions& s, Index points, double overhead,
                                   int64_t i, int64_t n, int64_t first_decay,
                                   double seconds_per_cost, double seconds_left) {
  if (seconds_left <= 0) return i;
  auto cost_left = [&](int64_t m) {
    return scheduled_mean_cost(s, points, overhead, i, m, m) * double(m - i);
  };
  if (i >= first_decay) return n;
  const double need = cost_left(n) * seconds_per_cost;
  // The longest length in [lo, hi] whose rest fits in `share` of what is left.
  auto longest = [&](int64_t lo, int64_t hi, double share) {
    while (lo < hi) {
      const int64_t mid = lo + (hi - lo + 1) / 2;
      if (cost_left(mid) * seconds_per_cost <= share * seconds_left)
        lo = mid;
      else
        hi = mid - 1;
    }
    return lo;
  };
  if (need > 1.02 * seconds_left) return longest(i + 1, n, 0.97);
  if (need < 0.85 * seconds_left) {
    int64_t hi = i + 4 * (n - i);
    if (s.kind != "step") {
      // Under the ramp, no longer than keeps M at iteration i on its level
      // (M at i falls as the run grows: i / n shrinks).
      const Index now = scheduled_points(s, points, i, n);
      int64_t lo = n;
      while (lo < hi) {
        const int64_t mid = lo + (hi - lo + 1) / 2;
        if (scheduled_points(s, points, i, mid) == now)
          lo = mid;
        else
          hi = mid - 1;
      }
      hi = lo;
    }
    if (hi > n) return longest(n, hi, 0.92);
  }
  return n;
}

// Sizing M to a short budget (`jsatlas fit --minutes`, `--min-steps`): the
// largest final M, between `least` and `points`, whose whole run of
// `min_steps` steps fits in `seconds_left` at `seconds_per_cost` (seconds per
// unit of modelled cost, overhead + M, measured on the run's first steps).
// A short fit needs its steps more than its points: at one minute of two
// cores a SHREC ant bought 990-1130 steps at M = 2500 and 2000 at M = 1200,
// and the fewer, finer steps left 2.4-4.0% of its surface inside out against
// 0.9-1.9% (docs/results.md, "M sized to the budget"). `points` when the
// budget already holds min_steps at it; `least` when not even that M does.
inline Index budgeted_points(const ScheduleOptions& s, Index points, double overhead,
                             double seconds_per_cost, double seconds_left, int64_t min_steps,
                             Index least) {
  least = std::min(least, points);
  if (min_steps <= 0 || !(seconds_per_cost > 0)) return points;
  auto steps_at = [&](Index m) {
    return seconds_left / (seconds_per_cost * scheduled_run_cost(s, m, overhead));
  };
  if (steps_at(points) >= double(min_steps)) return points;
  // A run's cost grows with M: the largest M whose run holds min_steps.
  Index lo = least, hi = points;
  while (lo < hi) {
    const Index mid = lo + (hi - lo + 1) / 2;
    if (steps_at(mid) >= double(min_steps))
      lo = mid;
    else
      hi = mid - 1;
  }
  return lo;
}

}  // namespace jsa
