// Tests of model/tool/gemm_choice.{h,cpp}: where the cache of `fit --gemm auto`
// lives, the products a step records, and the rule that a measured choice is
// made only when it can be kept (no cache: Eigen, unmeasured; a cache: measured
// once, then read). Every cache here is a file under the temp directory.
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "model/tool/gemm_choice.h"

namespace jsa::test {

namespace {

namespace fs = std::filesystem;

// An environment variable set (or unset, with nullptr) for one scope.
struct Env {
  std::string name;
  bool had;
  std::string before;
  Env(const char* n, const char* value) : name(n), had(std::getenv(n) != nullptr) {
    if (had) before = std::getenv(n);
    if (value)
      setenv(n, value, 1);
    else
      unsetenv(n);
  }
  ~Env() {
    if (had)
      setenv(name.c_str(), before.c_str(), 1);
    else
      unsetenv(name.c_str());
  }
};

FitOptions small_run() {
  FitOptions o;
  o.points = 200;
  o.atlas.gaussians = 100;
  o.atlas.width = 16;
  o.atlas.hidden_layers = 2;
  o.pool = 1000;
  return o;
}

fs::path scratch(const std::string& name) {
  const fs::path d =
      fs::temp_directory_path() / ("jsatlas_gemm_choice_" + name + "_" + std::to_string(getpid()));
  fs::remove_all(d);
  return d;
}

}  // namespace

TEST_CASE("the GEMM cache: JSATLAS_GEMM_CACHE, else XDG_CACHE_HOME, else HOME", "[gemm_choice]") {
  {
    const Env cache("JSATLAS_GEMM_CACHE", "/somewhere/g.json"), xdg("XDG_CACHE_HOME", "/xdg");
    CHECK(gemm_cache_path() == "/somewhere/g.json");
  }
  {
    const Env cache("JSATLAS_GEMM_CACHE", "off");
    CHECK(gemm_cache_path().empty());
  }
  {
    const Env cache("JSATLAS_GEMM_CACHE", nullptr), xdg("XDG_CACHE_HOME", "/xdg"),
        home("HOME", "/home/u");
    CHECK(gemm_cache_path() == "/xdg/jsatlas/gemm.json");
  }
  {
    const Env cache("JSATLAS_GEMM_CACHE", nullptr), xdg("XDG_CACHE_HOME", "relative"),
        home("HOME", "/home/u");
    CHECK(gemm_cache_path() == "/home/u/.cache/jsatlas/gemm.json");  // XDG wants absolute paths
  }
  {
    const Env cache("JSATLAS_GEMM_CACHE", nullptr), xdg("XDG_CACHE_HOME", nullptr),
        home("HOME", nullptr);
    CHECK(gemm_cache_path().empty());
  }
}

TEST_CASE("a step's recorded products are those of the run's networks", "[gemm_choice]") {
  const FitOptions o = small_run();
  const std::vector<GemmCall> calls = step_gemm_calls(o, 1);
  REQUIRE(!calls.empty());
  // A hidden layer's three products: H W (16 -> 16), dY W^T and H^T dY.
  bool forward = false, dx = false, dw = false;
  for (const GemmCall& g : calls) {
    forward = forward || (!g.transpose_a && !g.transpose_b && g.k == 16 && g.n == 16);
    dx = dx || (g.transpose_b && g.k == 16 && g.n == 16);
    dw = dw || (g.transpose_a && g.m == 16 && g.n == 16);
    CHECK(g.team == 1);  // one shape: the threads are inside each product
  }
  CHECK((forward && dx && dw));
  // Two shapes split over two threads: the products run in a team of two.
  FitOptions pair = o;
  pair.atlas.code_size = 8;
  pair.atlas.deform_layers = 0;
  const std::vector<GemmCall> split = step_gemm_calls(pair, 2);
  bool team = false;
  for (const GemmCall& g : split) team = team || g.team == 2;
  CHECK(team == (max_threads() >= 2));
}

// The fused softplus layer's tile products run in a team when there are two
// threads, recorded in whatever order the threads reach them: the key must
// not depend on it, or every run would measure afresh and could choose the
// other backend (a fit on two threads gave different losses twice that way).
TEST_CASE("the key repeats when the step's products run in a team", "[gemm_choice]") {
  if (!blas_built_in()) return;
  FitOptions o = small_run();
  o.points = 3000;  // phi's 6000 stacked points: several row tiles of the fused layers
  const std::vector<GemmCall> calls = step_gemm_calls(o, 1);
  bool team = false;
  for (const GemmCall& g : calls) team = team || g.team >= 2;
  CHECK(team == (max_threads() >= 2));
  const fs::path dir = scratch("team_key");
  const std::string path = (dir / "gemm.json").string();
  const GemmChoice first = choose_gemm(o, 1, path);
  CHECK(first.source == "measured");
  for (int k = 0; k < 3; ++k) {
    const GemmChoice again = choose_gemm(o, 1, path);
    CHECK(again.key == first.key);
    CHECK(again.source == "cache");
  }
  fs::remove_all(dir);
}

TEST_CASE("auto measures only where the choice is kept, then reads it back", "[gemm_choice]") {
  const FitOptions o = small_run();
  const GemmChoice none = choose_gemm(o, 1, "");
  CHECK(none.gemm == Gemm::eigen);
  CHECK(none.timing.eigen_seconds == 0);
  CHECK(none.key.empty());
  CHECK(describe(none).find("GEMMs by eigen") == 0);
  const fs::path dir = scratch("cache");
  const std::string path = (dir / "made" / "gemm.json").string();  // folders are made
  const GemmChoice first = choose_gemm(o, 1, path);
  if (!blas_built_in()) {
    CHECK(first.gemm == Gemm::eigen);
    CHECK(first.source.find("no BLAS") != std::string::npos);
    CHECK(!fs::exists(path));
    return;
  }
  INFO(describe(first));
  CHECK(first.source == "measured");
  CHECK(first.saved);
  CHECK(first.timing.eigen_seconds > 0);
  CHECK(first.timing.blas_seconds > 0);
  CHECK(first.gemm == faster_gemm(first.timing));
  std::ifstream in(path);
  const nlohmann::json cache = nlohmann::json::parse(in);
  REQUIRE(cache["choices"].contains(first.key));
  CHECK(cache["choices"][first.key]["gemm"] == gemm_name(first.gemm));
  const GemmChoice second = choose_gemm(o, 1, path);
  CHECK(second.source == "cache");
  CHECK(!second.saved);
  CHECK(second.gemm == first.gemm);
  CHECK(second.timing.blas_seconds == Approx(first.timing.blas_seconds));
  CHECK(describe(second).find("from the cache " + path) != std::string::npos);
  // Another run's products are another key: measured, the first entry kept.
  FitOptions wider = o;
  wider.atlas.width = 24;
  const GemmChoice other = choose_gemm(wider, 1, path);
  CHECK(other.source == "measured");
  CHECK(other.key != first.key);
  std::ifstream again(path);
  CHECK(nlohmann::json::parse(again)["choices"].size() == 2);
  // A file that is not a cache is replaced by one.
  std::ofstream(path) << "not json";
  const GemmChoice replaced = choose_gemm(o, 1, path);
  CHECK(replaced.source.find("replaced") != std::string::npos);
  CHECK(choose_gemm(o, 1, path).source == "cache");
  fs::remove_all(dir);
}

}  // namespace jsa::test
