// FitOptions from JSON (a checkpoint's settings): every malformed text is an
// InputError naming the source and the field, never a crash or a wrapped number.
#include <catch2/catch.hpp>
#include <string>

#include "engine/check.h"
#include "model/tool/fit_config.h"

namespace {

std::string message_of(const std::string& text) {
  try {
    jsa::fit_options_from_json(text, "run/model.ckpt");
  } catch (const jsa::InputError& e) {
    return e.what();
  }
  return "";
}

// `text` with `key` (first occurrence, which must be there) replaced by `to`;
// removing a key is how a settings file from before the key existed reads.
std::string replaced(std::string text, const std::string& key, const std::string& to = "") {
  const auto at = text.find(key);
  INFO(key);
  REQUIRE(at != std::string::npos);
  return text.replace(at, key.size(), to);
}

// The settings `o` written out compactly, with `key` replaced by `to`.
std::string written(const jsa::FitOptions& o, const std::string& key, const std::string& to = "") {
  return replaced(jsa::fit_options_to_json(o, -1), key, to);
}

// The defaults written out, with `from` replaced by `to`.
std::string edited(const std::string& from, const std::string& to) {
  return written(jsa::FitOptions(), from, to);
}

}  // namespace

TEST_CASE("fit config: the defaults round-trip through JSON", "[fit_config]") {
  const jsa::FitOptions o =
      jsa::fit_options_from_json(jsa::fit_options_to_json(jsa::FitOptions()), "x");
  CHECK(o.atlas.gaussians == jsa::FitOptions().atlas.gaussians);
  CHECK(o.seed == jsa::FitOptions().seed);
}

TEST_CASE(
    "fit config: the paper preset restores the paper's lambdas and keeps the run's own settings",
    "[fit_config]") {
  jsa::FitOptions o;
  REQUIRE(o.weights.cycle == 0.1);  // the laptop default (docs/method.md, "lambda_cycle")
  REQUIRE(o.orient_every == 100);   // the laptop default: the orientation mirror on
  o.iterations = 7;
  o.seed = 9;
  o.wrap_steps = 300;  // every heuristic beyond the paper on, to see the preset turn each off
  o.reseed_every = 250;
  jsa::apply_paper_preset(o);
  const jsa::LossWeights paper;
  CHECK(o.weights.surface == paper.surface);
  CHECK(o.weights.chart == paper.chart);
  CHECK(o.weights.cycle == 1.0);
  CHECK(o.weights.isometry == paper.isometry);
  CHECK(o.weights.repulsion == paper.repulsion);
  CHECK(o.atlas.gaussians == 10000);
  CHECK(o.points == 10000);
  CHECK(o.atlas.alpha == 0.01);
  CHECK(o.atlas.softplus_beta == 0);
  CHECK_FALSE(o.dense_surface);
  CHECK(o.orient_every == 0);
  CHECK(o.wrap_steps == 0);
  CHECK(o.reseed_every == 0);
  CHECK(o.iterations == 7);
  CHECK(o.seed == 9);
  CHECK(jsa::FitOptions().lr == 2e-3);          // a single shape's default
  CHECK(o.lr == jsa::kCollectionLearningRate);  // the preset's: 1e-3
  CHECK(jsa::kCollectionLearningRate == 1e-3);
  CHECK(jsa::fit_options_to_json(jsa::paper_fit_options()).find("\"cycle\": 1.0") !=
        std::string::npos);
}

TEST_CASE(
    "fit config: the paper's method (bench_table1) keeps the sizes and turns every heuristic off",
    "[fit_config]") {
  jsa::FitOptions o;
  o.wrap_steps = 300;
  o.reseed_every = 250;
  jsa::apply_paper_method(o);
  const jsa::FitOptions laptop;
  CHECK(o.atlas.gaussians == laptop.atlas.gaussians);
  CHECK(o.atlas.width == laptop.atlas.width);
  CHECK(o.points == laptop.points);
  CHECK(o.orient_every == 0);
  CHECK(o.wrap_steps == 0);
  CHECK(o.reseed_every == 0);
  CHECK_FALSE(o.dense_surface);
  CHECK(o.atlas.softplus_beta == 0);
  CHECK(o.atlas.alpha == 0.01);
  CHECK(o.weights.cycle == jsa::LossWeights{}.cycle);
  CHECK(laptop.schedule.kind == "ramp");
  CHECK(o.schedule.kind == "step");  // the paper trains at a fixed M
}

