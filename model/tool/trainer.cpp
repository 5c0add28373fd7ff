#include "model/tool/trainer.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <tuple>

#include "engine/parallel.h"
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
      {o.weights.code, "weights.code must be >= 0 and finite"},
      {o.weights.metric, "weights.metric must be >= 0 and finite"},
      {o.weights.evenness, "weights.evenness must be >= 0 and finite"},
      {o.weights.transport, "weights.transport must be >= 0 and finite"}};
  for (const auto& [w, message] : weights) require(w >= 0 && std::isfinite(w), message);
  require(o.repulsion_tolerance > 0, "repulsion_tolerance must be positive");
  require(o.orient_every >= 0 && o.reseed_every >= 0 && o.wrap_steps >= 0,
          "orient_every, reseed_every and wrap_steps must be >= 0");
  require(o.max_faults >= 0, "max_faults must be >= 0");
  require(o.fault_lr_factor > 0 && o.fault_lr_factor <= 1, "fault_lr_factor must be in (0, 1]");
  require(o.template_steps >= -1, "template_steps must be >= -1");
  require(o.template_share >= 0 && o.template_share < 1, "template_share must be in [0, 1)");
  require(o.chart_from >= 0 && o.chart_from <= 1, "chart_from must be in [0, 1]");
  require(o.evenness_from >= 0 && o.evenness_from <= 1, "evenness_from must be in [0, 1]");
  require(o.transport_from >= 0 && o.transport_from <= 1, "transport_from must be in [0, 1]");
  require(o.transport_points >= 1, "transport_points must be >= 1");
  require(std::isfinite(o.metric_end), "metric_end must be finite (< 0: lambda_metric constant)");
  require(o.metric_until < 0 || (o.metric_until > 0 && o.metric_until <= 1),
          "metric_until must be in (0, 1] (< 0: the first learning-rate decay)");
  require(o.code_lr_scale > 0 && std::isfinite(o.code_lr_scale),
          "code_lr_scale must be positive and finite");
  require(o.intrinsic >= 0 && std::isfinite(o.intrinsic), "intrinsic must be >= 0 and finite");
  require(o.intrinsic_until >= 0 && o.intrinsic_until <= 1, "intrinsic_until must be in [0, 1]");
  require(o.spectral_map >= 0 && std::isfinite(o.spectral_map),
          "spectral_map must be >= 0 and finite");
  require(o.nodes_width > 0 && std::isfinite(o.nodes_width), "nodes_width must be positive");
  require(o.fine_width > 0 && std::isfinite(o.fine_width), "fine_width must be positive");
  require(o.spectral_map_until > 0 && o.spectral_map_until <= 1,
          "spectral_map_until must be in (0, 1]");
  require(o.surface_lr_scale >= 0 && std::isfinite(o.surface_lr_scale),
          "surface_lr_scale must be >= 0 and finite");
  const ScheduleOptions& s = o.schedule;
  require(s.kind == "ramp" || s.kind == "step", "schedule.kind must be ramp or step");
  require(s.points_start > 0 && s.points_start <= 1, "schedule.points_start must be in (0, 1]");
  require(s.ramp_until > 0 && s.ramp_until <= 1, "schedule.ramp_until must be in (0, 1]");
  require(s.levels >= 1 && s.levels <= 1000, "schedule.levels must be in [1, 1000]");
  require(s.warmup >= 0 && s.warmup <= 1, "schedule.warmup must be in [0, 1]");
  require(s.drop_at >= 0 && s.drop_at <= 1, "schedule.drop_at must be in [0, 1]");
  require(s.drop > 0 && s.drop <= 1, "schedule.drop must be in (0, 1]");
}

