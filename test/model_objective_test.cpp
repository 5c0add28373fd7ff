// L_single (Eq. 5) end to end in double: every parameter's gradient (mu, phi,
// psi) from one backward() against central differences of the whole objective,
// for the full method and for each ablation row.
#include <catch2/catch.hpp>
#include <cmath>

#include "engine/ops.h"
#include "model/objective.h"
#include "test/small_atlas.h"
#include "test/sphere_pool.h"

using namespace jsa;

namespace {

AtlasOptions small_atlas_options() { return test_support::small_atlas(8); }

// Points on the unit sphere with their normals (= positions) scaled to alpha.
Block<double> random_targets(Index n, double alpha, uint64_t seed) {
  return test_support::sphere_pool(n, seed, alpha);
}

double objective_value(Atlas<double>& atlas, const std::vector<Block<double>>& targets,
                       const Components& c, Tape<double>& tape, bool backward) {
  Rng rng(99);  // the same draws every evaluation: the objective is a fixed function
  tape.clear();
  ObjectiveOptions o;
  o.components = c;
  Var loss = collection_objective(tape, atlas, targets, 24, rng, o, nullptr);
  if (backward) {
    atlas.params.zero_grad();
    tape.backward(loss);
  }
  return tape.scalar(loss);
}

// Central differences of value() at parameters first, first + stride, ... < end
// (value must re-evaluate the whole objective), against analytic: adds to
// `checked` and returns the worst |numeric - analytic| over its tolerance,
// 1e-7 + 1e-4 max(|numeric|, |analytic|). Small steps keep nearest-neighbour
// matches and ReLU patterns unchanged (random inputs are in general position,
// so ties and kinks are measure-zero events).
template <class Value>
double worst_central_difference(Atlas<double>& atlas, const std::vector<double>& analytic,
                                size_t first, size_t end, size_t stride, Value value,
                                int& checked) {
  double worst = 0;
  for (size_t i = first; i < end; i += stride) {
    double& x = atlas.params.values()[i];
    const double x0 = x, h = 1e-6 * std::max(1.0, std::abs(x0));
    x = x0 + h;
    const double lp = value();
    x = x0 - h;
    const double lm = value();
    x = x0;
    const double num = (lp - lm) / (2 * h);
    worst = std::max(worst, std::abs(num - analytic[i]) /
                                (1e-7 + 1e-4 * std::max(std::abs(num), std::abs(analytic[i]))));
    ++checked;
  }
  return worst;
}

}  // namespace

TEST_CASE("objective: gradients of L_single match central differences", "[objective]") {
  for (int row : {6, 7, 8, 9, 10, 11}) {
    AtlasOptions ao = small_atlas_options();
    Components c = Components::table_row(row);
    ao.gaussian_noise = c.distribution;
    Atlas<double> atlas(ao);
    Rng init(5);
    atlas.initialize(init);
    // Large weights for the small terms so that they matter in the check.
    const std::vector<Block<double>> targets{random_targets(32, ao.alpha, 3)};
    Tape<double> tape;
    objective_value(atlas, targets, c, tape, true);
    const std::vector<double> analytic = atlas.params.grads();
    // Central differences on a fixed subset of entries (every 7th).
    int checked = 0;
    const double worst = worst_central_difference(
        atlas, analytic, 0, analytic.size(), 7,
        [&]() { return objective_value(atlas, targets, c, tape, false); }, checked);
    INFO("Table 1 row " << row << ": " << checked << " entries, worst error/tolerance " << worst);
    CHECK(checked > 30);
    CHECK(worst <= 1.0);
  }
}

TEST_CASE(
    "objective: gradients of L_full for a collection (latent codes) match central differences",
    "[objective]") {
  AtlasOptions ao = small_atlas_options();
  ao.shapes = 2;
  ao.code_size = 4;
  ao.code_layer = GENERATE(0, 1);  // codes at the input, and after the first layer
  INFO("code_layer " << ao.code_layer);
  Atlas<double> atlas(ao);
  Rng init(5);
  atlas.initialize(init);
  // Codes larger than their N(0, 0.01^2) start, so that they matter in the check.
  for (const char* name : {"codes.phi", "codes.psi"}) {
    auto c = atlas.params.value(atlas.params.find(name));
    for (Index i = 0; i < c.size(); ++i) c.data()[i] = 0.3 * std::sin(1.0 + 3.0 * double(i));
  }
  const std::vector<Block<double>> targets{random_targets(32, ao.alpha, 3),
                                           random_targets(32, ao.alpha, 4)};
  const Components c;
  Tape<double> tape;
  objective_value(atlas, targets, c, tape, true);
  const std::vector<double> analytic = atlas.params.grads();
  double worst = 0;
  int checked = 0;
  for (const char* name : {"codes.phi", "codes.psi", "phi.wf", "psi.wf", "domain.mu", "phi.w0"}) {
    const auto& e = atlas.params.entry(atlas.params.find(name));
    worst = std::max(
        worst, worst_central_difference(
                   atlas, analytic, e.offset, e.offset + size_t(e.rows * e.cols), 3,
                   [&]() { return objective_value(atlas, targets, c, tape, false); }, checked));
  }
  INFO(checked << " entries, worst error/tolerance " << worst);
  CHECK(checked > 40);
  CHECK(worst <= 1.0);
}

