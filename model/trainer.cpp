#include "model/trainer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <istream>
#include <limits>
#include <ostream>

#include "model/orientation.h"
#include "model/reseed.h"

namespace jsa {

Trainer::Trainer(const FitOptions& o, const std::vector<Block<double>>& pools)
    : options_(o), rng_(o.seed, 0) {
  JSA_CHECK(!pools.empty(), "no shapes to fit");
  if (o.points <= 0) throw InputError("--points must be positive");
  if (o.iterations < 0) throw InputError("--iters must be >= 0");
  for (const Block<double>& pool : pools) {
    JSA_CHECK(pool.cols() == 6 && pool.rows() > 0, "a target pool must be P x 6");
    pools_.push_back(pool.cast<float>());
    pools_.back().rightCols(3) *= float(o.atlas.alpha);
    if (o.dense_surface)
      surfaces_.emplace_back(o.components.normals ? pools_.back()
                                                  : Block<float>(pools_.back().leftCols(3)));
  }
  const int n = int(pools.size());
  const int b = o.batch_shapes > 0 && o.batch_shapes < n ? o.batch_shapes : n;
  if (o.batch_shapes < 0) throw InputError("--batch-shapes must be >= 0");
  targets_.assign(size_t(b), Block<float>(o.points, 6));
  for (int i = 0; i < b; ++i) batch_.push_back(i);
  options_.atlas.shapes = int(pools.size());
  AtlasOptions ao = options_.atlas;
  ao.gaussian_noise = o.components.distribution;
  atlas_ = std::make_unique<Atlas<float>>(ao);
  Rng init(o.seed, 1);
  atlas_->initialize(init);
}

double Trainer::learning_rate() const {
  std::vector<int64_t> milestones;
  for (double f : options_.decay_at)
    milestones.push_back(int64_t(std::llround(f * double(options_.iterations))));
  return lr_scale_ * step_decay(options_.lr, iteration_, milestones, options_.decay);
}

void Trainer::take_snapshot() {
  good_params_ = atlas_->params.values();
  good_m_ = adam_.first_moment();
  good_v_ = adam_.second_moment();
  good_steps_ = adam_.steps();
}

WrapReport Trainer::wrap(const std::function<bool()>& cancelled) {
  if (wrapped_ || iteration_ > 0 || options_.wrap_steps <= 0) return {};
  wrapped_ = true;
  Rng rng(options_.seed, 2);  // its own stream: the training draws are the same with or without it
  return wrap_initialize(*atlas_, pools_, options_.wrap_steps, options_.points, options_.lr, rng,
                         cancelled);
}

void Trainer::step() {
  if (iteration_ == 0 && !wrapped_) wrap();
  const int n = int(pools_.size()), b = int(batch_.size());
  if (iteration_ == 0 && n > 1 && !template_finished_) {
    const int64_t want = options_.template_steps >= 0
                             ? options_.template_steps
                             : template_steps_for(options_, options_.iterations, n);
    if (want > 0) {
      if (template_done_ < want) train_template(want - template_done_);
      finish_template();
    }
  }
  if (b < n) {
    // A uniform subset of B shapes: the first B of a partial Fisher-Yates shuffle.
    std::vector<int> order(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) order[size_t(i)] = i;
    for (int i = 0; i < b; ++i)
      std::swap(order[size_t(i)], order[size_t(i) + rng_.below(uint64_t(n - i))]);
    batch_.assign(order.begin(), order.begin() + b);
  }
  if (!train_on(batch_, learning_rate(), iteration_)) return;
  ++iteration_;
  const double first_decay = options_.decay_at.empty() ? 1.0 : options_.decay_at.front();
  choose_orientation(iteration_, double(iteration_) < first_decay * double(options_.iterations));
  reseed();
}

int64_t Trainer::template_steps_for(const FitOptions& o, int64_t iterations, int shapes) {
  if (o.template_steps >= 0) return o.template_steps;
  if (shapes <= 1 || !(o.template_share > 0) || o.template_share >= 1) return 0;
  // A template step costs about 1/N of a joint step (one shape instead of N).
  return int64_t(
      std::llround(o.template_share / (1 - o.template_share) * double(iterations) * shapes));
}

void Trainer::train_template(int64_t steps, const std::function<bool()>& cancelled) {
  JSA_CHECK(iteration_ == 0 && !template_finished_,
            "the template start runs before the joint training");
  if (pools_.size() < 2) return;
  const std::vector<int> template_batch{0};
  for (int64_t k = 0; k < steps; ++k) {
    if (cancelled && cancelled()) return;
    if (!train_on(template_batch, lr_scale_ * options_.lr, template_done_)) continue;
    ++template_done_;
    // Until the joint run, the template's orientation is chosen as a run's is.
    choose_orientation(template_done_, true);
  }
}

void Trainer::finish_template() {
  if (template_finished_) return;
  template_finished_ = true;
  if (template_done_ == 0 || !atlas_->has_codes()) return;
  // Every shape starts as the template: f_i <- f_0 for phi and psi, and the same
  // for Adam's moments of the codes, so the first joint steps are the template's.
  for (const char* name : {"codes.phi", "codes.psi"}) {
    const int id = atlas_->params.find(name);
    JSA_CHECK(id >= 0, "the atlas has no " << name);
    const auto& e = atlas_->params.entry(id);
    for (std::vector<float>* buffer :
         {&atlas_->params.values(), &adam_.first_moment(), &adam_.second_moment()}) {
      if (buffer->empty()) continue;
      float* block = buffer->data() + e.offset;  // rows x cols, row-major: one code per row
      for (Index r = 1; r < e.rows; ++r)
        for (Index c = 0; c < e.cols; ++c) block[r * e.cols + c] = block[c];
    }
  }
  take_snapshot();
}

bool Trainer::train_on(const std::vector<int>& batch, double lr, int64_t counter) {
  const int n = int(pools_.size()), b = int(batch.size());
  targets_.resize(size_t(b), Block<float>(options_.points, 6));
  // M targets {x_S, n_S} per shape of the batch, drawn with replacement from its pool.
  for (int k = 0; k < b; ++k) {
    const Block<float>& pool = pools_[size_t(batch[size_t(k)])];
    for (Index m = 0; m < options_.points; ++m)
      targets_[size_t(k)].row(m) = pool.row(Index(rng_.below(uint64_t(pool.rows()))));
  }
  tape_.clear();
  ObjectiveOptions objective{options_.weights, options_.components, options_.repulsion_tolerance};
  if (double(iteration_) < options_.chart_from * double(options_.iterations))
    objective.components.chart = false;
  Var loss = collection_objective(tape_, *atlas_, targets_, options_.points, rng_, objective,
                                  &last_, b < n ? batch : std::vector<int>{}, surfaces_);
  atlas_->params.zero_grad();
  tape_.backward(loss);
  if (counter == fault_at_ && faults_to_inject_ > 0) {
    --faults_to_inject_;
    last_.total = std::numeric_limits<double>::quiet_NaN();
  }
  bool finite = std::isfinite(last_.total);
  for (float g : atlas_->params.grads()) finite = finite && std::isfinite(g);
  if (!finite) {
    // Back to the last good state with half the step; this batch is skipped.
    ++faults_total_;
    if (!good_params_.empty()) {
      atlas_->params.values() = good_params_;
      adam_.first_moment() = good_m_;
      adam_.second_moment() = good_v_;
      adam_.set_steps(good_steps_);
    }
    lr_scale_ *= 0.5;
    if (++faults_in_a_row_ > options_.max_faults) throw NumericalFault(faults_in_a_row_, counter);
    return false;
  }
  faults_in_a_row_ = 0;
  if (counter % kSnapshotEvery == 0) take_snapshot();
  if (options_.code_lr_scale != 1 && atlas_->has_codes()) {
    // Adam's update of the codes, scaled: theta <- old + s (theta_Adam - old).
    std::vector<std::pair<size_t, std::vector<float>>> before;
    for (const char* name : {"codes.phi", "codes.psi"}) {
      const auto& e = atlas_->params.entry(atlas_->params.find(name));
      const float* v = atlas_->params.values().data() + e.offset;
      before.emplace_back(size_t(e.offset), std::vector<float>(v, v + e.rows * e.cols));
    }
    adam_.step(atlas_->params, lr);
    const float s = float(options_.code_lr_scale);
    for (const auto& [offset, old] : before) {
      float* v = atlas_->params.values().data() + offset;
      for (size_t k = 0; k < old.size(); ++k) v[k] = old[k] + s * (v[k] - old[k]);
    }
  } else {
    adam_.step(atlas_->params, lr);
  }
  batch_step_ = batch;
  return true;
}

void Trainer::choose_orientation(int64_t counter, bool in_window) {
  const int every = options_.orient_every;
  if (every <= 0 || !options_.components.normals || counter % every != 0 || !in_window) return;
  // Its own stream: the check does not shift the draws of the training steps.
  Rng rng(options_.seed, 1000 + uint64_t(counter / every));
  double back = 0;
  for (size_t i = 0; i < targets_.size(); ++i)
    back += back_facing_fraction(*atlas_, targets_[i], std::min<Index>(options_.points, 2000), rng,
                                 batch_step_[i]);
  if (back / double(targets_.size()) <= 0.5) return;
  mirror_domain(*atlas_, {&adam_.first_moment(), &adam_.second_moment()});
  ++mirrors_;
  take_snapshot();  // a fault must not restore the unmirrored state
}

void Trainer::reseed() {
  const int every = options_.reseed_every;
  if (every <= 0 || !options_.components.normals || !options_.components.distribution ||
      iteration_ % every != 0)
    return;
  const double first_decay = options_.decay_at.empty() ? 1.0 : options_.decay_at.front();
  if (double(iteration_) >= first_decay * double(options_.iterations)) return;
  Rng rng(options_.seed, 3000 + uint64_t(iteration_ / every));
  // Targets from the pools: more than a step's M, so that holes are seen.
  const Index count = 4 * options_.points;
  std::vector<Block<float>> targets;
  for (int s : batch_step_) {
    const Block<float>& pool = pools_[size_t(s)];
    Block<float> t(count, 6);
    for (Index m = 0; m < count; ++m) t.row(m) = pool.row(Index(rng.below(uint64_t(pool.rows()))));
    targets.push_back(std::move(t));
  }
  const ReseedReport r = reseed_flipped_means(*atlas_, targets, batch_step_, rng,
                                              {&adam_.first_moment(), &adam_.second_moment()});
  if (r.flipped == 0) return;
  reseeded_ += r.flipped;
  take_snapshot();
}

// Layout: i64 iteration, 4 x u64 RNG state, i64 Adam steps, f64 lr scale, parameters,
// then Adam's two moment vectors (u64 length + floats each).
void Trainer::save_state(std::ostream& out) const {
  auto put = [&](const void* p, size_t n) {
    out.write(static_cast<const char*>(p), std::streamsize(n));
  };
  put(&iteration_, sizeof iteration_);
  const auto s = rng_.state();
  put(s.data(), sizeof(uint64_t) * 4);
  const int64_t steps = adam_.steps();
  put(&steps, sizeof steps);
  put(&lr_scale_, sizeof lr_scale_);
  atlas_->params.save(out);
  for (const std::vector<float>* v : {&adam_.first_moment(), &adam_.second_moment()}) {
    const uint64_t n = v->size();
    put(&n, sizeof n);
    put(v->data(), sizeof(float) * n);
  }
}

void Trainer::load_state(std::istream& in, const std::string& what) {
  auto get = [&](void* p, size_t n) {
    in.read(static_cast<char*>(p), std::streamsize(n));
    if (size_t(in.gcount()) != n) throw InputError(what + ": truncated training state");
  };
  int64_t it = 0, steps = 0;
  std::array<uint64_t, 4> s{};
  get(&it, sizeof it);
  get(s.data(), sizeof(uint64_t) * 4);
  get(&steps, sizeof steps);
  double scale = 1;
  get(&scale, sizeof scale);
  if (!(scale > 0 && scale <= 1)) throw InputError(what + ": bad learning-rate scale");
  atlas_->params.load(in, what);
  for (std::vector<float>* v : {&adam_.first_moment(), &adam_.second_moment()}) {
    uint64_t n = 0;
    get(&n, sizeof n);
    if (n != 0 && n != atlas_->params.size())
      throw InputError(what + ": Adam state does not match the model");
    v->resize(n);
    get(v->data(), sizeof(float) * n);
  }
  if (it < 0 || steps < 0) throw InputError(what + ": negative iteration count");
  iteration_ = it;
  rng_.set_state(s);
  adam_.set_steps(steps);
  lr_scale_ = scale;
  take_snapshot();
}

}  // namespace jsa
