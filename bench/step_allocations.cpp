// Heap allocations per training step: how many times Trainer::step() calls
// malloc (operator new, Eigen's aligned buffers and nanoflann's pools all end
// there) once the step has warmed up. Counts, not times: safe to run on a busy
// machine, and the same on every run of the same binary and settings.
//
//   bench_step_allocations [INPUT ...] [--warmup W] [--steps S] [--threads T]
//                          [--points M] [--gaussians K] [--width W] [--iters N]
//                          [--schedule ramp|step] [--even-from F] [--where]
//
// INPUT: meshes or builtin:NAME (default builtin:torus); two or more make a
// collection with the command line's collection sizes (M = K = 1000, 5 x 64,
// D of 3 layers, fixed M). Runs W steps, then S steps, and prints each of the S
// steps' count and their median. Steps that take a snapshot (every
// Trainer::kSnapshotEvery) or choose the orientation (every orient_every) are
// labelled: they copy the state or evaluate phi outside the step's tape.
// --where: the call stacks of the last counted step's allocations, each with
// its count (the binary is linked with -rdynamic for the names; inlined
// functions show as their caller).
//
// How: test/allocation_counter.h, which defines malloc and its kin in this
// program so that every library's calls come to it (not under AddressSanitizer).
#include <cxxabi.h>
#include <execinfo.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "CLI/CLI.hpp"
#include "engine/parallel.h"
#include "model/tool/shape_input.h"
#include "model/tool/trainer.h"
#include "test/allocation_counter.h"

namespace {
// --where: up to kTraces call stacks of kDepth frames, recorded in place (no
// allocation inside the hook; backtrace() is warmed up before counting).
constexpr int kTraces = 8192, kDepth = 24;
std::atomic<int> g_traced{0};
void* g_frames[kTraces][kDepth];
int g_depth[kTraces];
thread_local bool t_in_hook = false;

void record_stack() {
  if (t_in_hook) return;
  const int k = g_traced.fetch_add(1);
  if (k >= kTraces) return;
  t_in_hook = true;
  g_depth[k] = backtrace(g_frames[k], kDepth);
  t_in_hook = false;
}

// One frame as "function" (demangled, without its argument list), or the raw line.
std::string frame_name(const char* line) {
  const char* open = std::strchr(line, '(');
  const char* plus = open ? std::strchr(open, '+') : nullptr;
  if (!open || !plus || plus == open + 1) return line;
  const std::string mangled(open + 1, plus);
  int status = 0;
  char* plain = abi::__cxa_demangle(mangled.c_str(), nullptr, nullptr, &status);
  std::string name = status == 0 && plain ? plain : mangled;
  std::free(plain);
  return name.size() > 150 ? name.substr(0, 150) + "..." : name;
}

// The recorded stacks, grouped, most frequent first.
void print_stacks() {
  const int n = std::min(g_traced.load(), kTraces);
  std::map<std::vector<std::string>, int> stacks;
  for (int k = 0; k < n; ++k) {
    char** lines = backtrace_symbols(g_frames[k], g_depth[k]);
    std::vector<std::string> names;
    for (int f = 2; f < g_depth[k]; ++f) {  // past count_one and the allocator
      names.push_back(frame_name(lines[f]));
      if (names.back().find("Trainer::step") != std::string::npos) break;
    }
    std::free(lines);
    ++stacks[names];
  }
  std::vector<std::pair<int, const std::vector<std::string>*>> order;
  for (const auto& [names, count] : stacks) order.push_back({count, &names});
  std::sort(order.begin(), order.end(),
            [](const auto& a, const auto& b) { return a.first > b.first; });
  for (const auto& [count, names] : order) {
    std::printf("%d x\n", count);
    for (const std::string& name : *names) std::printf("    %s\n", name.c_str());
  }
}
}  // namespace

using namespace jsa;

