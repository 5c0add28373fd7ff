#include "model/tool/gemm_choice.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "engine/parallel.h"
#include "engine/rng.h"
#include "io/atomic_write.h"

namespace jsa {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) != 0) continue;
    const size_t colon = line.find(':');
    const size_t begin = line.find_first_not_of(" \t", colon + 1);
    if (colon != std::string::npos && begin != std::string::npos) return line.substr(begin);
  }
  return "unknown CPU";
}

// The step's products as one number (FNV-1a over every field of every call):
// another network, M, shape count or thread split is another key. A team's
// threads record their calls in the order they start, which the threads'
// interleaving decides (the fused softplus layer's row tiles, a collection's
// per-shape workers): the calls are hashed grouped by (team, thread), each
// thread's in its own order, so the same run gives the same key every time.
// Without team calls the order, and so the key, is the recorded one.
std::string signature(std::vector<GemmCall> calls) {
  std::stable_sort(calls.begin(), calls.end(), [](const GemmCall& a, const GemmCall& b) {
    return a.team != b.team ? a.team < b.team : a.thread < b.thread;
  });
  uint64_t h = 14695981039346656037ull;
  auto mix = [&](int64_t v) {
    for (int byte = 0; byte < 8; ++byte) {
      h ^= uint64_t(v >> (8 * byte)) & 0xff;
      h *= 1099511628211ull;
    }
  };
  for (const GemmCall& g : calls) {
    mix(g.transpose_a);
    mix(g.transpose_b);
    mix(g.accumulate);
    mix(g.m);
    mix(g.n);
    mix(g.k);
    mix(g.team);
    mix(g.thread);
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return std::string(hex) + " (" + std::to_string(calls.size()) + " products)";
}

// An exclusive lock (flock) on PATH.lock while it lives: the read, measure,
// write of one run is not interleaved with another's.
class CacheLock {
 public:
  explicit CacheLock(const std::string& path) {
    fd_ = ::open((path + ".lock").c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ >= 0 && ::flock(fd_, LOCK_EX) != 0) {
      ::close(fd_);
      fd_ = -1;
    }
  }
  ~CacheLock() {
    if (fd_ >= 0) ::close(fd_);  // closing releases the lock
  }
  CacheLock(const CacheLock&) = delete;
  CacheLock& operator=(const CacheLock&) = delete;
  bool held() const { return fd_ >= 0; }

 private:
  int fd_ = -1;
};

// {"about": ..., "choices": {KEY: {"gemm", "eigen_ms", "blas_ms", "repeats"}}};
// an empty one when the file is missing, or is not such a file (*replaced).
json read_cache(const std::string& path, bool* replaced) {
  std::ifstream in(path);
  if (!in) return json::object();
  try {
    json j = json::parse(in);
    if (j.is_object() && j.contains("choices") && j["choices"].is_object()) return j;
  } catch (const std::exception&) {
  }
  *replaced = true;
  return json::object();
}

}  // namespace

std::string gemm_cache_path() {
  if (const char* p = std::getenv("JSATLAS_GEMM_CACHE")) {
    const std::string s = p;
    return s == "off" ? "" : s;
  }
  const char* xdg = std::getenv("XDG_CACHE_HOME");
  if (xdg && xdg[0] == '/') return std::string(xdg) + "/jsatlas/gemm.json";
  const char* home = std::getenv("HOME");
  if (home && home[0] != '\0') return std::string(home) + "/.cache/jsatlas/gemm.json";
  return "";
}

std::vector<GemmCall> step_gemm_calls(const FitOptions& o, int shapes) {
  FitOptions p = o;
  p.wrap_steps = 0;
  p.template_steps = 0;
  p.template_share = 0;
  p.template_shape = 0;
  p.template_max_steps = 0;
  p.reseed_every = 0;
  p.orient_every = 0;
  p.chart_from = 0;  // the full method: most of a run
  p.intrinsic = 0;
  p.schedule.kind = "step";  // the run's full M: where its time goes
  p.iterations = std::max<int64_t>(p.iterations, 1);
  // Points on the unit sphere with their normals, the same for every shape.
  const Index rows = std::max<Index>(p.points, 1000);
  Block<double> pool(rows, 6);
  Rng rng(1);
  for (Index r = 0; r < rows; ++r) {
    const double x = rng.normal(), y = rng.normal(), z = rng.normal();
    const double length = std::max(std::sqrt(x * x + y * y + z * z), 1e-9);
    pool.row(r) << x / length, y / length, z / length, x / length, y / length, z / length;
  }
  Trainer probe(p, std::vector<Block<double>>(size_t(std::max(shapes, 1)), pool));
  const GemmRecorder recorder;
  probe.step();
  return recorder.calls();
}

