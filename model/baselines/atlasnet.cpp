#include "model/baselines/atlasnet.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/ops.h"
#include "io/geometry/nearest.h"
#include "losses/chamfer.h"

namespace jsa {

AtlasNetVariant AtlasNetVariant::table_row(int row) {
  JSA_CHECK(row >= 1 && row <= 4, "AtlasNet baselines are Table 1 rows 1-4, got " << row);
  AtlasNetVariant v;
  v.patches = row <= 2 ? 1 : 10;
  v.learned_points = row % 2 == 0;
  return v;
}

std::string AtlasNetVariant::name() const {
  return std::string(learned_points ? "ANv2-" : "ANv1-") + std::to_string(patches);
}

AtlasNetOptions atlasnet_options(const AtlasNetVariant& variant, const FitOptions& fit,
                                 int shapes) {
  AtlasNetOptions o;
  o.variant = variant;
  o.points = fit.points;
  o.width = fit.atlas.width;
  o.hidden_layers = fit.atlas.hidden_layers;
  o.shapes = shapes;
  o.code_size = fit.atlas.code_size;
  return o;
}

template <class T>
AtlasNet<T>::AtlasNet(const AtlasNetOptions& o) : options_(o) {
  const int p = o.variant.patches;
  JSA_CHECK(p >= 1, "an AtlasNet needs at least one patch");
  JSA_CHECK(o.shapes >= 1 && (o.shapes == 1 || o.code_size > 0), "bad collection size");
  if (o.points < p)
    throw InputError("AtlasNet " + o.variant.name() + ": M = " + std::to_string(o.points) +
                     " points cannot cover " + std::to_string(p) +
                     " patches (give --points >= " + std::to_string(p) + ")");
  const int d = o.shapes > 1 ? o.code_size : 0;
  // alpha = 1: the baselines' loss has no normals; evaluation wants unit ones.
  for (int k = 0; k < p; ++k)
    phi.emplace_back(params, MlpShape{2, 3, o.width, o.hidden_layers, d}, T(1),
                     "patch" + std::to_string(k));
  if (o.variant.learned_points)
    for (int k = 0; k < p; ++k)
      points_.push_back(
          params.add("patch" + std::to_string(k) + ".uv", patch_share(o.points, k), 2));
  if (d > 0) codes_ = params.add("codes", o.shapes, d);
}

template <class T>
Index AtlasNet<T>::patch_share(Index count, int patch) const {
  const Index p = options_.variant.patches;
  return count / p + (patch < count % p ? 1 : 0);
}

template <class T>
void AtlasNet<T>::initialize(Rng& rng) {
  // Separate streams per purpose, as Atlas::initialize does.
  for (int k = 0; k < patches(); ++k) {
    Rng r = rng.stream(10 + uint64_t(k));
    phi[size_t(k)].initialize(params, r);
  }
  Rng r_points = rng.stream(2);
  for (int b : points_) {
    auto x = params.value(b);
    for (Index i = 0; i < x.size(); ++i) x.data()[i] = T(r_points.uniform());  // U([0,1]^2)
  }
  if (codes_ >= 0) {
    Rng r_codes = rng.stream(4);
    auto c = params.value(codes_);
    for (Index i = 0; i < c.size(); ++i) c.data()[i] = T(0.01 * r_codes.normal());
  }
}

template <class T>
Var AtlasNet<T>::code(Tape<T>& t, int shape) {
  if (codes_ < 0) return Var{};
  JSA_CHECK(shape >= 0 && shape < options_.shapes, "shape " << shape << " of " << options_.shapes);
  return gather_rows(t, params.on(t, codes_), {shape});
}

template <class T>
Var AtlasNet<T>::patch_points(Tape<T>& t, int patch, Rng& rng) {
  JSA_CHECK(patch >= 0 && patch < patches(), "patch " << patch << " of " << patches());
  if (!points_.empty()) return params.on(t, points_[size_t(patch)]);
  Block<T> x(patch_share(options_.points, patch), 2);
  for (Index i = 0; i < x.size(); ++i) x.data()[i] = T(rng.uniform());
  return t.constant(x);
}

// L = sum_i CD(U_p phi_p,i(x_p), S_i) + l_code (1/N) sum_i |f_i|^2   (Eqs. 6, 12)
template <class T>
Var atlasnet_objective(Tape<T>& t, AtlasNet<T>& net, const std::vector<Block<T>>& targets, Rng& rng,
                       double code_weight, double* chamfer_out) {
  const int n = net.shapes();
  JSA_CHECK(int(targets.size()) == n, targets.size() << " target sets for " << n << " shapes");
  const T nan = std::numeric_limits<T>::quiet_NaN();
  Var total;
  double chamfer_sum = 0;
  for (int i = 0; i < n; ++i) {
    JSA_CHECK(targets[size_t(i)].cols() >= 3, "targets must have the 3 point columns first");
    const Var f = net.code(t, i);
    std::vector<Var> parts;
    for (int p = 0; p < net.patches(); ++p)
      parts.push_back(
          net.phi[size_t(p)].evaluate(t, net.params, net.patch_points(t, p, rng), false, f).points);
    const Var x = parts.size() == 1 ? parts[0] : concat_rows(t, parts);  // M x 3
    if (!t.value(x).allFinite()) {
      if (chamfer_out) *chamfer_out = double(nan);
      return t.constant(Block<T>::Constant(1, 1, nan));
    }
    const Var cd = chamfer(t, x, t.constant(targets[size_t(i)].leftCols(3)));
    chamfer_sum += double(t.scalar(cd));
    total = i == 0 ? cd : add(t, total, cd);
  }
  if (net.has_codes() && code_weight > 0) {
    // The auto-decoder's prior, as collection_objective adds it.
    Var norms = sum(t, square(t, net.code(t, 0)));
    for (int i = 1; i < n; ++i) norms = add(t, norms, sum(t, square(t, net.code(t, i))));
    total = add(t, total, scale(t, norms, T(code_weight / n)));
  }
  if (chamfer_out) *chamfer_out = chamfer_sum / n;
  return total;
}

AtlasNetTrainer::AtlasNetTrainer(const FitOptions& o, const AtlasNetVariant& variant,
                                 const std::vector<Block<double>>& pools)
    : options_(o), rng_(o.seed, 0) {
  JSA_CHECK(!pools.empty(), "no shapes to fit");
  if (o.points <= 0) throw InputError("--points must be positive");
  if (o.iterations < 0) throw InputError("--iters must be >= 0");
  for (const Block<double>& pool : pools) {
    JSA_CHECK(pool.cols() >= 3 && pool.rows() > 0, "a target pool must be P x 3 or more");
    pools_.push_back(pool.leftCols(3).cast<float>());
  }
  targets_.assign(pools.size(), Block<float>(o.points, 3));
  net_ = std::make_unique<AtlasNet<float>>(atlasnet_options(variant, o, int(pools.size())));
  Rng init(o.seed, 1);
  net_->initialize(init);
}

double AtlasNetTrainer::learning_rate() const {
  std::vector<int64_t> milestones;
  for (double f : options_.decay_at)
    milestones.push_back(int64_t(std::llround(f * double(options_.iterations))));
  return lr_scale_ * step_decay(options_.lr, iteration_, milestones, options_.decay);
}

void AtlasNetTrainer::step() {
  // M targets per shape, drawn with replacement from its pool.
  for (size_t k = 0; k < pools_.size(); ++k)
    for (Index m = 0; m < options_.points; ++m)
      targets_[k].row(m) = pools_[k].row(Index(rng_.below(uint64_t(pools_[k].rows()))));
  tape_.clear();
  const Var loss =
      atlasnet_objective(tape_, *net_, targets_, rng_, options_.weights.code, &last_chamfer_);
  last_loss_ = double(tape_.scalar(loss));
  net_->params.zero_grad();
  bool finite = std::isfinite(last_loss_);
  if (finite) {
    tape_.backward(loss);
    for (float g : net_->params.grads()) finite = finite && std::isfinite(g);
  }
  if (!finite) {
    // Adam never sees the bad gradient: the parameters stay as they were, and the
    // next attempt takes a half step (Trainer also restores a snapshot; the
    // Chamfer-only baselines have not needed one).
    lr_scale_ *= 0.5;
    if (++faults_in_a_row_ > options_.max_faults)
      throw NumericalFault(faults_in_a_row_, iteration_);
    return;
  }
  faults_in_a_row_ = 0;
  adam_.step(net_->params, learning_rate());
  ++iteration_;
}

PatchPoints sample_patches(const AtlasNet<float>& net, Index count, Rng& rng) {
  PatchPoints s;
  s.uv.resize(count, 2);
  s.patch.reserve(size_t(count));
  Index r = 0;
  for (int p = 0; p < net.patches(); ++p) {
    const Index share = net.patch_share(count, p);
    const int set = net.learned_points(p);
    if (set < 0) {
      for (Index k = 0; k < share; ++k, ++r) {
        s.uv(r, 0) = rng.uniform();
        s.uv(r, 1) = rng.uniform();
        s.patch.push_back(p);
      }
      continue;
    }
    // v2: the learned points in a random order (Fisher-Yates), cycled.
    const auto x = net.params.value(set);
    std::vector<Index> order(size_t(x.rows()));
    for (Index i = 0; i < x.rows(); ++i) order[size_t(i)] = i;
    for (Index i = x.rows() - 1; i > 0; --i)
      std::swap(order[size_t(i)], order[size_t(rng.below(uint64_t(i + 1)))]);
    for (Index k = 0; k < share; ++k, ++r) {
      s.uv.row(r) = x.row(order[size_t(k % x.rows())]).cast<double>();
      s.patch.push_back(p);
    }
  }
  return s;
}

namespace {

// phi_p,i at every (patch, uv), patch by patch in batches; normals only if asked
// (they need the Jacobian, three times the rows).
void map_patches(AtlasNet<float>& net, const PatchPoints& at, int shape, Block<double>& points,
                 Block<double>* normals) {
  const Index n = at.uv.rows();
  JSA_CHECK(Index(at.patch.size()) == n, "one patch per 2D point");
  points.resize(n, 3);
  if (normals) normals->resize(n, 3);
  Tape<float> t;
  const Index batch = 8192;
  for (int p = 0; p < net.patches(); ++p) {
    std::vector<Index> rows;
    for (Index r = 0; r < n; ++r)
      if (at.patch[size_t(r)] == p) rows.push_back(r);
    for (size_t b = 0; b < rows.size(); b += size_t(batch)) {
      const size_t m = std::min(rows.size() - b, size_t(batch));
      Block<float> x(Index(m), 2);
      for (size_t k = 0; k < m; ++k) x.row(Index(k)) = at.uv.row(rows[b + k]).cast<float>();
      t.clear();
      const SurfacePoints s = net.phi[size_t(p)].evaluate(t, net.params, t.constant(x),
                                                          normals != nullptr, net.code(t, shape));
      for (size_t k = 0; k < m; ++k) {
        points.row(rows[b + k]) = t.value(s.points).row(Index(k)).cast<double>();
        if (normals)
          normals->row(rows[b + k]) = t.value(s.normals).row(Index(k)).cast<double>().normalized();
      }
    }
  }
}

}  // namespace

void evaluate_patches(AtlasNet<float>& net, const PatchPoints& at, int shape, Block<double>& points,
                      Block<double>& normals) {
  map_patches(net, at, shape, points, &normals);
}

Evaluation evaluate_atlasnet(AtlasNet<float>& net, const Mesh& shape,
                             const Normalization& normalization, const EvaluationOptions& o,
                             int index) {
  Rng rng(o.seed, 10);
  const PatchPoints at = sample_patches(net, o.samples, rng);
  Block<double> points, normals;
  evaluate_patches(net, at, index, points, normals);
  return evaluate_points(points, normals, shape, normalization, o);
}

AtlasNetCorrespondence::AtlasNetCorrespondence(AtlasNet<float>& net, Index count, uint64_t seed) {
  if (!net.options().variant.learned_points) {
    Rng rng(seed, 20);
    samples_ = sample_patches(net, count, rng);
  } else {
    // v2: the samples are the learned points themselves, every one of them.
    Index total = 0;
    for (int p = 0; p < net.patches(); ++p) total += net.params.value(net.learned_points(p)).rows();
    samples_.uv.resize(total, 2);
    Index r = 0;
    for (int p = 0; p < net.patches(); ++p) {
      const auto x = net.params.value(net.learned_points(p));
      for (Index i = 0; i < x.rows(); ++i, ++r) {
        samples_.uv.row(r) = x.row(i).cast<double>();
        samples_.patch.push_back(p);
      }
    }
  }
  images_.resize(size_t(net.shapes()));
  for (int i = 0; i < net.shapes(); ++i) map_patches(net, samples_, i, images_[size_t(i)], nullptr);
}

Block<double> AtlasNetCorrespondence::operator()(int from, int to,
                                                 const Block<double>& p_unit) const {
  const int n = int(images_.size());
  JSA_CHECK(from >= 0 && from < n && to >= 0 && to < n,
            "shapes " << from << ", " << to << " of " << n);
  // The sample whose image by shape I is nearest to p, then its image by shape J.
  std::vector<int> nn;
  nearest(p_unit, images_[size_t(from)], nn);
  Block<double> q(p_unit.rows(), 3);
  for (Index r = 0; r < p_unit.rows(); ++r) q.row(r) = images_[size_t(to)].row(nn[size_t(r)]);
  return q;
}

template class AtlasNet<float>;
template class AtlasNet<double>;
template Var atlasnet_objective<float>(Tape<float>&, AtlasNet<float>&,
                                       const std::vector<Block<float>>&, Rng&, double, double*);
template Var atlasnet_objective<double>(Tape<double>&, AtlasNet<double>&,
                                        const std::vector<Block<double>>&, Rng&, double, double*);

}  // namespace jsa
