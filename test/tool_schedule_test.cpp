// The training schedule (model/tool/schedule.h): M's ramp in levels, the
// learning rate's warm-up and step decays, the cost ratio that sizes a run to a
// time budget, the schedule's place in a run's settings (config.json and the
// checkpoint), and the trainer following it across level changes, a resume,
// a fault's rewind and the template start of a collection.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <set>
#include <string>

#include "model/tool/fit_config.h"
#include "model/tool/schedule.h"
#include "model/tool/trainer.h"
#include "test/sphere_pool.h"

using jsa::Index;
using jsa::ScheduleOptions;

TEST_CASE("schedule: step keeps M fixed and decays lr at the fractions", "[schedule]") {
  ScheduleOptions s;
  s.kind = "step";
  for (int64_t i : {0, 1, 499, 999}) CHECK(jsa::scheduled_points(s, 2500, i, 1000) == 2500);
  CHECK(jsa::scheduled_lr(s, 1e-3, {0.75, 0.9}, 0.1, 0, 1000) == Approx(1e-3));
  CHECK(jsa::scheduled_lr(s, 1e-3, {0.75, 0.9}, 0.1, 749, 1000) == Approx(1e-3));
  CHECK(jsa::scheduled_lr(s, 1e-3, {0.75, 0.9}, 0.1, 750, 1000) == Approx(1e-4));
  CHECK(jsa::scheduled_lr(s, 1e-3, {0.75, 0.9}, 0.1, 900, 1000) == Approx(1e-5));
  CHECK(jsa::scheduled_cost_ratio(s, 2500, 250) == Approx(1.0));
}

TEST_CASE("schedule: ramp grows M in equal levels to its final value by ramp_until", "[schedule]") {
  ScheduleOptions s;
  s.kind = "ramp";
  s.points_start = 0.25;
  s.ramp_until = 0.5;
  s.levels = 4;
  const int64_t n = 1000;
  CHECK(jsa::scheduled_points(s, 2500, 0, n) == 625);
  CHECK(jsa::scheduled_points(s, 2500, 124, n) == 625);
  CHECK(jsa::scheduled_points(s, 2500, 125, n) == 1250);
  CHECK(jsa::scheduled_points(s, 2500, 374, n) == 1875);
  CHECK(jsa::scheduled_points(s, 2500, 375, n) == 2500);
  CHECK(jsa::scheduled_points(s, 2500, 999, n) == 2500);
  std::set<Index> seen;
  Index last = 0;
  for (int64_t i = 0; i < n; ++i) {
    const Index m = jsa::scheduled_points(s, 2500, i, n);
    CHECK(m >= last);  // never shrinks: each level reallocates the tape once
    last = m;
    seen.insert(m);
  }
  CHECK(seen.size() == 4);
  // Mean step cost over the run, (overhead + M_i) against overhead + M_0:
  // levels of 1/8 of the run each at 625..2500, then 2500 for half the run.
  const double c = 250;
  const double expected = ((c + 625) + (c + 1250) + (c + 1875) + 5 * (c + 2500)) / 8 / (c + 625);
  CHECK(jsa::scheduled_cost_ratio(s, 2500, c) == Approx(expected).epsilon(1e-3));
  // Timed steps that straddle a level change (a short --iters under --minutes).
  CHECK(jsa::scheduled_mean_cost(s, 2500, c, 0, 125, n) == Approx(c + 625));
  CHECK(jsa::scheduled_mean_cost(s, 2500, c, 120, 130, n) == Approx(c + (625 + 1250) / 2.0));
  // Never below 16 points.
  s.points_start = 0.001;
  CHECK(jsa::scheduled_points(s, 100, 0, n) == 16);
}