GemmChoice choose_gemm(const FitOptions& o, int shapes, const std::string& cache_path) {
  GemmChoice c;
  c.cache = cache_path;
  if (!blas_built_in()) {
    c.source = "this jsatlas has no BLAS backend";
    return c;
  }
  if (cache_path.empty()) {
    c.source =
        "no cache to keep a measurement in (JSATLAS_GEMM_CACHE=off, or no home "
        "directory): not measured";
    return c;
  }
  const std::vector<GemmCall> calls = step_gemm_calls(o, shapes);
  c.key = "cpu " + cpu_model() + " | Eigen " + Eigen::SimdInstructionSetsInUse() + " | " +
          std::to_string(max_threads()) + " threads | " + blas_description() + " | step " +
          signature(calls);
  const fs::path folder = fs::path(cache_path).parent_path();
  std::error_code ignored;
  if (!folder.empty()) fs::create_directories(folder, ignored);
  const CacheLock lock(cache_path);
  if (!lock.held()) {
    c.source = "cannot lock the cache (" + cache_path + ".lock): not measured";
    c.key.clear();
    return c;
  }
  bool replaced = false;
  json cache = read_cache(cache_path, &replaced);
  json& choices = cache["choices"];
  if (choices.is_object() && choices.contains(c.key)) {
    const json& e = choices[c.key];
    Gemm g = Gemm::eigen;
    if (e.is_object() && e.contains("gemm") && e["gemm"].is_string() &&
        parse_gemm(e["gemm"].get<std::string>(), &g)) {
      c.gemm = g;
      c.timing.eigen_seconds = e.value("eigen_ms", 0.0) * 1e-3;
      c.timing.blas_seconds = e.value("blas_ms", 0.0) * 1e-3;
      c.timing.repeats = e.value("repeats", 0);
      c.source = "cache";
      return c;
    }
  }
  c.timing = time_gemm_calls(calls);
  const Gemm measured = faster_gemm(c.timing);
  cache["about"] =
      "jsatlas fit --gemm auto: the GEMM backend measured once per CPU, build, thread count, "
      "BLAS and set of a step's products (docs/performance.md); delete the file to measure again";
  choices[c.key] = {{"gemm", gemm_name(measured)},
                    {"eigen_ms", c.timing.eigen_seconds * 1e3},
                    {"blas_ms", c.timing.blas_seconds * 1e3},
                    {"repeats", c.timing.repeats},
                    {"margin", kGemmMargin}};
  try {
    write_file_atomically(cache_path, [&](std::ostream& out) { out << cache.dump(2) << "\n"; });
  } catch (const std::exception& e) {
    c.source =
        std::string("measured, but the cache could not be written (") + e.what() + "), so not used";
    return c;  // Eigen: a choice that is not kept could flip in the next run
  }
  c.gemm = measured;
  c.saved = true;
  c.source = replaced ? "measured; the file was not a cache and was replaced" : "measured";
  return c;
}

std::string describe(const GemmChoice& c) {
  std::string s = std::string("GEMMs by ") + gemm_name(c.gemm);
  if (c.gemm == Gemm::blas) s += " (" + blas_description() + ")";
  if (!(c.timing.eigen_seconds > 0 && c.timing.blas_seconds > 0)) return s + ": " + c.source;
  char buf[256];
  std::snprintf(buf, sizeof buf,
                ": a step's products in %.1f ms by Eigen, %.1f ms by the BLAS (%.2fx; the BLAS "
                "needs %.2fx)",
                c.timing.eigen_seconds * 1e3, c.timing.blas_seconds * 1e3,
                c.timing.eigen_seconds / c.timing.blas_seconds, kGemmMargin);
  s += buf;
  if (c.source == "cache") return s + ", from the cache " + c.cache;
  std::snprintf(buf, sizeof buf, "; %s in %.2f s", c.source.c_str(), c.timing.wall_seconds);
  s += buf;
  return c.saved ? s + ", kept in " + c.cache : s;
}

}  // namespace jsa