void Trainer::require_rank_support(const FitOptions& o, int shapes, int ranks) {
  if (ranks > shapes)
    throw InputError(std::to_string(ranks) + " MPI ranks for " + std::to_string(shapes) +
                     " shapes: run at most one rank per shape");
  if (ranks > 1 && o.wrap_steps > 0)
    throw InputError("wrap_steps is not supported with more than one MPI rank");
  if (ranks > 1 && o.reseed_every > 0)
    throw InputError("reseed_every is not supported with more than one MPI rank");
  // The template start trains shape 0 alone: one rank would work while the
  // others wait, so a data-parallel run starts all shapes jointly.
  if (ranks > 1 && template_steps_for(o, o.iterations, shapes) > 0)
    throw InputError("template_steps is not supported with more than one MPI rank");
  if (ranks > 1 && o.template_shape != 0)
    throw InputError("template_shape other than 0 is not supported with more than one MPI rank");
  // The nodes are placed after the template start, which a data-parallel run has not.
  if (ranks > 1 && o.atlas.deform_nodes > 0)
    throw InputError("deform_nodes is not supported with more than one MPI rank");
}

Trainer::Trainer(const FitOptions& o, const std::vector<Block<double>>& pools, Team* team)
    : options_(o), team_(team), rng_(o.seed, 0) {
  JSA_CHECK(!pools.empty(), "no shapes to fit");
  validate(o);
  const int n = int(pools.size());
  if (o.template_shape < 0 || o.template_shape >= n)
    throw InputError("template_shape must name one of the " + std::to_string(n) + " shapes (0.." +
                     std::to_string(n - 1) + ")");
  const int ranks = team ? team->size() : 1;
  require_rank_support(o, n, ranks);
  std::tie(first_shape_, last_shape_) = jsa::shape_block(n, ranks, team ? team->rank() : 0);
  for (int i = 0; i < n; ++i) {
    const Block<double>& pool = pools[size_t(i)];
    if (i < first_shape_ || i >= last_shape_) {
      pools_.emplace_back(0, 6);  // another rank's shape
      continue;
    }
    const bool intrinsic = o.intrinsic > 0;
    JSA_CHECK(pool.cols() == (intrinsic ? 9 : 6) && pool.rows() > 0,
              (intrinsic ? "a target pool must be P x 9 [x_S, n_S, h_S] with --intrinsic"
                         : "a target pool must be P x 6"));
    pools_.push_back(pool.leftCols(6).cast<float>());
    pools_.back().rightCols(3) *= float(o.atlas.alpha);
    Block<float> index_rows =
        o.components.normals ? pools_.back() : Block<float>(pools_.back().leftCols(3));
    if (intrinsic) {
      descriptors_.push_back(pool.rightCols(3).cast<float>() * float(o.intrinsic));
      // L_6D^h's dense direction: the pool index over [x_S, alpha n_S, beta h_S].
      Block<float> rows(index_rows.rows(), 9);
      rows << index_rows, descriptors_.back();
      if (o.dense_surface) intrinsic_surfaces_.emplace_back(std::move(rows));
      if (i == o.template_shape) {
        reference_surface_ = std::make_unique<NearestIndex<float>>(pools_.back().leftCols(3));
        reference_descriptors_ = descriptors_.back();
      }
    }
    if (o.dense_surface) surfaces_.emplace_back(std::move(index_rows));
  }
  if (o.intrinsic > 0) {
    if (n < 2) throw InputError("--intrinsic is for collections (two shapes or more)");
    if (!o.components.normals) throw InputError("--intrinsic needs the normals in the loss");
    if (!reference_surface_)
      throw InputError("--intrinsic needs the template shape on every rank (not over MPI yet)");
  }
  const int b = o.batch_shapes > 0 && o.batch_shapes < n ? o.batch_shapes : n;
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
  take_snapshot(rng_.state());
}

std::string describe(const FaultRecovery& f) {
  std::ostringstream s;
  const char* what = f.template_step ? "template step " : "iteration ";
  s << "NaN/Inf in the step from " << what << f.iteration << "; restored the state of " << what
    << f.restored << " (parameters, Adam, RNG, counter), learning-rate scale now " << f.lr_scale;
  return s.str();
}

double Trainer::learning_rate() const {
  return lr_scale_ * scheduled_lr(options_.schedule, options_.lr, options_.decay_at, options_.decay,
                                  iteration_, options_.iterations);
}

Index Trainer::points() const {
  return scheduled_points(options_.schedule, options_.points, iteration_, options_.iterations);
}

void Trainer::take_snapshot(const std::array<uint64_t, 4>& rng_state) {
  good_.params = atlas_->params.values();
  good_.m = adam_.first_moment();
  good_.v = adam_.second_moment();
  good_.adam_steps = adam_.steps();
  good_.iteration = iteration_;
  good_.template_done = template_done_;
  good_.rng = rng_state;
}