TEST_CASE("schedule: the warm-up rises linearly from lr/10", "[schedule]") {
  ScheduleOptions s;
  s.warmup = 0.1;
  CHECK(jsa::scheduled_lr(s, 1e-3, {0.75}, 0.1, 0, 1000) == Approx(1e-4));
  CHECK(jsa::scheduled_lr(s, 1e-3, {0.75}, 0.1, 50, 1000) == Approx(5.5e-4));
  CHECK(jsa::scheduled_lr(s, 1e-3, {0.75}, 0.1, 100, 1000) == Approx(1e-3));
  CHECK(jsa::scheduled_lr(s, 1e-3, {0.75}, 0.1, 800, 1000) == Approx(1e-4));
}

TEST_CASE("schedule: the drop multiplies the rate from its fraction of the run on, decays too",
          "[schedule]") {
  ScheduleOptions s;
  s.drop_at = 0.5;
  s.drop = 0.5;
  CHECK(jsa::scheduled_lr(s, 2e-3, {0.75}, 0.1, 0, 1000) == Approx(2e-3));
  CHECK(jsa::scheduled_lr(s, 2e-3, {0.75}, 0.1, 499, 1000) == Approx(2e-3));
  CHECK(jsa::scheduled_lr(s, 2e-3, {0.75}, 0.1, 500, 1000) == Approx(1e-3));
  CHECK(jsa::scheduled_lr(s, 2e-3, {0.75}, 0.1, 749, 1000) == Approx(1e-3));
  CHECK(jsa::scheduled_lr(s, 2e-3, {0.75}, 0.1, 750, 1000) == Approx(1e-4));
  // drop_at = 0 is no drop, whatever the factor.
  s.drop_at = 0;
  CHECK(jsa::scheduled_lr(s, 2e-3, {0.75}, 0.1, 600, 1000) == Approx(2e-3));
}

TEST_CASE("schedule: a weight moves geometrically to its end value, then stays", "[schedule]") {
  // 1e-2 -> 1e-1 by iteration 750 of 1000: a decade in 750 steps.
  CHECK(jsa::scheduled_weight(1e-2, 1e-1, 0.75, 0, 1000) == Approx(1e-2));
  CHECK(jsa::scheduled_weight(1e-2, 1e-1, 0.75, 375, 1000) == Approx(std::sqrt(1e-3)));
  CHECK(jsa::scheduled_weight(1e-2, 1e-1, 0.75, 750, 1000) == Approx(1e-1));
  CHECK(jsa::scheduled_weight(1e-2, 1e-1, 0.75, 999, 1000) == Approx(1e-1));
  // Down as well; linear when an end is 0; constant when end < 0.
  CHECK(jsa::scheduled_weight(1e-1, 1e-3, 0.5, 250, 1000) == Approx(1e-2));
  CHECK(jsa::scheduled_weight(1e-2, 0, 0.5, 250, 1000) == Approx(5e-3));
  CHECK(jsa::scheduled_weight(1e-2, -1, 0.5, 250, 1000) == 1e-2);
}

TEST_CASE("schedule: lambda_metric ends at the first decay or where --w-metric-until says",
          "[schedule]") {
  jsa::FitOptions o;
  o.iterations = 1000;
  o.weights.metric = 1e-2;
  // The default: linearly to 0 over the first quarter of the joint steps.
  CHECK(jsa::metric_weight_at(o, 0) == Approx(1e-2));
  CHECK(jsa::metric_weight_at(o, 125) == Approx(5e-3));
  CHECK(jsa::metric_weight_at(o, 250) == 0);
  CHECK(jsa::metric_weight_at(o, 999) == 0);
  // Constant over the whole run (metric_end < 0) ...
  o.metric_end = -1;
  CHECK(jsa::metric_weight_at(o, 999) == 1e-2);
  // ... to 0 by the first decay (0.75 of the run) ...
  o.metric_end = 0;
  o.metric_until = -1;
  REQUIRE(o.decay_at.front() == 0.75);
  CHECK(jsa::metric_weight_at(o, 375) == Approx(5e-3));
  CHECK(jsa::metric_weight_at(o, 750) == 0);
  // ... or by a fifth of it, then off (the objective skips a zero-weight term).
  o.metric_until = 0.2;
  CHECK(jsa::metric_weight_at(o, 0) == Approx(1e-2));
  CHECK(jsa::metric_weight_at(o, 100) == Approx(5e-3));
  CHECK(jsa::metric_weight_at(o, 200) == 0);
  CHECK(jsa::metric_weight_at(o, 999) == 0);
  // Without decays the move spans the run.
  o.metric_until = -1;
  o.decay_at.clear();
  CHECK(jsa::metric_weight_at(o, 500) == Approx(5e-3));
}