TEST_CASE("fit config: settings added later read as what older runs did", "[fit_config]") {
  jsa::FitOptions o;
  o.orient_every = 25;
  o.batch_shapes = 3;
  o.wrap_steps = 40;
  o.reseed_every = 60;
  o.dense_surface = true;
  o.atlas.softplus_beta = 7.5;
  const jsa::FitOptions back = jsa::fit_options_from_json(jsa::fit_options_to_json(o), "x");
  CHECK(back.orient_every == 25);
  CHECK(back.batch_shapes == 3);
  CHECK(back.wrap_steps == 40);
  CHECK(back.reseed_every == 60);
  CHECK(back.dense_surface);
  CHECK(back.atlas.softplus_beta == 7.5);
  // A checkpoint written before these existed: no orientation check, no
  // batching, no wrap, ReLU.
  std::string old = jsa::fit_options_to_json(o, -1);
  for (const std::string key :
       {"\"orient_every\":25,", "\"batch_shapes\":3,", ",\"wrap_steps\":40", ",\"reseed_every\":60",
        ",\"dense_surface\":true", "\"softplus_beta\":7.5,"})
    old = replaced(old, key);
  const jsa::FitOptions legacy = jsa::fit_options_from_json(old, "old");
  CHECK(legacy.orient_every == 0);
  CHECK(legacy.batch_shapes == 0);
  CHECK(legacy.wrap_steps == 0);
  CHECK(legacy.reseed_every == 0);
  CHECK(!legacy.dense_surface);
  CHECK(legacy.atlas.softplus_beta == 0);
  CHECK(message_of(edited("\"batch_shapes\":0", "\"batch_shapes\":-2")) ==
        "run/model.ckpt: sizes must be positive");
  // The GEMMs' backend (a later addition): kept both ways, a run from before
  // it ran on Eigen, and a name other than the two is refused.
  for (const jsa::Gemm g : {jsa::Gemm::eigen, jsa::Gemm::blas}) {
    jsa::FitOptions p;
    p.gemm = g;
    CHECK(jsa::fit_options_from_json(jsa::fit_options_to_json(p), "x").gemm == g);
  }
  {
    jsa::FitOptions p;
    p.gemm = jsa::Gemm::blas;
    CHECK(jsa::fit_options_from_json(written(p, ",\"gemm\":\"blas\""), "old").gemm ==
          jsa::Gemm::eigen);
  }
  CHECK(message_of(edited("\"gemm\":\"eigen\"", "\"gemm\":\"fast\"")) ==
        "run/model.ckpt: field 'gemm' must be \"eigen\" or \"blas\"");
  CHECK(message_of(edited("\"gemm\":\"eigen\"", "\"gemm\":1")) ==
        "run/model.ckpt: field 'gemm' has the wrong type");
  // Shapes split over threads (a later addition): kept both ways, and a run
  // from before it took one shape at a time.
  for (const bool split : {true, false}) {
    jsa::FitOptions p;
    p.parallel_shapes = split;
    CHECK(jsa::fit_options_from_json(jsa::fit_options_to_json(p), "x").parallel_shapes == split);
  }
  CHECK(!jsa::fit_options_from_json(written(jsa::FitOptions{}, ",\"parallel_shapes\":true"), "old")
             .parallel_shapes);
  // lambda_metric's end value (a later addition): kept, absent = constant, and
  // a non-finite one refused.
  jsa::FitOptions m;
  m.metric_end = 0.1;
  CHECK(jsa::fit_options_from_json(jsa::fit_options_to_json(m), "x").metric_end == 0.1);
  const std::string end_key = ",\"metric_end\":0.1";
  CHECK(jsa::fit_options_from_json(written(m, end_key), "old").metric_end == -1);
  CHECK_THROWS(jsa::fit_options_from_json(written(m, end_key, ",\"metric_end\":1e999"), "big"));
  // ... and where it is reached (a later addition): kept, absent = the first
  // decay, out of (0, 1] refused.
  jsa::FitOptions u;
  u.metric_until = 0.2;
  CHECK(jsa::fit_options_from_json(jsa::fit_options_to_json(u), "x").metric_until == 0.2);
  const std::string until_key = ",\"metric_until\":0.2";
  CHECK(jsa::fit_options_from_json(written(u, until_key), "old").metric_until == -1);
  for (const char* bad : {"0", "1.5", "1e999"})
    CHECK_THROWS(jsa::fit_options_from_json(
        written(u, until_key, std::string(",\"metric_until\":") + bad), "bad"));
  // The conformal L_metric (a later addition): kept, absent = isometric.
  jsa::FitOptions c;
  c.metric_conformal = true;
  CHECK(jsa::fit_options_from_json(jsa::fit_options_to_json(c), "x").metric_conformal);
  CHECK(!jsa::fit_options_from_json(written(c, ",\"metric_conformal\":true"), "old")
             .metric_conformal);
  // Later additions read as off when absent, and are kept when set: the pose
  // step's tie-break by fitting, and phi as a deformation per shape.
  jsa::FitOptions d;
  d.pose_fit_steps = 300;
  d.atlas.deform_layers = 3;
  const jsa::FitOptions read = jsa::fit_options_from_json(jsa::fit_options_to_json(d), "x");
  CHECK(read.pose_fit_steps == 300);
  CHECK(read.atlas.deform_layers == 3);
  for (const std::string key : {",\"pose_fit_steps\":300", ",\"deform_layers\":3"}) {
    const jsa::FitOptions old = jsa::fit_options_from_json(written(d, key), "old");
    CHECK(old.pose_fit_steps == (key.find("pose") != std::string::npos ? 0 : 300));
    CHECK(old.atlas.deform_layers == (key.find("deform") != std::string::npos ? 0 : 3));
  }
  CHECK_THROWS(jsa::fit_options_from_json(
      written(d, ",\"deform_layers\":3", ",\"deform_layers\":-1"), "negative"));
  // D reading the domain point: kept when set, off when absent.
  d.atlas.deform_domain = true;
  CHECK(jsa::fit_options_from_json(jsa::fit_options_to_json(d), "x").atlas.deform_domain);
  CHECK(!jsa::fit_options_from_json(written(d, ",\"deform_domain\":true"), "old")
             .atlas.deform_domain);
  // The node displacement and its registration: kept when set, off when absent.
  d.atlas.deform_nodes = 128;
  d.register_nodes = true;
  d.register_prior = 0.3;
  d.nodes_lr_scale = 0.5;
  d.nodes_width = 1.5;
  d.template_coverage = true;
  d.atlas.fine_nodes = 64;
  d.fine_width = 0.5;
  d.atlas.chart_width = 96;
  d.atlas.chart_fourier = 16;
  d.atlas.chart_fourier_sigma = 2.5;
  const jsa::FitOptions nodes = jsa::fit_options_from_json(jsa::fit_options_to_json(d), "x");
  CHECK(nodes.atlas.deform_nodes == 128);
  CHECK(nodes.register_nodes);
  CHECK(nodes.register_prior == 0.3);
  CHECK(nodes.nodes_lr_scale == 0.5);
  CHECK(nodes.nodes_width == 1.5);
  CHECK(nodes.template_coverage);
  CHECK(nodes.atlas.fine_nodes == 64);
  CHECK(nodes.fine_width == 0.5);
  CHECK(nodes.atlas.chart_width == 96);
  CHECK(nodes.atlas.chart_fourier == 16);
  CHECK(nodes.atlas.chart_fourier_sigma == 2.5);
  std::string before_nodes = jsa::fit_options_to_json(d, -1);
  for (const std::string key :
       {",\"deform_nodes\":128", ",\"register_nodes\":true", ",\"register_prior\":0.3",
        ",\"nodes_lr_scale\":0.5", ",\"nodes_width\":1.5", ",\"template_coverage\":true",
        ",\"fine_nodes\":64", ",\"fine_width\":0.5", ",\"chart_width\":96", ",\"chart_fourier\":16",
        ",\"chart_fourier_sigma\":2.5"})
    before_nodes = replaced(before_nodes, key);
  const jsa::FitOptions no_nodes = jsa::fit_options_from_json(before_nodes, "old");
  CHECK(no_nodes.atlas.deform_nodes == 0);
  CHECK(!no_nodes.register_nodes);
  CHECK(no_nodes.register_prior == 0);
  CHECK(no_nodes.nodes_lr_scale == 1);
  CHECK(no_nodes.nodes_width == 1);
  CHECK(!no_nodes.template_coverage);
  CHECK(no_nodes.atlas.fine_nodes == 0);
  CHECK(no_nodes.fine_width == 1);
  CHECK(no_nodes.atlas.chart_width == 0);
  CHECK(no_nodes.atlas.chart_fourier == 0);
  CHECK(no_nodes.atlas.chart_fourier_sigma == jsa::AtlasOptions{}.chart_fourier_sigma);
  CHECK_THROWS(jsa::fit_options_from_json(
      written(d, ",\"nodes_width\":1.5", ",\"nodes_width\":0.0"), "zero width"));
  d.atlas.deform_nodes = 0;
  d.register_nodes = false;
  d.template_coverage = false;
  d.register_prior = 0;
  d.nodes_lr_scale = 1;
  d.nodes_width = jsa::FitOptions{}.nodes_width;
  d.atlas.fine_nodes = 0;
  d.fine_width = 1;
  d.atlas.chart_width = 0;
  d.atlas.chart_fourier = 0;
  d.atlas.chart_fourier_sigma = jsa::AtlasOptions{}.chart_fourier_sigma;
  // L_6D^h's weight and its stage: kept when set, off (and the whole run) when absent.
  d.intrinsic = 0.25;
  d.intrinsic_until = 0.5;
  const jsa::FitOptions kept = jsa::fit_options_from_json(jsa::fit_options_to_json(d), "x");
  CHECK(kept.intrinsic == 0.25);
  CHECK(kept.intrinsic_until == 0.5);
  std::string before_intrinsic = jsa::fit_options_to_json(d, -1);
  for (const std::string key : {",\"intrinsic\":0.25", ",\"intrinsic_until\":0.5"})
    before_intrinsic = replaced(before_intrinsic, key);
  const jsa::FitOptions absent = jsa::fit_options_from_json(before_intrinsic, "old");
  CHECK(absent.intrinsic == 0);
  CHECK(absent.intrinsic_until == 1);
}