void Trainer::restore_snapshot() {
  atlas_->params.values() = good_.params;
  adam_.first_moment() = good_.m;
  adam_.second_moment() = good_.v;
  adam_.set_steps(good_.adam_steps);
  iteration_ = good_.iteration;
  template_done_ = good_.template_done;
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
  const int n = int(pools_.size()), b = int(batch_.size());
  if (iteration_ == 0 && n > 1 && !template_finished_) {
    const int64_t want = template_steps_for(options_, options_.iterations, n);
    if (want > 0) {
      if (template_done_ < want) train_template(want - template_done_);
      finish_template();
    }
  }
  // The state this step starts from: a snapshot taken after it is checked
  // finite must replay the same draws.
  const std::array<uint64_t, 4> rng_at_start = rng_.state();
  if (b < n) {
    // A uniform subset of B shapes: the first B of a partial Fisher-Yates shuffle
    // (the same on every rank: rng_ is).
    std::vector<int>& order = batch_order_;  // kept: no allocation in a step
    order.resize(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) order[size_t(i)] = i;
    for (int i = 0; i < b; ++i)
      std::swap(order[size_t(i)], order[size_t(i) + rng_.below(uint64_t(n - i))]);
    batch_.assign(order.begin(), order.begin() + b);
  }
  StepReport report;
  report.lr = learning_rate();
  if (train_on(batch_, report.lr, false, rng_at_start, report)) {
    ++iteration_;
    const double first_decay = options_.decay_at.empty() ? 1.0 : options_.decay_at.front();
    report.mirrored = choose_orientation(
        iteration_, double(iteration_) < first_decay * double(options_.iterations));
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

int64_t Trainer::template_steps_for(const FitOptions& o, int64_t iterations, int shapes) {
  if (o.template_steps >= 0) return o.template_steps;
  if (shapes <= 1 || !(o.template_share > 0) || o.template_share >= 1) return 0;
  // A template step costs about 1/N of a joint step at the ramp's first M (one
  // shape instead of N); a joint step costs on average the ramp's cost ratio
  // times that first one (1 at a fixed M).
  const double ratio = scheduled_cost_ratio(o.schedule, o.points, kStepOverheadPoints);
  const int64_t steps = int64_t(std::llround(o.template_share / (1 - o.template_share) *
                                             double(iterations) * shapes * ratio));
  return o.template_max_steps > 0 ? std::min(steps, o.template_max_steps) : steps;
}

void Trainer::train_template(int64_t steps, const std::function<bool()>& cancelled) {
  JSA_CHECK(iteration_ == 0 && !template_finished_,
            "the template start runs before the joint training");
  if (pools_.size() < 2 || steps <= 0) return;
  // The template steps come before iteration 0 and do not count against the
  // schedule: they take the M of iteration 0 (under the ramp, its first level)
  // and the base learning rate. The template is shape 0 fitted from the random
  // start, the regime the ramp's cheap steps are for; the ramp's levels and the
  // decays stay fractions of the joint iterations, so --iters means the same
  // with or without a template (and --minutes can size the two apart); and M
  // does not drop when the joint run starts.
  const std::vector<int> template_batch{options_.template_shape};
  // A fault rewinds template_done_ to the last snapshot: the steps are redone,
  // so the template ends with `steps` good steps more, as a run's iterations do.
  const int64_t target = template_done_ + steps;
  while (template_done_ < target) {
    if (cancelled && cancelled()) return;
    const std::array<uint64_t, 4> rng_at_start = rng_.state();
    StepReport report;
    if (!train_on(template_batch, lr_scale_ * options_.lr, true, rng_at_start, report)) {
      if (unresolved_faults_ > options_.max_faults)
        throw NumericalFault(unresolved_faults_, failed_iteration_);
      continue;
    }
    ++template_done_;
    // Until the joint run, the template's orientation is chosen as a run's is.
    choose_orientation(template_done_, true);
  }
}

void Trainer::set_spectral_map(const Block<double>& template_vertices,
                               const std::vector<Block<double>>& images) {
  JSA_CHECK(int(images.size()) == atlas_->shapes(), "one image block per shape");
  JSA_CHECK(template_vertices.cols() == 3 && template_vertices.rows() > 0,
            "the template's vertices: V x 3");
  map_images_.clear();
  for (int i = 0; i < atlas_->shapes(); ++i) {
    const Block<double>& image = images[size_t(i)];
    JSA_CHECK(i == options_.template_shape ||
                  (image.rows() == template_vertices.rows() && image.cols() == 3),
              "shape " << i << ": one image per template vertex");
    map_images_.push_back(image.cast<float>());
  }
  map_surface_ = std::make_unique<NearestIndex<float>>(template_vertices.cast<float>());
}

void Trainer::finish_template() {
  if (template_finished_) return;
  template_finished_ = true;
  if (template_done_ == 0 || !atlas_->has_codes()) return;
  // Every shape starts as the template t: f_i <- f_t for phi and psi, and the
  // same for Adam's moments of the codes, so the first joint steps are the template's.
  for (const char* name : {"codes.phi", "codes.psi"}) {
    const int id = atlas_->params.find(name);
    JSA_CHECK(id >= 0, "the atlas has no " << name);
    const auto& e = atlas_->params.entry(id);
    for (std::vector<float>* buffer :
         {&atlas_->params.values(), &adam_.first_moment(), &adam_.second_moment()}) {
      if (buffer->empty()) continue;
      float* block = buffer->data() + e.offset;  // rows x cols, row-major: one code per row
      const Index t = options_.template_shape;
      for (Index r = 0; r < e.rows; ++r)
        if (r != t)
          for (Index c = 0; c < e.cols; ++c) block[r * e.cols + c] = block[t * e.cols + c];
    }
  }
  if (atlas_->phi.has_nodes()) {
    // The node displacement starts here (model/tool/node_placement.h): its
    // centres on the template's surface, and with a registration
    // (set_spectral_map) each shape's t_k,i fitted to it; Adam's moments of
    // the nodes are still zero (the term was off in the template start).
    NodePlacementOptions np;
    np.seed = options_.seed;
    np.width = options_.nodes_width;
    np.fine_width = options_.fine_width;
    const Block<float>* vertices = map_surface_ ? &map_surface_->points() : nullptr;
    node_report_ = place_nodes(*atlas_, options_.template_shape, vertices,
                               vertices ? &map_images_ : nullptr, np);
  }
  take_snapshot(rng_.state());  // a fault in the joint run must not undo the copy
}

bool Trainer::train_on(const std::vector<int>& batch, double lr, bool template_step,
                       const std::array<uint64_t, 4>& rng_at_start, StepReport& report) {
  const int b = int(batch.size());
  const int64_t counter = template_step ? template_done_ : iteration_;
  // Each shape draws its targets and its x_P from a generator of its own, seeded
  // by the step's key and the shape's index: the same numbers whichever rank
  // trains the shape, and in one process (docs/mpi.md). The key comes from rng_,
  // so a restored snapshot replays them.
  const uint64_t key = rng_.next();
  const Index points = this->points();  // the schedule's M, the same on every rank
  local_.clear();
  for (int s : batch)
    if (s >= first_shape_ && s < last_shape_) local_.push_back(s);
  targets_.resize(local_.size());
  // L_6D^h in the template start and until intrinsic_until of the iterations, then L_6D.
  const bool intrinsic = options_.intrinsic > 0 &&
                         (template_step || double(iteration_) < options_.intrinsic_until *
                                                                    double(options_.iterations));
  // (made here, not kept: the trainer may move, its members with it)
  const IntrinsicField<float> field{options_.template_shape, reference_surface_.get(),
                                    &reference_descriptors_};
  for (Block<float>& t : targets_)
    t.resize(points, intrinsic ? 9 : 6);  // a no-op within a level of the ramp
  shape_rngs_.clear();
  for (int s : local_) shape_rngs_.emplace_back(key, uint64_t(s));
  // M targets {x_S, n_S} (and beta h_S) per shape, drawn with replacement from its pool.
  for (size_t k = 0; k < local_.size(); ++k) {
    const Block<float>& pool = pools_[size_t(local_[k])];
    Rng& rng = shape_rngs_[k];
    for (Index m = 0; m < points; ++m) {
      const Index r = Index(rng.below(uint64_t(pool.rows())));
      targets_[k].row(m).head(6) = pool.row(r);
      if (intrinsic)
        targets_[k].row(m).tail(3) = descriptors_[size_t(local_[k] - first_shape_)].row(r);
    }
  }
  ObjectiveOptions objective{options_.weights, options_.components, options_.repulsion_tolerance};
  if (atlas_->shapes() > 1) objective.metric_reference = options_.template_shape;  // L_metric's
  objective.metric_conformal = options_.metric_conformal;
  objective.weights.metric = metric_weight_at(options_, counter);
  // The staged objective (FitOptions::chart_from): phi and P alone at first.
  if (double(iteration_) < options_.chart_from * double(options_.iterations))
    objective.components.chart = false;
  if (double(iteration_) < options_.evenness_from * double(options_.iterations))
    objective.weights.evenness = 0;
  objective.transport_points = options_.transport_points;
  if (double(iteration_) < options_.transport_from * double(options_.iterations))
    objective.weights.transport = 0;
  // L_map: from the first joint step, falling linearly to 0 at spectral_map_until.
  const double map_end = options_.spectral_map_until * double(options_.iterations);
  const bool map_on =
      !template_step && map_surface_ && options_.spectral_map > 0 && double(iteration_) < map_end;
  objective.weights.map = map_on ? options_.spectral_map * (1.0 - double(iteration_) / map_end) : 0;
  const MapField<float> map_field{options_.template_shape, map_surface_.get(), &map_images_};

  // L_full is a sum over shapes (Eq. 12), so its gradient is too: the step's
  // shapes are split into `workers` consecutive groups, each group's share of
  // L_full is built and differentiated on a tape of its own by one thread
  // (the same split an MPI run makes over ranks, docs/mpi.md), and the
  // groups' gradients are summed in group order. Worker 0 also adds L_rep and
  // the codes' prior. One worker is the plain step.
  const int count = int(local_.size());
  const int workers =
      options_.parallel_shapes && count > 1 ? std::max(1, std::min(max_threads(), count)) : 1;
  if (int(worker_tapes_.size()) < workers - 1) {
    worker_tapes_.resize(size_t(workers - 1));
    worker_grads_.resize(size_t(workers - 1));
  }
  worker_targets_.resize(size_t(workers));
  shape_threads_ = workers;
  // Per worker: its loss terms, its exception, its share of the objective;
  // members, cleared not freed, so that a step allocates nothing.
  std::vector<LossTerms>& part = worker_terms_;
  std::vector<std::exception_ptr>& failure = worker_failures_;
  part.assign(size_t(workers), LossTerms{});
  failure.assign(size_t(workers), nullptr);
  worker_shares_.resize(size_t(workers));
  atlas_->params.zero_grad();
  auto work = [&](int w) {
    const int begin = count * w / workers, end = count * (w + 1) / workers;
    ObjectiveShare<float>& share = worker_shares_[size_t(w)];
    share.shapes.clear();
    share.rngs.clear();
    share.surfaces.clear();
    share.intrinsic = nullptr;
    share.map = nullptr;
    share.batch = b;
    share.repulsion = first_shape_ == 0 && w == 0;  // rank 0: N l_rep L_rep is counted once
    share.code_begin = w == 0 ? first_shape_ : 0;
    share.code_end = w == 0 ? last_shape_ : 0;
    if (intrinsic) share.intrinsic = &field;
    if (map_on) share.map = &map_field;
    std::vector<Block<float>>& own = worker_targets_[size_t(w)];
    if (workers > 1) own.resize(size_t(end - begin));
    for (int k = begin; k < end; ++k) {
      share.shapes.push_back(local_[size_t(k)]);
      share.rngs.push_back(&shape_rngs_[size_t(k)]);
      const std::vector<NearestIndex<float>>& dense = intrinsic ? intrinsic_surfaces_ : surfaces_;
      if (!dense.empty())
        share.surfaces.push_back(&dense[size_t(local_[size_t(k)] - first_shape_)]);
      if (workers > 1) own[size_t(k - begin)] = targets_[size_t(k)];  // storage kept between steps
    }
    const std::vector<Block<float>>& targets = workers > 1 ? own : targets_;
    Tape<float>& tape = w == 0 ? tape_ : worker_tapes_[size_t(w - 1)];
    if (w > 0) {
      std::vector<float>& grads = worker_grads_[size_t(w - 1)];
      grads.assign(atlas_->params.size(), 0.0f);
      tape.set_parameter_grads(&grads);
    }
    tape.clear();
    const Var loss =
        objective_share(tape, *atlas_, targets, points, objective, share, &part[size_t(w)]);
    tape.backward(loss);
  };
  if (workers == 1) {
    work(0);
  } else {
#pragma omp parallel for num_threads(workers) schedule(static, 1)
    for (int w = 0; w < workers; ++w) {
      try {
        work(w);
      } catch (...) {
        failure[size_t(w)] = std::current_exception();  // nothing may leave an OpenMP region
      }
    }
    for (const std::exception_ptr& e : failure)
      if (e) std::rethrow_exception(e);
    std::vector<float>& grads = atlas_->params.grads();
    for (int w = 1; w < workers; ++w) {
      const std::vector<float>& g = worker_grads_[size_t(w - 1)];
      for (size_t i = 0; i < grads.size(); ++i) grads[i] += g[i];
    }
  }
  LossTerms sums;
  for (const LossTerms& p : part) {
    sums.total += p.total;
    sums.surface += p.surface;
    sums.chart += p.chart;
    sums.cycle_2d += p.cycle_2d;
    sums.cycle_6d += p.cycle_6d;
    sums.isometry += p.isometry;
    sums.repulsion += p.repulsion;
    sums.evenness += p.evenness;
    sums.map += p.map;
  }
  // The test hook counts joint iterations only (the template start has none).
  if (!template_step && counter == fault_at_ && faults_to_inject_ > 0) {
    --faults_to_inject_;
    sums.total = std::numeric_limits<double>::quiet_NaN();
  }
  bool finite = std::isfinite(sums.total);
  for (float g : atlas_->params.grads()) finite = finite && std::isfinite(g);
  // Over MPI the flag is summed with the loss terms: when any rank saw a NaN or
  // Inf, every rank takes the same recovery below, from the same snapshot.
  if (team_ && team_->size() > 1) finite = exchange(sums, finite);
  last_ = sums;
  for (double* v : {&last_.surface, &last_.chart, &last_.cycle_2d, &last_.cycle_6d, &last_.isometry,
                    &last_.evenness, &last_.map})
    *v /= b;
  report.terms = last_;
  // Template steps and joint iterations in one increasing count: the template
  // runs whole before iteration 0, and its snapshot is never restored after.
  const int64_t position = template_done_ + iteration_;
  if (!finite) {
    // Undo: back to the last good state, whole; this batch is skipped and the
    // steps since the snapshot are redone with the smaller learning rate. Every
    // rank takes its snapshot at the same iterations, so all rewind together.
    FaultRecovery f;
    f.iteration = counter;
    f.template_step = template_step;
    restore_snapshot();
    lr_scale_ *= options_.fault_lr_factor;
    f.restored = template_step ? template_done_ : iteration_;
    f.lr_scale = lr_scale_;
    fault_log_.push_back(f);
    if (position >= failed_position_) {
      failed_position_ = position;
      failed_iteration_ = counter;
    }
    ++unresolved_faults_;
    report.fault = &fault_log_.back();
    return false;
  }
  if (position > failed_position_) unresolved_faults_ = 0;  // past every failure so far
  if (counter % kSnapshotEvery == 0) take_snapshot(rng_at_start);
  // Per-group rates: Adam's update of a group, scaled by s,
  // theta <- old + s (theta_Adam - old): the codes (code_lr_scale) and, in the
  // joint training of a deformed collection, the shared surface phi
  // (surface_lr_scale; its parameters are "phi.*" but not D's "phi.deform.*").
  // (held_: a member, its entries' storage reused from step to step)
  std::vector<Held>& held = held_;
  size_t held_count = 0;
  auto hold = [&](int index, double scale) {
    const auto& e = atlas_->params.entry(index);
    const float* v = atlas_->params.values().data() + e.offset;
    if (held_count == held.size()) held.emplace_back();
    Held& h = held[held_count++];
    h.offset = size_t(e.offset);
    h.scale = float(scale);
    h.old.assign(v, v + e.rows * e.cols);
  };
  if (options_.code_lr_scale != 1 && atlas_->has_codes())
    for (const char* name : {"codes.phi", "codes.psi"})
      hold(atlas_->params.find(name), options_.code_lr_scale);
  if (options_.nodes_lr_scale != 1 && atlas_->phi.has_nodes())
    hold(atlas_->params.find("nodes.phi"), options_.nodes_lr_scale);
  if (options_.surface_lr_scale != 1 && !template_step && atlas_->phi.deforms())
    for (int i = 0; i < atlas_->params.count(); ++i) {
      const std::string& name = atlas_->params.entry(i).name;
      if (name.rfind("phi.", 0) == 0 && name.rfind("phi.deform.", 0) != 0)
        hold(i, options_.surface_lr_scale);
    }
  adam_.step(atlas_->params, lr);
  for (size_t j = 0; j < held_count; ++j) {
    const Held& h = held[j];
    float* v = atlas_->params.values().data() + h.offset;
    for (size_t k = 0; k < h.old.size(); ++k) v[k] = h.old[k] + h.scale * (v[k] - h.old[k]);
  }
  batch_step_ = batch;
  return true;
}

bool Trainer::choose_orientation(int64_t counter, bool in_window) {
  const int every = options_.orient_every;
  if (every <= 0 || !options_.components.normals || counter % every != 0 || !in_window)
    return false;
  // Its own streams, one per shape: the check does not shift the draws of the
  // training steps, and a shape draws the same on any rank.
  const Rng check(options_.seed, 1000 + uint64_t(counter / every));
  double back = 0;
  for (size_t i = 0; i < targets_.size(); ++i) {
    Rng rng = check.stream(uint64_t(local_[i]));
    const Block<float> six = targets_[i].leftCols(6);  // [x_S, alpha n_S] (not L_6D^h's h)
    back += back_facing_fraction(*atlas_, six, std::min<Index>(six.rows(), 2000), rng, local_[i]);
  }
  if (team_ && team_->size() > 1) team_->sum_in_rank_order(&back, 1);
  if (back / double(batch_step_.size()) <= 0.5) return false;
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
  for (int s : batch_step_) {
    const Block<float>& pool = pools_[size_t(s)];
    Block<float> t(count, 6);
    for (Index m = 0; m < count; ++m) t.row(m) = pool.row(Index(rng.below(uint64_t(pool.rows()))));
    targets.push_back(std::move(t));
  }
  const ReseedReport r = reseed_flipped_means(*atlas_, targets, batch_step_, rng,
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
  for (const FaultRecovery& f : fault_log_) {
    nlohmann::json j = {
        {"iteration", f.iteration}, {"restored", f.restored}, {"lr_scale", f.lr_scale}};
    if (f.template_step) j["template"] = true;
    faults.push_back(j);
  }
  st.progress = nlohmann::json{{"iteration", iteration_},
                               {"lr_scale", lr_scale_},
                               {"faults", faults},
                               {"mirrors", mirrors_},
                               {"reseeded", reseeded_},
                               {"template_steps_done", template_done_},
                               {"template_finished", template_finished_}}
                    .dump();
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
    if (n == 0) return;  // an empty moment vector has no data() to copy into
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
  int64_t template_done = 0;
  bool template_finished = false;
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
      FaultRecovery r{integer(f.at("iteration")), integer(f.at("restored")),
                      f.at("lr_scale").get<double>()};
      if (f.contains("template")) r.template_step = f.at("template").get<bool>();
      faults.push_back(r);
    }
    // Written since the template start (coll); older states had none.
    if (p.contains("template_steps_done")) template_done = integer(p.at("template_steps_done"));
    if (p.contains("template_finished")) template_finished = p.at("template_finished").get<bool>();
  } catch (const std::exception& e) {
    throw InputError(what + ": malformed RNG or progress state (" + e.what() + ")");
  }
  if (it < 0 || steps < 0 || mirrors < 0 || reseeded < 0 || template_done < 0)
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
  template_done_ = template_done;
  template_finished_ = template_finished || it > 0;
  take_snapshot(rng_.state());
}

}  // namespace jsa