TEST_CASE("schedule: stored in the run's settings, older runs read as step",
          "[schedule][fit_config]") {
  jsa::FitOptions o;
  CHECK(o.schedule.kind == "ramp");
  CHECK(jsa::paper_fit_options().schedule.kind == "step");
  o.schedule.points_start = 0.4;
  o.schedule.ramp_until = 0.6;
  o.schedule.levels = 3;
  o.schedule.warmup = 0.05;
  o.schedule.drop_at = 0.5;
  o.schedule.drop = 0.25;
  const std::string text = jsa::fit_options_to_json(o, -1);
  const jsa::FitOptions back = jsa::fit_options_from_json(text, "x");
  CHECK(back.schedule.kind == "ramp");
  CHECK(back.schedule.points_start == 0.4);
  CHECK(back.schedule.ramp_until == 0.6);
  CHECK(back.schedule.levels == 3);
  CHECK(back.schedule.warmup == 0.05);
  CHECK(back.schedule.drop_at == 0.5);
  CHECK(back.schedule.drop == 0.25);
  // Runs written before the drop existed: no drop.
  std::string before_drop = text;
  for (const char* key : {"\"drop\":0.25,", "\"drop_at\":0.5,"}) {
    const auto k = before_drop.find(key);
    REQUIRE(k != std::string::npos);
    before_drop.erase(k, std::strlen(key));
  }
  const jsa::FitOptions no_drop = jsa::fit_options_from_json(before_drop, "x");
  CHECK(no_drop.schedule.drop_at == 0);
  CHECK(no_drop.schedule.drop == 1);
  std::string old = text;
  const auto at = old.find(",\"schedule\":");
  REQUIRE(at != std::string::npos);
  old.erase(at, old.find('}', at) + 1 - at);
  CHECK(jsa::fit_options_from_json(old, "old").schedule.kind == "step");
  std::string bad = text;
  bad.replace(bad.find("\"ramp\""), 6, "\"cosine\"");
  CHECK_THROWS_WITH(jsa::fit_options_from_json(bad, "run/model.ckpt"),
                    Catch::Contains("run/model.ckpt") && Catch::Contains("schedule.kind"));
}

namespace {

// A ramp of two levels over the first half of 8 iterations: M = 64 for
// iterations 0 and 1, then 128.
jsa::FitOptions two_level_options() {
  jsa::FitOptions o;
  o.atlas.gaussians = 128;
  o.atlas.width = 16;
  o.atlas.hidden_layers = 2;
  o.points = 128;
  o.iterations = 8;
  o.threads = 1;
  o.schedule.kind = "ramp";
  o.schedule.points_start = 0.5;
  o.schedule.ramp_until = 0.5;
  o.schedule.levels = 2;
  return o;
}

}  // namespace

TEST_CASE("schedule: the trainer draws the scheduled M targets, across a level change",
          "[schedule][trainer]") {
  jsa::Trainer t(two_level_options(), test_support::sphere_pool(2000, 1));
  for (int i = 0; i < 8; ++i) {
    CHECK(t.points() == (i < 2 ? 64 : 128));
    t.step();
    CHECK(std::isfinite(t.last().total));
  }
  CHECK(t.iteration() == 8);
}