TEST_CASE("fit config: malformed JSON is rejected naming the source and the field",
          "[fit_config]") {
  CHECK(message_of("{\"atlas\": 3").find("run/model.ckpt: not valid JSON") == 0);
  CHECK(message_of("[1, 2]") == "run/model.ckpt: expected a JSON object");
  CHECK(message_of("{}") == "run/model.ckpt: missing field 'atlas.gaussians'");
  CHECK(message_of(edited("\"lr\":", "\"lr_\":")) == "run/model.ckpt: missing field 'lr'");
  CHECK(message_of(edited("\"width\":", "\"width\":\"wide\",\"w\":")) ==
        "run/model.ckpt: field 'atlas.width' has the wrong type");
  CHECK(message_of(edited("\"points\":", "\"points\":-3,\"p\":")) ==
        "run/model.ckpt: sizes must be positive");
}

// Found by test/fuzz/fuzz_fit_config: nlohmann's static_cast of 1e300 into an int
// was undefined behaviour (UBSan float-cast-overflow); 10^10 wrapped silently.
TEST_CASE("fuzz regressions: integer fields out of their type's range", "[fit_config][fuzz]") {
  const std::string out_of_range = "run/model.ckpt: field 'atlas.gaussians' is out of range";
  CHECK(message_of(edited("\"gaussians\":", "\"gaussians\":1e300,\"g\":")) == out_of_range);
  CHECK(message_of(edited("\"gaussians\":", "\"gaussians\":10000000000,\"g\":")) == out_of_range);
  CHECK(message_of(edited("\"gaussians\":", "\"gaussians\":2.5,\"g\":")) == out_of_range);
  CHECK(message_of(edited("\"seed\":", "\"seed\":-1,\"s\":")) ==
        "run/model.ckpt: field 'seed' is out of range");
  CHECK(message_of(edited("\"gaussians\":", "\"gaussians\":12.0,\"g\":"))
            .empty());  // a whole float is fine
}

TEST_CASE(
    "fit config: sizes beyond the command line's limits are rejected before anything is allocated",
    "[fit_config]") {
  jsa::FitOptions o;
  o.atlas.width = 1 << 20;
  const std::string text = jsa::fit_options_to_json(o);
  try {
    jsa::fit_options_from_json(text, "settings");
    FAIL("no InputError");
  } catch (const jsa::InputError& e) {
    CHECK(std::string(e.what()).find("beyond the command line's limits") != std::string::npos);
  }
}
