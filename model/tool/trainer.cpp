#include "model/tool/trainer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <istream>
#include <limits>
#include <ostream>
#include <tuple>

#include "model/heuristics/orientation.h"
#include "model/heuristics/reseed.h"

namespace jsa {

Trainer::Trainer(const FitOptions& o, const std::vector<Block<double>>& pools, Team* team)
    : options_(o), team_(team), rng_(o.seed, 0) {
  JSA_CHECK(!pools.empty(), "no shapes to fit");
  if (o.points <= 0) throw InputError("--points must be positive");
  if (o.iterations < 0) throw InputError("--iters must be >= 0");
  const int n = int(pools.size());
  const int ranks = team ? team->size() : 1;
  if (ranks > n)
    throw InputError(std::to_string(ranks) + " MPI ranks for " + std::to_string(n) +
                     " shapes: run at most one rank per shape");
  if (ranks > 1 && o.wrap_steps > 0)
    throw InputError("--wrap is not supported with more than one MPI rank");
  if (ranks > 1 && o.reseed_every > 0)
    throw InputError("--reseed is not supported with more than one MPI rank");
  std::tie(first_shape_, last_shape_) = jsa::shape_block(n, ranks, team ? team->rank() : 0);
  for (int i = 0; i < n; ++i) {
    const Block<double>& pool = pools[size_t(i)];
    if (i < first_shape_ || i >= last_shape_) {
      pools_.emplace_back(0, 6);  // another rank's shape
      continue;
    }
    JSA_CHECK(pool.cols() == 6 && pool.rows() > 0, "a target pool must be P x 6");
    pools_.push_back(pool.cast<float>());
    pools_.back().rightCols(3) *= float(o.atlas.alpha);
    if (o.dense_surface)
      surfaces_.emplace_back(o.components.normals ? pools_.back()
                                                  : Block<float>(pools_.back().leftCols(3)));
  }
  const int b = o.batch_shapes > 0 && o.batch_shapes < n ? o.batch_shapes : n;
  if (o.batch_shapes < 0) throw InputError("--batch-shapes must be >= 0");
  for (int i = 0; i < b; ++i) batch_.push_back(i);
  options_.atlas.shapes = int(pools.size());
  AtlasOptions ao = options_.atlas;
  ao.gaussian_noise = o.components.distribution;
  atlas_ = std::make_unique<Atlas<float>>(ao);
  Rng init(o.seed, 1);
  atlas_->initialize(init);
  // Every parameter but the codes is shared by all shapes: its gradient is summed over the ranks.
  const Parameters<float>& p = atlas_->params;
  for (int e = 0; e < p.count(); ++e) {
    const auto& entry = p.entry(e);
    if (entry.name == "codes.phi" || entry.name == "codes.psi") continue;
    shared_.push_back({entry.offset, size_t(entry.rows * entry.cols)});
  }
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
  if (b < n) {
    // A uniform subset of B shapes: the first B of a partial Fisher-Yates shuffle
    // (the same on every rank: rng_ is).
    std::vector<int> order(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) order[size_t(i)] = i;
    for (int i = 0; i < b; ++i)
      std::swap(order[size_t(i)], order[size_t(i) + rng_.below(uint64_t(n - i))]);
    batch_.assign(order.begin(), order.begin() + b);
  }
  // Each shape draws its targets and its x_P from a generator of its own, seeded
  // by the step's key and the shape's index: the same numbers whichever rank
  // trains the shape, and in one process (docs/mpi.md).
  const uint64_t key = rng_.next();
  local_.clear();
  for (int s : batch_)
    if (s >= first_shape_ && s < last_shape_) local_.push_back(s);
  targets_.resize(local_.size(), Block<float>(options_.points, 6));
  shape_rngs_.clear();
  for (int s : local_) shape_rngs_.emplace_back(key, uint64_t(s));
  ObjectiveShare<float> share;
  share.shapes = local_;
  share.batch = b;
  share.repulsion = first_shape_ == 0;  // rank 0: N l_rep L_rep is counted once
  share.code_begin = first_shape_;
  share.code_end = last_shape_;
  // M targets {x_S, n_S} per shape, drawn with replacement from its pool.
  for (size_t k = 0; k < local_.size(); ++k) {
    const Block<float>& pool = pools_[size_t(local_[k])];
    Rng& rng = shape_rngs_[k];
    for (Index m = 0; m < options_.points; ++m)
      targets_[k].row(m) = pool.row(Index(rng.below(uint64_t(pool.rows()))));
    share.rngs.push_back(&rng);
    if (!surfaces_.empty()) share.surfaces.push_back(&surfaces_[size_t(local_[k] - first_shape_)]);
  }
  tape_.clear();
  const ObjectiveOptions objective{options_.weights, options_.components,
                                   options_.repulsion_tolerance};
  LossTerms sums;
  Var loss = objective_share(tape_, *atlas_, targets_, options_.points, objective, share, &sums);
  atlas_->params.zero_grad();
  tape_.backward(loss);
  if (iteration_ == fault_at_ && faults_to_inject_ > 0) {
    --faults_to_inject_;
    sums.total = std::numeric_limits<double>::quiet_NaN();
  }
  bool finite = std::isfinite(sums.total);
  for (float g : atlas_->params.grads()) finite = finite && std::isfinite(g);
  if (team_ && team_->size() > 1) finite = exchange(sums, finite);
  last_ = sums;
  for (double* v :
       {&last_.surface, &last_.chart, &last_.cycle_2d, &last_.cycle_6d, &last_.isometry})
    *v /= b;
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
    if (++faults_in_a_row_ > options_.max_faults)
      throw NumericalFault(faults_in_a_row_, iteration_);
    return;
  }
  faults_in_a_row_ = 0;
  if (iteration_ % kSnapshotEvery == 0) take_snapshot();
  adam_.step(atlas_->params, learning_rate());
  ++iteration_;
  choose_orientation();
  reseed();
}

