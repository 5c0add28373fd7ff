#include "model/tool/trainer.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>

#include "model/heuristics/orientation.h"
#include "model/heuristics/reseed.h"

namespace jsa {

// Errors name the setting as config.json does; the command line maps them to its flags.
static void validate(const FitOptions& o) {
  auto require = [](bool ok, const char* message) {
    if (!ok) throw InputError(message);
  };
  require(o.points > 0, "points must be positive");
  require(o.iterations >= 0, "iterations must be >= 0");
  require(o.batch_shapes >= 0, "batch_shapes must be >= 0");
  require(o.lr > 0 && std::isfinite(o.lr), "lr must be positive and finite");
  require(o.decay >= 0 && o.decay <= 1, "decay must be in [0, 1]");
  for (double f : o.decay_at) require(f >= 0 && f <= 1, "decay_at must be fractions in [0, 1]");
  require(o.atlas.alpha > 0 && std::isfinite(o.atlas.alpha),
          "atlas.alpha must be positive and finite");
  const std::pair<double, const char*> weights[] = {
      {o.weights.surface, "weights.surface_6d must be >= 0 and finite"},
      {o.weights.chart, "weights.chart_2d must be >= 0 and finite"},
      {o.weights.cycle, "weights.cycle must be >= 0 and finite"},
      {o.weights.isometry, "weights.isometry must be >= 0 and finite"},
      {o.weights.repulsion, "weights.repulsion must be >= 0 and finite"},
      {o.weights.code, "weights.code must be >= 0 and finite"}};
  for (const auto& [w, message] : weights) require(w >= 0 && std::isfinite(w), message);
  require(o.repulsion_tolerance > 0, "repulsion_tolerance must be positive");
  require(o.orient_every >= 0 && o.reseed_every >= 0 && o.wrap_steps >= 0,
          "orient_every, reseed_every and wrap_steps must be >= 0");
  require(o.max_faults >= 0, "max_faults must be >= 0");
  require(o.fault_lr_factor > 0 && o.fault_lr_factor <= 1, "fault_lr_factor must be in (0, 1]");
}

Trainer::Trainer(const FitOptions& o, const std::vector<Block<double>>& pools)
    : options_(o), rng_(o.seed, 0) {
  JSA_CHECK(!pools.empty(), "no shapes to fit");
  validate(o);
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
  targets_.assign(size_t(b), Block<float>(o.points, 6));
  for (int i = 0; i < b; ++i) batch_.push_back(i);
  options_.atlas.shapes = int(pools.size());
  AtlasOptions ao = options_.atlas;
  ao.gaussian_noise = o.components.distribution;
  atlas_ = std::make_unique<Atlas<float>>(ao);
  Rng init(o.seed, 1);
  atlas_->initialize(init);
  take_snapshot(rng_.state());
}

std::string describe(const FaultRecovery& f) {
  std::ostringstream s;
  s << "NaN/Inf in the step from iteration " << f.iteration << "; restored the state of iteration "
    << f.restored << " (parameters, Adam, RNG, counter), learning-rate scale now " << f.lr_scale;
  return s.str();
}

double Trainer::learning_rate() const {
  std::vector<int64_t> milestones;
  for (double f : options_.decay_at)
    milestones.push_back(int64_t(std::llround(f * double(options_.iterations))));
  return lr_scale_ * step_decay(options_.lr, iteration_, milestones, options_.decay);
}

void Trainer::take_snapshot(const std::array<uint64_t, 4>& rng_state) {
  good_.params = atlas_->params.values();
  good_.m = adam_.first_moment();
  good_.v = adam_.second_moment();
  good_.adam_steps = adam_.steps();
  good_.iteration = iteration_;
  good_.rng = rng_state;
}

void Trainer::restore_snapshot() {
  atlas_->params.values() = good_.params;
  adam_.first_moment() = good_.m;
  adam_.second_moment() = good_.v;
  adam_.set_steps(good_.adam_steps);
  iteration_ = good_.iteration;
  rng_.set_state(good_.rng);
}

WrapReport Trainer::wrap(const std::function<bool()>& cancelled) {
  if (wrapped_ || iteration_ > 0 || options_.wrap_steps <= 0) return {};
  wrapped_ = true;
  Rng rng(options_.seed, 2);  // its own stream: the training draws are the same with or without it
  const WrapReport r = wrap_initialize(*atlas_, pools_, options_.wrap_steps, options_.points,
                                       options_.lr, rng, cancelled);
  take_snapshot(rng_.state());  // a fault must not undo the wrap
  return r;
}

void Trainer::step() {
  const auto start = std::chrono::steady_clock::now();
  if (iteration_ == 0 && !wrapped_) wrap();
  // The state this step starts from: a snapshot taken after it is checked
  // finite must replay the same draws.
  const std::array<uint64_t, 4> rng_at_start = rng_.state();
  const int n = int(pools_.size()), b = int(batch_.size());
  if (b < n) {
    // A uniform subset of B shapes: the first B of a partial Fisher-Yates shuffle.
    std::vector<int> order(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) order[size_t(i)] = i;
    for (int i = 0; i < b; ++i)
      std::swap(order[size_t(i)], order[size_t(i) + rng_.below(uint64_t(n - i))]);
    batch_.assign(order.begin(), order.begin() + b);
  }
  // M targets {x_S, n_S} per shape of the batch, drawn with replacement from its pool.
  for (int k = 0; k < b; ++k) {
    const Block<float>& pool = pools_[size_t(batch_[size_t(k)])];
    for (Index m = 0; m < options_.points; ++m)
      targets_[size_t(k)].row(m) = pool.row(Index(rng_.below(uint64_t(pool.rows()))));
  }
  tape_.clear();
  const ObjectiveOptions objective{options_.weights, options_.components,
                                   options_.repulsion_tolerance};
  Var loss = collection_objective(tape_, *atlas_, targets_, options_.points, rng_, objective,
                                  &last_, b < n ? batch_ : std::vector<int>{}, surfaces_);
  atlas_->params.zero_grad();
  tape_.backward(loss);
  if (iteration_ == fault_at_ && faults_to_inject_ > 0) {
    --faults_to_inject_;
    last_.total = std::numeric_limits<double>::quiet_NaN();
  }
  bool finite = std::isfinite(last_.total);
  for (float g : atlas_->params.grads()) finite = finite && std::isfinite(g);
  StepReport report;
  report.lr = learning_rate();
  report.terms = last_;
  if (!finite) {
    // Undo: back to the last good state, whole; this batch is skipped and the
    // steps since the snapshot are redone with the smaller learning rate.
    FaultRecovery f;
    f.iteration = iteration_;
    restore_snapshot();
    lr_scale_ *= options_.fault_lr_factor;
    f.restored = iteration_;
    f.lr_scale = lr_scale_;
    fault_log_.push_back(f);
    failed_iteration_ = std::max(failed_iteration_, f.iteration);
    ++unresolved_faults_;
    report.fault = &fault_log_.back();
  } else {
    if (iteration_ > failed_iteration_) unresolved_faults_ = 0;  // past every failure so far
    if (iteration_ % kSnapshotEvery == 0) take_snapshot(rng_at_start);
    adam_.step(atlas_->params, report.lr);
    ++iteration_;
    report.mirrored = choose_orientation();
    report.reseeded = reseed();
  }
  elapsed_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  report.iteration = iteration_;
  report.iterations = options_.iterations;
  report.faults = faults();
  report.mirrors = mirrors_;
  report.reseeded_total = reseeded_;
  report.elapsed = elapsed_;
  if (progress_) progress_(report);
  if (unresolved_faults_ > options_.max_faults)
    throw NumericalFault(unresolved_faults_, failed_iteration_);
}

bool Trainer::choose_orientation() {
  const int every = options_.orient_every;
  if (every <= 0 || !options_.components.normals || iteration_ % every != 0) return false;
  const double first_decay = options_.decay_at.empty() ? 1.0 : options_.decay_at.front();
  if (double(iteration_) >= first_decay * double(options_.iterations)) return false;
  // Its own stream: the check does not shift the draws of the training steps.
  Rng rng(options_.seed, 1000 + uint64_t(iteration_ / every));
  double back = 0;
  for (size_t i = 0; i < targets_.size(); ++i)
    back += back_facing_fraction(*atlas_, targets_[i], std::min<Index>(options_.points, 2000), rng,
                                 batch_[i]);
  if (back / double(targets_.size()) <= 0.5) return false;
  mirror_domain(*atlas_, {&adam_.first_moment(), &adam_.second_moment()});
  ++mirrors_;
  take_snapshot(rng_.state());  // a fault must not restore the unmirrored state
  return true;
}

int Trainer::reseed() {
  const int every = options_.reseed_every;
  if (every <= 0 || !options_.components.normals || !options_.components.distribution ||
      iteration_ % every != 0)
    return 0;
  const double first_decay = options_.decay_at.empty() ? 1.0 : options_.decay_at.front();
  if (double(iteration_) >= first_decay * double(options_.iterations)) return 0;
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
  if (r.flipped == 0) return 0;
  reseeded_ += r.flipped;
  take_snapshot(rng_.state());
  return r.flipped;
}

TrainerState Trainer::save_state() const {
  TrainerState st;
  std::ostringstream params;
  atlas_->params.save(params);
  st.parameters = params.str();
  auto put = [&](const void* p, size_t n) { st.optimiser.append(static_cast<const char*>(p), n); };
  const int64_t steps = adam_.steps();
  put(&steps, sizeof steps);
  for (const std::vector<float>* v : {&adam_.first_moment(), &adam_.second_moment()}) {
    const uint64_t n = v->size();
    put(&n, sizeof n);
    put(v->data(), sizeof(float) * n);
  }
  st.rng = nlohmann::json{{"xoshiro256", rng_.state()}}.dump();
  nlohmann::json faults = nlohmann::json::array();
  for (const FaultRecovery& f : fault_log_)
    faults.push_back(nlohmann::json{
        {"iteration", f.iteration}, {"restored", f.restored}, {"lr_scale", f.lr_scale}});
  st.progress = nlohmann::json{
      {"iteration", iteration_},
      {"lr_scale", lr_scale_},
      {"faults", faults},
      {"mirrors", mirrors_},
      {"reseeded",
       reseeded_}}.dump();
  return st;
}

void Trainer::load_state(const TrainerState& st, const std::string& what) {
  std::istringstream params(st.parameters);
  atlas_->params.load(params, what);
  if (params.peek() != std::char_traits<char>::eof())
    throw InputError(what + ": trailing bytes after the parameters");
  size_t at = 0;
  auto get = [&](void* p, size_t n) {
    if (st.optimiser.size() - at < n) throw InputError(what + ": truncated optimiser state");
    std::memcpy(p, st.optimiser.data() + at, n);
    at += n;
  };
  int64_t steps = 0;
  get(&steps, sizeof steps);
  std::vector<float> moments[2];
  for (std::vector<float>& v : moments) {
    uint64_t n = 0;
    get(&n, sizeof n);
    if (n != 0 && n != atlas_->params.size())
      throw InputError(what + ": Adam state does not match the model");
    v.resize(n);
    get(v.data(), sizeof(float) * n);
  }
  if (at != st.optimiser.size()) throw InputError(what + ": trailing bytes in the optimiser state");
  int64_t it = 0;
  double scale = 1;
  std::array<uint64_t, 4> s{};
  std::vector<FaultRecovery> faults;
  int mirrors = 0, reseeded = 0;
  try {
    const nlohmann::json r = nlohmann::json::parse(st.rng), p = nlohmann::json::parse(st.progress);
    // Integers only: nlohmann converts a float such as 1e300 with static_cast (undefined).
    auto integer = [](const nlohmann::json& v) {
      if (!v.is_number_integer() ||
          (v.is_number_unsigned() && v.get<uint64_t>() > uint64_t(INT64_MAX)))
        throw std::runtime_error("expected an integer");
      return v.get<int64_t>();
    };
    const nlohmann::json& words = r.at("xoshiro256");
    if (!words.is_array() || words.size() != 4) throw std::runtime_error("expected 4 state words");
    for (size_t i = 0; i < 4; ++i) {
      if (!words[i].is_number_unsigned())
        throw std::runtime_error("expected an unsigned state word");
      s[i] = words[i].get<uint64_t>();
    }
    it = integer(p.at("iteration"));
    if (!p.at("lr_scale").is_number()) throw std::runtime_error("expected a number");
    scale = p.at("lr_scale").get<double>();
    mirrors = int(std::clamp<int64_t>(integer(p.at("mirrors")), -1, INT32_MAX));
    reseeded = int(std::clamp<int64_t>(integer(p.at("reseeded")), -1, INT32_MAX));
    for (const nlohmann::json& f : p.at("faults")) {
      if (!f.at("lr_scale").is_number()) throw std::runtime_error("expected a number");
      faults.push_back(
          {integer(f.at("iteration")), integer(f.at("restored")), f.at("lr_scale").get<double>()});
    }
  } catch (const std::exception& e) {
    throw InputError(what + ": malformed RNG or progress state (" + e.what() + ")");
  }
  if (it < 0 || steps < 0 || mirrors < 0 || reseeded < 0)
    throw InputError(what + ": negative count in the training state");
  if (!(scale > 0 && scale <= 1)) throw InputError(what + ": bad learning-rate scale");
  iteration_ = it;
  rng_.set_state(s);
  adam_.first_moment() = std::move(moments[0]);
  adam_.second_moment() = std::move(moments[1]);
  adam_.set_steps(steps);
  lr_scale_ = scale;
  fault_log_ = std::move(faults);
  mirrors_ = mirrors;
  reseeded_ = reseeded;
  take_snapshot(rng_.state());
}

}  // namespace jsa