TEST_CASE("objective: ablation rows switch the terms on one by one", "[objective]") {
  CHECK_FALSE(Components::table_row(6).normals);
  CHECK(Components::table_row(7).normals);
  CHECK_FALSE(Components::table_row(7).repulsion);
  CHECK(Components::table_row(8).repulsion);
  CHECK_FALSE(Components::table_row(8).distribution);
  CHECK(Components::table_row(9).distribution);
  CHECK_FALSE(Components::table_row(9).chart);
  CHECK(Components::table_row(10).chart);
  CHECK_FALSE(Components::table_row(10).isometry);
  CHECK(Components::table_row(11).isometry);
  CHECK_THROWS_AS(Components::table_row(5), InternalError);
}

TEST_CASE("objective: a batch of B of N shapes is their sum scaled by N / B", "[objective]") {
  AtlasOptions ao = small_atlas_options();
  ao.shapes = 3;
  ao.code_size = 4;
  Atlas<double> atlas(ao);
  Rng init(6);
  atlas.initialize(init);
  const Block<double> t0 = random_targets(24, ao.alpha, 7), t2 = random_targets(24, ao.alpha, 8);
  ObjectiveOptions o;
  o.components.repulsion = false;  // counted once per step, not per shape: compared separately
  o.weights.code = 0;
  Tape<double> tape;
  Rng r1(11);
  const double batch =
      tape.scalar(collection_objective(tape, atlas, {t2, t0}, 24, r1, o, nullptr, {2, 0}));
  tape.clear();
  Rng r2(11);
  const double l2 = tape.scalar(single_shape_objective(tape, atlas, 2, t2, 24, r2, o, nullptr));
  const double l0 = tape.scalar(single_shape_objective(tape, atlas, 0, t0, 24, r2, o, nullptr));
  CHECK(batch == Approx(1.5 * (l2 + l0)).epsilon(1e-12));
  tape.clear();
  Rng r3(11);
  CHECK_THROWS_AS(collection_objective(tape, atlas, {t2, t0}, 24, r3, o, nullptr, {2, 3}),
                  InternalError);
}

TEST_CASE(
    "objective: dense L_6D equals Eq. 7 when the pool is the step's targets, and is differentiable",
    "[objective]") {
  AtlasOptions ao = small_atlas_options();
  Atlas<double> atlas(ao);
  Rng init(12);
  atlas.initialize(init);
  const Block<double> targets = random_targets(24, ao.alpha, 13);
  ObjectiveOptions o;
  auto run = [&](const std::vector<NearestIndex<double>>& surfaces, LossTerms& terms) {
    Tape<double> tape;
    Rng rng(14);
    Var loss = collection_objective(tape, atlas, {targets}, 24, rng, o, &terms, {}, surfaces);
    atlas.params.zero_grad();
    tape.backward(loss);
    return atlas.params.grads();
  };
  LossTerms sparse_terms, same_terms, dense_terms;
  const std::vector<double> g_sparse = run({}, sparse_terms);
  std::vector<NearestIndex<double>> same;
  same.emplace_back(targets);
  const std::vector<double> g_same = run(same, same_terms);
  CHECK(same_terms.total == Approx(sparse_terms.total).epsilon(1e-12));
  double worst = 0;
  for (size_t i = 0; i < g_sparse.size(); ++i)
    worst = std::max(worst, std::abs(g_sparse[i] - g_same[i]));
  CHECK(worst < 1e-12);

  // A pool 20 times denser on the same sphere: the x_P side finds closer matches.
  std::vector<NearestIndex<double>> dense;
  dense.emplace_back(random_targets(480, ao.alpha, 15));
  run(dense, dense_terms);
  CHECK(dense_terms.surface < sparse_terms.surface);
  CHECK(dense_terms.chart ==
        Approx(sparse_terms.chart).epsilon(1e-12));  // L_2D does not see the pool

  // Central differences of the dense objective on every 7th parameter.
  const std::vector<double> analytic = run(dense, dense_terms);
  auto value = [&]() {
    Tape<double> tape;
    Rng rng(14);
    return tape.scalar(
        collection_objective(tape, atlas, {targets}, 24, rng, o, nullptr, {}, dense));
  };
  int checked = 0;
  const double worst_fd =
      worst_central_difference(atlas, analytic, 0, analytic.size(), 7, value, checked);
  INFO(checked << " entries, worst error/tolerance " << worst_fd);
  CHECK(checked > 30);
  CHECK(worst_fd <= 1.0);
}