// The step's sums over the ranks, in rank order (model/tool/team.h): the loss
// terms, whether every rank's loss and gradient were finite, and the gradient of
// the shared parameters. The codes' gradients stay on the rank of their shape.
bool Trainer::exchange(LossTerms& sums, bool finite) {
  double terms[8] = {sums.total,    sums.surface,  sums.chart,     sums.cycle_2d,
                     sums.cycle_6d, sums.isometry, sums.repulsion, finite ? 0.0 : 1.0};
  team_->sum_in_rank_order(terms, 8);
  sums = LossTerms{terms[0], terms[1], terms[2], terms[3], terms[4], terms[5], terms[6]};
  if (terms[7] != 0 || !std::isfinite(sums.total)) return false;
  std::vector<float>& grads = atlas_->params.grads();
  exchange_.clear();
  for (const auto& [offset, length] : shared_)
    exchange_.insert(exchange_.end(), &grads[offset], &grads[offset] + length);
  team_->sum_in_rank_order(exchange_.data(), exchange_.size());
  size_t at = 0;
  for (const auto& [offset, length] : shared_) {
    std::copy(exchange_.begin() + std::ptrdiff_t(at),
              exchange_.begin() + std::ptrdiff_t(at + length), &grads[offset]);
    at += length;
  }
  return true;
}

void Trainer::gather_codes() {
  if (!team_ || team_->size() == 1 || !atlas_->has_codes()) return;
  Parameters<float>& p = atlas_->params;
  const size_t d = size_t(p.entry(p.find("codes.phi")).cols);
  for (std::vector<float>* buffer : {&p.values(), &adam_.first_moment(), &adam_.second_moment()}) {
    if (buffer->empty()) continue;  // Adam's moments before the first step, on every rank
    for (const char* name : {"codes.phi", "codes.psi"}) {
      // Rows of other ranks' shapes to zero, then a sum: each row keeps its owner's value exactly.
      const auto& entry = p.entry(p.find(name));
      float* codes = buffer->data() + entry.offset;
      for (int s = 0; s < atlas_->shapes(); ++s)
        if (s < first_shape_ || s >= last_shape_)
          std::fill(codes + size_t(s) * d, codes + size_t(s + 1) * d, 0.0f);
      team_->sum_in_rank_order(codes, size_t(entry.rows) * d);
    }
  }
}

void Trainer::choose_orientation() {
  const int every = options_.orient_every;
  if (every <= 0 || !options_.components.normals || iteration_ % every != 0) return;
  const double first_decay = options_.decay_at.empty() ? 1.0 : options_.decay_at.front();
  if (double(iteration_) >= first_decay * double(options_.iterations)) return;
  // Its own streams, one per shape: the check does not shift the draws of the
  // training steps, and a shape draws the same on any rank.
  const Rng check(options_.seed, 1000 + uint64_t(iteration_ / every));
  double back = 0;
  for (size_t i = 0; i < targets_.size(); ++i) {
    Rng rng = check.stream(uint64_t(local_[i]));
    back += back_facing_fraction(*atlas_, targets_[i], std::min<Index>(options_.points, 2000), rng,
                                 local_[i]);
  }
  if (team_ && team_->size() > 1) team_->sum_in_rank_order(&back, 1);
  if (back / double(batch_.size()) <= 0.5) return;
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
  for (int s : batch_) {
    const Block<float>& pool = pools_[size_t(s)];
    Block<float> t(count, 6);
    for (Index m = 0; m < count; ++m) t.row(m) = pool.row(Index(rng.below(uint64_t(pool.rows()))));
    targets.push_back(std::move(t));
  }
  const ReseedReport r = reseed_flipped_means(*atlas_, targets, batch_, rng,
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