TEST_CASE("schedule: a run resumed before a level change follows the uninterrupted one",
          "[schedule][trainer]") {
  const jsa::Block<double> pool = test_support::sphere_pool(2000, 1);
  jsa::Trainer straight(two_level_options(), pool);
  std::vector<double> expected;
  while (!straight.finished()) {
    straight.step();
    expected.push_back(straight.last().total);
  }
  jsa::Trainer first(two_level_options(), pool);
  first.step();
  // The settings as a checkpoint stores them, read back: the schedule with them.
  const jsa::FitOptions stored =
      jsa::fit_options_from_json(jsa::fit_options_to_json(first.options()), "settings");
  jsa::Trainer second(stored, pool);
  second.load_state(first.save_state(), "state");
  CHECK(second.points() == 64);
  for (size_t i = 1; i < expected.size(); ++i) {
    second.step();
    CHECK(second.last().total == expected[i]);
  }
  CHECK(second.points() == 128);
}

TEST_CASE("schedule: a fault rewinds M with the iteration", "[schedule][trainer]") {
  const jsa::Block<double> pool = test_support::sphere_pool(2000, 1);
  jsa::Trainer t(two_level_options(), pool);
  for (int i = 0; i < 3; ++i) t.step();
  CHECK(t.points() == 128);
  t.inject_faults(3, 1);
  t.step();  // back to the snapshot of iteration 0, in the first level
  CHECK(t.iteration() == 0);
  CHECK(t.points() == 64);
  for (int i = 0; i < 3; ++i) {
    t.step();
    CHECK(std::isfinite(t.last().total));
  }
  CHECK(t.points() == 128);
}

TEST_CASE("schedule: the template start takes the first level and its share of the ramp's cost",
          "[schedule][trainer]") {
  jsa::FitOptions o = two_level_options();
  o.atlas.code_size = 4;
  o.template_steps = 3;
  const std::vector<jsa::Block<double>> pools = {test_support::sphere_pool(2000, 1),
                                                 test_support::sphere_pool(2000, 2)};
  jsa::Trainer t(o, pools);
  t.train_template(3);
  CHECK(t.template_done() == 3);
  CHECK(t.iteration() == 0);  // the template does not count against the schedule
  CHECK(t.points() == 64);
  t.finish_template();
  for (int i = 0; i < 8; ++i) t.step();
  CHECK(t.points() == 128);
  CHECK(std::isfinite(t.last().total));
  // template_steps -1: share / (1 - share) x iterations x N single-shape steps,
  // times the ramp's mean cost relative to its first level (1 at a fixed M).
  o.template_steps = -1;
  o.template_share = 0.3;
  o.iterations = 1000;
  const double ratio = jsa::scheduled_cost_ratio(o.schedule, o.points, jsa::kStepOverheadPoints);
  CHECK(ratio > 1);
  CHECK(jsa::Trainer::template_steps_for(o, 1000, 2) == std::llround(0.3 / 0.7 * 1000 * 2 * ratio));
  o.schedule.kind = "step";
  CHECK(jsa::Trainer::template_steps_for(o, 1000, 2) == std::llround(0.3 / 0.7 * 1000 * 2));
  // template_max_steps caps the share (857 steps above), and only when it binds.
  o.template_max_steps = 500;
  CHECK(jsa::Trainer::template_steps_for(o, 1000, 2) == 500);
  o.template_max_steps = 5000;
  CHECK(jsa::Trainer::template_steps_for(o, 1000, 2) == std::llround(0.3 / 0.7 * 1000 * 2));
  o.template_steps = 7000;  // an explicit length is not capped
  CHECK(jsa::Trainer::template_steps_for(o, 1000, 2) == 7000);
}

