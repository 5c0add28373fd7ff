#include "model/tool/pose_by_fit.h"

#include <chrono>
#include <vector>

#include "engine/rng.h"
#include "losses/chamfer.h"

namespace jsa {

namespace {

// The run's method on two shapes, the reference first: its template start
// fitted for `template_steps`, M fixed (a ramp would spend the short fit on
// small M), the decays where a run of `steps` has them.
FitOptions two_shape_options(const FitOptions& run, const PoseFitOptions& p) {
  FitOptions f = run;
  f.iterations = p.steps;
  f.template_steps = p.template_steps;
  f.template_share = 0;
  f.template_shape = 0;
  f.schedule = ScheduleOptions{};
  f.schedule.kind = "step";
  f.batch_shapes = 0;
  f.wrap_steps = 0;
  return f;
}

Block<double> turned(const Block<double>& pool, const Eigen::Matrix3d& r) {
  Block<double> out(pool.rows(), 6);
  out.leftCols(3) = pool.leftCols(3) * r;
  out.rightCols(3) = pool.rightCols(3) * r;
  return out;
}

// L_6D after the fit, on fresh draws: the symmetric Chamfer (mean squared
// distance, both ways) between rows [phi_s(x), alpha n] for `count` x ~ P and
// the first `count` rows [x_S, alpha n_S] of the shape's pool.
double surface_distance(Atlas<float>& atlas, int shape, const Block<double>& pool, Index count,
                        uint64_t seed) {
  Rng rng(seed, 21);
  Block<double> uv, points, normals;
  sample_reconstruction(atlas, count, rng, uv, points, normals, shape);
  const double alpha = atlas.options().alpha;
  Block<double> fitted(points.rows(), 6), target = pool.topRows(std::min(count, pool.rows()));
  fitted.leftCols(3) = points;
  fitted.rightCols(3) = alpha * normals;
  target.rightCols(3) *= alpha;
  return chamfer_distance(fitted, target);
}

}  // namespace

std::vector<PoseFitChoice> choose_poses_by_fit(
    const FitOptions& run, const Block<double>& reference, const std::vector<Block<double>>& pools,
    const std::vector<std::vector<Eigen::Matrix3d>>& candidates, const PoseFitOptions& p) {
  JSA_CHECK(pools.size() == candidates.size(), "one candidate list per pool");
  JSA_CHECK(p.template_steps >= 0 && p.steps >= 1 && p.scored >= 1 && p.scored <= p.steps,
            "bad pose-fit options");
  std::vector<PoseFitChoice> out(pools.size());
  const FitOptions f = two_shape_options(run, p);
  // The reference alone, once: its state after the template start is the same
  // whatever the second shape is (the template steps draw on shape 0 only, and
  // finish_template copies shape 0's codes).
  TrainerState start;
  bool started = false;
  for (size_t i = 0; i < pools.size(); ++i) {
    if (candidates[i].size() < 2) continue;
    const auto t0 = std::chrono::steady_clock::now();
    PoseFitChoice& c = out[i];
    for (size_t k = 0; k < candidates[i].size(); ++k) {
      Trainer t(f, std::vector<Block<double>>{reference, turned(pools[i], candidates[i][k])});
      if (!started) {
        t.train_template(f.template_steps);
        t.finish_template();
        start = t.save_state();
        started = true;
      } else {
        t.load_state(start, "pose fit");
      }
      // Indexed by iteration: a step undone by a fault is overwritten by its redo.
      std::vector<double> loss(size_t(p.steps), 0.0);
      while (!t.finished()) {
        t.step();
        if (t.iteration() > 0) loss[size_t(t.iteration() - 1)] = t.last().total;
      }
      double sum = 0;
      for (int64_t s = p.steps - p.scored; s < p.steps; ++s) sum += loss[size_t(s)];
      c.losses.push_back(sum / double(p.scored));
      c.surfaces.push_back(surface_distance(t.atlas(), 1, turned(pools[i], candidates[i][k]),
                                            p.surface_samples, run.seed));
      const std::vector<double>& score = p.by_surface ? c.surfaces : c.losses;
      if (score.back() < score[size_t(c.chosen)]) c.chosen = int(k);
    }
    c.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  return out;
}

PoseFitChoice choose_pose_by_fit(const FitOptions& run, const Block<double>& reference,
                                 const Block<double>& pool,
                                 const std::vector<Eigen::Matrix3d>& candidates,
                                 const PoseFitOptions& options) {
  return choose_poses_by_fit(run, reference, {pool}, {candidates}, options)[0];
}

}  // namespace jsa