int main(int argc, char** argv) {
  CLI::App app{"Heap allocations per training step (malloc calls inside Trainer::step())"};
  std::vector<std::string> inputs;
  int warmup = 5, steps = 10, threads = 0;
  Index points = -1;
  int gaussians = -1, width = -1;
  int64_t iters = -1;
  std::string schedule;
  double even_from = -1;
  bool where = false;
  app.add_option("inputs", inputs, "meshes or builtin:NAME (default builtin:torus)");
  app.add_option("--warmup", warmup, "steps before counting");
  app.add_option("--steps", steps, "steps counted, one by one");
  app.add_option("--threads", threads, "threads (0: all)");
  app.add_option("--points", points, "M (default: the command line's)");
  app.add_option("--gaussians", gaussians, "K");
  app.add_option("--width", width, "hidden units");
  app.add_option("--iters", iters, "the run's length (the schedule's)");
  app.add_option("--schedule", schedule, "ramp or step");
  app.add_option("--even-from", even_from, "L_even from this fraction of the run (0: all along)");
  app.add_flag("--where", where, "print the call stacks of the last counted step's allocations");
  CLI11_PARSE(app, argc, argv);
  if (inputs.empty()) inputs = {"builtin:torus"};

  if (!allocation_counter::counting_available()) {
    std::fprintf(stderr, "bench_step_allocations: no counting under a sanitizer\n");
    return 1;
  }
  try {
    FitOptions o;
    const bool collection = inputs.size() > 1;
    if (collection) {  // as `jsatlas fit A B ...` (bin/fit_command.cpp)
      o.points = kCollectionPoints;
      o.atlas.gaussians = kCollectionGaussians;
      o.atlas.width = kCollectionWidth;
      o.atlas.deform_layers = kCollectionDeformLayers;
      o.schedule.kind = "step";
      o.iterations = kFixedScheduleIterations;
      o.lr = kCollectionLearningRate;
      o.weights.evenness = 0;
    }
    o.threads = threads;
    if (points > 0) o.points = points;
    if (gaussians > 0) o.atlas.gaussians = gaussians;
    if (width > 0) o.atlas.width = width;
    if (iters > 0) o.iterations = iters;
    if (!schedule.empty()) o.schedule.kind = schedule;
    if (even_from >= 0) o.evenness_from = even_from;
    set_threads(o.threads);
    std::vector<Block<double>> pools;
    for (size_t i = 0; i < inputs.size(); ++i)
      pools.push_back(load_run_input(inputs[i], o.pool, o.seed + 1000 * i).pool);
    Trainer trainer(o, pools);
    for (int i = 0; i < warmup; ++i) trainer.step();
    void* warm[4];
    backtrace(warm, 4);  // its first call loads the unwinder (and allocates)
    std::vector<long> counts;
    for (int i = 0; i < steps; ++i) {
      const int64_t at = trainer.iteration();
      g_traced.store(0);
      allocation_counter::on_allocation = where && i + 1 == steps ? record_stack : nullptr;
      allocation_counter::start();
      trainer.step();
      const long n = allocation_counter::stop();
      counts.push_back(n);
      std::string note;
      if (at % Trainer::kSnapshotEvery == 0) note += " (snapshot)";
      if (o.orient_every > 0 && (at + 1) % o.orient_every == 0) note += " (orientation)";
      std::printf("step %lld: M = %lld, %ld allocations%s\n", static_cast<long long>(at),
                  static_cast<long long>(trainer.points()), n, note.c_str());
    }
    if (where) print_stacks();
    std::vector<long> sorted = counts;
    std::sort(sorted.begin(), sorted.end());
    std::printf("median over %d steps: %ld allocations per step (%s, %d thread%s)\n", steps,
                sorted.empty() ? 0L : sorted[sorted.size() / 2],
                collection ? "collection" : "single shape", max_threads(),
                max_threads() == 1 ? "" : "s");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_step_allocations: %s\n", e.what());
    return 1;
  }
  return 0;
}