TEST_CASE("schedule: out-of-range settings are refused naming the setting", "[schedule][trainer]") {
  const jsa::Block<double> pool = test_support::sphere_pool(200, 1);
  jsa::FitOptions o = two_level_options();
  o.schedule.kind = "cosine";
  CHECK_THROWS_WITH(jsa::Trainer(o, pool), "schedule.kind must be ramp or step");
  o = two_level_options();
  o.schedule.points_start = 0;
  CHECK_THROWS_WITH(jsa::Trainer(o, pool), "schedule.points_start must be in (0, 1]");
  o = two_level_options();
  o.schedule.levels = 0;
  CHECK_THROWS_WITH(jsa::Trainer(o, pool), "schedule.levels must be in [1, 1000]");
}

TEST_CASE(
    "budgeted_iterations: a run is shortened to what is left, lengthened while M keeps its level",
    "[tool][schedule]") {
  jsa::ScheduleOptions ramp;  // the default: M from 625 to 2500 over 3/4 of the run
  const jsa::Index m = 2500;
  const double overhead = jsa::kStepOverheadPoints;
  const int64_t n = 1000, decay = 750;
  // The rest of the run at iteration 100, in modelled cost units.
  const double rest = jsa::scheduled_mean_cost(ramp, m, overhead, 100, n, n) * double(n - 100);
  // Time enough (1 s per 1000 cost units, and the rest needs rest / 1000 s): unchanged.
  CHECK(jsa::budgeted_iterations(ramp, m, overhead, 100, n, decay, 1e-3, rest * 1e-3) == n);
  // Steps twice as dear as planned: shortened, and the new rest fits in 97% of what is left.
  const int64_t k = jsa::budgeted_iterations(ramp, m, overhead, 100, n, decay, 2e-3, rest * 1e-3);
  REQUIRE(k > 100);
  REQUIRE(k < n);
  const double kept = jsa::scheduled_mean_cost(ramp, m, overhead, 100, k, k) * double(k - 100);
  CHECK(kept * 2e-3 <= 0.97 * rest * 1e-3);
  // ... and it is the longest such run: one step more would not fit.
  const double more =
      jsa::scheduled_mean_cost(ramp, m, overhead, 100, k + 1, k + 1) * double(k + 1 - 100);
  CHECK(more * 2e-3 > 0.97 * rest * 1e-3);
  // Cheaper steps than planned, under the ramp, on its first level (i / n = 0.1,
  // the level ends at 0.1875): lengthened, up to four times the rest, M unchanged at i.
  const int64_t first =
      jsa::budgeted_iterations(ramp, m, overhead, 100, n, decay, 1e-4, rest * 1e-3);
  CHECK(first > n);
  CHECK(first <= 100 + 4 * (n - 100));
  CHECK(jsa::scheduled_points(ramp, m, 100, first) == jsa::scheduled_points(ramp, m, 100, n));
  // On the second level (i = 300 of 1000: 0.3 in [0.1875, 0.375)): lengthened
  // only as far as keeps M at i on that level (n' <= 300 / 0.1875 = 1600).
  const double rest300 = jsa::scheduled_mean_cost(ramp, m, overhead, 300, n, n) * double(n - 300);
  const int64_t second =
      jsa::budgeted_iterations(ramp, m, overhead, 300, n, decay, 1e-4, rest300 * 1e-3);
  CHECK(second > n);
  CHECK(second <= 1600);
  CHECK(jsa::scheduled_points(ramp, m, 300, second) == jsa::scheduled_points(ramp, m, 300, n));
  CHECK(jsa::scheduled_points(ramp, m, 300, second + 1) < jsa::scheduled_points(ramp, m, 300, n));
  // At a fixed M (collections, --preset paper): lengthened to the longest run
  // whose rest fits in 92% of what is left, at most four times the rest.
  jsa::ScheduleOptions step;
  step.kind = "step";
  const double cost = jsa::scheduled_mean_cost(step, m, overhead, 100, n, n);  // per step
  const int64_t longer =
      jsa::budgeted_iterations(step, m, overhead, 100, n, decay, 1e-3, 2.0 * cost * 900 * 1e-3);
  CHECK(longer - 100 <= int64_t(0.92 * 2.0 * 900));  // twice the time: about twice the rest
  CHECK(longer - 100 >= int64_t(0.92 * 2.0 * 900) - 1);
  CHECK(jsa::budgeted_iterations(step, m, overhead, 100, n, decay, 1e-3,
                                 100.0 * cost * 900 * 1e-3) == 100 + 4 * 900);
  // Within 85-102% of what is left: unchanged (no back and forth).
  CHECK(jsa::budgeted_iterations(step, m, overhead, 100, n, decay, 1e-3, 1.1 * cost * 900 * 1e-3) ==
        n);
  // Past the first decay, not lengthened either.
  CHECK(jsa::budgeted_iterations(step, m, overhead, 800, n, decay, 1e-3, 100.0) == n);
  // Past the first decay the length stays (moving the decays would break the schedule) ...
  CHECK(jsa::budgeted_iterations(ramp, m, overhead, 800, n, decay, 2e-3, 1.0) == n);
  // ... and once the budget is spent the run ends where it is.
  CHECK(jsa::budgeted_iterations(ramp, m, overhead, 800, n, decay, 2e-3, 0.0) == 800);
  CHECK(jsa::budgeted_iterations(ramp, m, overhead, 100, n, decay, 2e-3, -5.0) == 100);
  // No time for even one step: one more step, not a run that never ends.
  CHECK(jsa::budgeted_iterations(ramp, m, overhead, 100, n, decay, 1.0, 1e-9) == 101);
}

TEST_CASE(
    "budgeted_points: a budget too short for the steps asked takes the largest M that holds "
    "them",
    "[tool][schedule]") {
  jsa::ScheduleOptions ramp;
  const jsa::Index m = 2500, least = 625;
  const double overhead = jsa::kStepOverheadPoints, per_cost = 1e-5;  // seconds per cost unit
  const double full_run = jsa::scheduled_run_cost(ramp, m, overhead) * per_cost;  // s per step
  // Time for 2000 steps at M = 2500: kept at 1500 and 2000 steps asked, and with none asked.
  CHECK(jsa::budgeted_points(ramp, m, overhead, per_cost, 2000 * full_run, 1500, least) == m);
  CHECK(jsa::budgeted_points(ramp, m, overhead, per_cost, 2000 * full_run, 2000, least) == m);
  CHECK(jsa::budgeted_points(ramp, m, overhead, per_cost, 2000 * full_run, 0, least) == m);
  // 3000 steps asked: a smaller M whose run holds them, and the largest such
  // (one point more would not).
  const double left = 2000 * full_run;
  const jsa::Index k = jsa::budgeted_points(ramp, m, overhead, per_cost, left, 3000, least);
  REQUIRE(k < m);
  REQUIRE(k > least);
  auto steps = [&](jsa::Index p) {
    return left / (per_cost * jsa::scheduled_run_cost(ramp, p, overhead));
  };
  CHECK(steps(k) >= 3000);
  CHECK(steps(k + 1) < 3000);
  // The ramp's mean step costs overhead + 0.71875 M (four levels of 3/16 of
  // the run at 1/4, 1/2, 3/4 and 1 of M, then M): 2000 steps at M = 2500 hold
  // 3000 at M = (2000 x 2046.9 / 3000 - 250) / 0.71875 = 1551.
  CHECK(k >= 1549);
  CHECK(k <= 1552);
  // Not even the least M holds them: the least M; a fixed M shrinks alike.
  CHECK(jsa::budgeted_points(ramp, m, overhead, per_cost, left, 100000, least) == least);
  jsa::ScheduleOptions step;
  step.kind = "step";
  const jsa::Index f = jsa::budgeted_points(step, m, overhead, per_cost,
                                            2000 * (overhead + m) * per_cost, 4000, least);
  CHECK(f >= 1124);  // 2000 x 2750 / 4000 - 250 = 1125, within the rounding of the test
  CHECK(f <= 1125);
}
