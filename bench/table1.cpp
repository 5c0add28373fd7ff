// The paper's Table 1 for one category of shapes, in one command: the AtlasNet
// baselines (rows 1-4, model/baselines/atlasnet.h) and the ablation of the method (rows
// 6-11, Components::table_row), each fitted to the whole category as one
// collection with every seed, then scored as the paper does (Sec. 4): Chamfer
// and exact-EMD associations on M' = 2000 samples (spatial and normal
// distances) and the correspondence error on the category's .vts keypoints.
//
//   bench_table1 --out DIR --category ant ../shared/data/shrec/ant_{1,2,3,4}.obj
//                --keypoints ../shared/data/shrec --iters 300 --seeds 4
//                [--rows 1,2,3,4,6,7,8,9,10,11,12] [--threads 1] [-M N] [-K N]
//                [--width N] [--depth N] [--code-size N]
//
// Each finished (row, seed) is written to DIR/runs/<category>_row<r>_seed<s>.json
// (atomically); a restarted command reads those back instead of redoing them,
// so it can be stopped at any time and loses at most the run in progress.
// After every run DIR/table1_<category>.md is rewritten in the paper's layout.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "bench/timing.h"
#include "engine/parallel.h"
#include "io/atomic_write.h"
#include "io/keypoints.h"
#include "model/baselines/atlasnet.h"
#include "model/tool/correspondence.h"
#include "model/tool/evaluate.h"
#include "model/tool/registration_check.h"
#include "model/tool/shape_input.h"

using namespace jsa;
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

// Table 1 reports normals scaled by alpha = 0.01 (the norm of the normals in
// phi6), and every column in units of 1e-2.
constexpr double kTableAlpha = 0.01;
constexpr double kUnits = 100;  // x 1e-2
// Row 12 is not the paper's: jsatlas's own recipe for a collection (recipe_options).
constexpr int kRecipeRow = 12;

struct Args {
  std::string out, category, keypoint_dir;
  std::vector<std::string> inputs;
  std::vector<int> rows = {1, 2, 3, 4, 6, 7, 8, 9, 10, 11, kRecipeRow};
  int seeds = 4, threads = 0;
  FitOptions fit;  // the CLI defaults of `jsatlas fit` (main: the paper's method, lr 1e-3)
  Index samples = 2000;
  std::string command;
};

std::string row_name(int row) {
  if (row <= 4) return AtlasNetVariant::table_row(row).name();
  if (row == kRecipeRow)
    return "jsatlas: row 11 + template start, D, L_metric, softplus, registration if trusted, psi "
           "on Fourier features";
  static const char* names[] = {"phi",
                                "phi, n",
                                "phi, n, L_rep",
                                "phi, n, L_rep, P",
                                "phi, n, L_rep, P, psi",
                                "phi, n, L_rep, P, psi, L_iso"};
  return names[row - 6];
}

// What a run's numbers depend on besides row and seed: a run file written at
// another budget must not be mixed into this table.
json budget_json(const Args& a) {
  json b;
  b["iterations"] = a.fit.iterations;
  b["points_M"] = a.fit.points;
  b["gaussians_K"] = a.fit.atlas.gaussians;
  b["width"] = a.fit.atlas.width;
  b["depth"] = a.fit.atlas.hidden_layers;
  b["code_size"] = a.fit.atlas.code_size;
  b["lr"] = a.fit.lr;
  b["recipe_w_even"] = 0.0;  // row 12 as `jsatlas fit` collections (L_even on before 2026-12-05)
  b["recipe_auto_register"] = kCollectionAutoRegister;  // and no registration before 2026-12-07
  b["recipe_chart_fourier"] = kCollectionChartFourier;  // the paper's psi before 2026-12-07
  b["pool"] = a.fit.pool;
  b["eval_samples"] = a.samples;
  b["inputs"] = a.inputs;
  // Only when set, so the run files written before the option (ReLU) still match.
  if (a.fit.atlas.softplus_beta > 0) b["softplus_beta"] = a.fit.atlas.softplus_beta;
  // Always: run files written before the paper paths turned the orientation
  // mirror off (they lack this key) ran it, and must not be mixed in.
  b["orient_every"] = a.fit.orient_every;
  return b;
}

std::string run_path(const Args& a, int row, int seed) {
  return (fs::path(a.out) / "runs" /
          (a.category + "_row" + std::to_string(row) + "_seed" + std::to_string(seed) + ".json"))
      .string();
}

struct Category {
  std::vector<Mesh> meshes;
  std::vector<std::vector<int>> keypoints;  // empty without --keypoints
};

// Row 12: what `jsatlas fit A B C D` trains, at this table's sizes and length,
// so that the recipe of docs/collections.md is measured next to the paper's
// rows at the same budget: jsatlas's defaults (softplus, the orientation
// mirror, the dense L_6D, L_metric), phi_i(x) = phi(x) + D(phi(x), f_i), psi
// on random Fourier features (kCollectionChartFourier), and
// the template start from the medoid, its 30% share counted in steps of equal
// cost (Trainer::template_steps_for), and the registration as the start where
// --auto-register trusts it (run_one). The poses are the stored ones, as for
// the other rows (`jsatlas fit` would also align them).
FitOptions recipe_options(const FitOptions& table, const std::vector<Block<double>>& pools) {
  FitOptions o;
  o.iterations = table.iterations;
  o.points = table.points;
  o.atlas.gaussians = table.atlas.gaussians;
  o.atlas.width = table.atlas.width;
  o.atlas.hidden_layers = table.atlas.hidden_layers;
  o.atlas.code_size = table.atlas.code_size;
  o.lr = table.lr;
  o.pool = table.pool;
  o.seed = table.seed;
  o.threads = table.threads;
  o.schedule.kind = "step";  // collections keep M fixed (bin/fit_command.cpp)
  o.weights.evenness = 0;    // and L_even off
  o.atlas.deform_layers = kCollectionDeformLayers;
  o.template_steps = -1;
  o.template_share = 0.3;
  o.template_max_steps = kTemplateMaxSteps;
  o.template_shape = medoid_shape(pools).shape;
  o.auto_register = kCollectionAutoRegister;
  o.atlas.chart_fourier = kCollectionChartFourier;  // psi on Fourier features of its 6D input
  return o;
}

// One (row, seed): fit the collection, evaluate every shape, and the keypoints.
json run_one(const Args& a, const Category& cat, int row, int seed) {
  FitOptions o = a.fit;
  o.seed = uint64_t(seed);
  std::vector<Block<double>> pools;
  std::vector<Normalization> frames;
  for (size_t i = 0; i < a.inputs.size(); ++i) {
    // As `jsatlas fit` draws them: the pool (and so the unit frame) follows the seed.
    const RunInput in = load_run_input(a.inputs[i], o.pool, o.seed + 1000 * i);
    pools.push_back(in.pool);
    frames.push_back(in.normalization);
  }
  EvaluationOptions eo;
  eo.samples = a.samples;
  json j;
  j["category"] = a.category;
  j["row"] = row;
  j["seed"] = seed;
  j["method"] = row_name(row);
  j["budget"] = budget_json(a);
  j["threads"] = max_threads();
  const auto t0 = bench::Clock::now();
  auto last_print = t0;
  auto progress = [&](int64_t it, double loss) {
    if (bench::seconds_since(last_print) < 30) return;
    last_print = bench::Clock::now();
    std::fprintf(stderr, "    it %lld/%lld  loss %.4e  (%.0f s)\n", (long long)it,
                 (long long)o.iterations, loss, bench::seconds_since(t0));
  };
  std::vector<Evaluation> evals;
  KeypointError corr;
  double train_seconds = 0;
  try {
    if (row <= 4) {
      AtlasNetTrainer tr(o, AtlasNetVariant::table_row(row), pools);
      while (!tr.finished()) {
        tr.step();
        progress(tr.iteration(), tr.last_loss());
      }
      train_seconds = bench::seconds_since(t0);
      j["final_loss"] = tr.last_loss();
      for (size_t i = 0; i < a.inputs.size(); ++i)
        evals.push_back(evaluate_atlasnet(tr.net(), cat.meshes[i], frames[i], eo, int(i)));
      if (!cat.keypoints.empty()) {
        const AtlasNetCorrespondence rule(tr.net(), CorrespondenceOptions{}.nearest_samples, 0);
        const CorrespondenceMap map = [&](int from, int to, const Block<double>& p,
                                          const Block<double>&) { return rule(from, to, p); };
        corr = keypoint_error(map, cat.meshes, frames, cat.keypoints);
      }
    } else {
      std::optional<RegistrationCheck> check;
      if (row == kRecipeRow) {
        o = recipe_options(o, pools);
        j["template_shape"] = o.template_shape;
        j["template_steps"] = Trainer::template_steps_for(o, o.iterations, int(pools.size()));
        // `jsatlas fit`'s --auto-register: the registration as the start where
        // its maps invert each other (model/tool/registration_check.h).
        check = check_registration(cat.meshes, frames, o.template_shape, o.auto_register);
        j["registration_round_trip"] = {check->spectral, check->spatial};
        j["registered"] = check->trusted;
        if (check->trusted) {
          o.atlas.deform_nodes = kAutoRegisterNodes;
          o.register_nodes = true;
          o.nodes_lr_scale = 0;
        }
      } else {
        o.components = Components::table_row(row);
      }
      Trainer tr(o, pools);
      if (check && check->trusted)
        tr.set_spectral_map(check->start.template_vertices, check->start.images);
      while (!tr.finished()) {
        tr.step();
        progress(tr.iteration(), tr.last().total);
      }
      train_seconds = bench::seconds_since(t0);
      j["final_loss"] = tr.last().total;
      j["faults"] = tr.faults();
      for (size_t i = 0; i < a.inputs.size(); ++i)
        evals.push_back(evaluate_reconstruction(tr.atlas(), cat.meshes[i], frames[i], eo, int(i)));
      if (!cat.keypoints.empty()) {
        // Rows 10-11 through psi; rows 6-9 have no chart: the nearest-sample rule.
        CorrespondenceOptions co;
        co.use_chart = o.components.chart;
        corr = keypoint_error(tr.atlas(), cat.meshes, frames, cat.keypoints, co);
      }
    }
  } catch (const NumericalFault& e) {
    // Recorded, not retried: the same seed would diverge the same way.
    j["failed"] = e.what();
    j["train_seconds"] = bench::seconds_since(t0);
    j["eval_seconds"] = 0.0;
    return j;
  }
  j["train_seconds"] = train_seconds;
  json shapes = json::array(), mean;
  const char* keys[] = {
      "chamfer_spatial",           "chamfer_normal_unit", "emd_spatial",
      "emd_normal_unit",           "back_facing",         "floor_chamfer_spatial",
      "floor_chamfer_normal_unit", "floor_emd_spatial",   "floor_emd_normal_unit"};
  for (const char* k : keys) mean[k] = 0.0;
  for (size_t i = 0; i < evals.size(); ++i) {
    const Evaluation& e = evals[i];
    json s;
    s["input"] = a.inputs[i];
    s["chamfer_spatial"] = e.fit.chamfer_spatial;
    s["chamfer_normal_unit"] = e.fit.chamfer_normal;
    s["emd_spatial"] = e.fit_emd.spatial;
    s["emd_normal_unit"] = e.fit_emd.normal;
    s["back_facing"] = e.fit.back_facing;
    s["floor_chamfer_spatial"] = e.floor.chamfer_spatial;
    s["floor_chamfer_normal_unit"] = e.floor.chamfer_normal;
    s["floor_emd_spatial"] = e.floor_emd.spatial;
    s["floor_emd_normal_unit"] = e.floor_emd.normal;
    s["emd_solve_seconds"] = e.fit_emd.seconds + e.floor_emd.seconds;  // both assignments
    for (const char* k : keys)
      mean[k] = mean[k].get<double>() + s[k].get<double>() / double(evals.size());
    shapes.push_back(s);
  }
  j["shapes"] = shapes;
  j["mean_over_shapes"] = mean;
  if (!cat.keypoints.empty()) {
    j["correspondence"] = {{"rule", row >= 10 ? "chart" : "nearest-sample"},  // 10-12: psi
                           {"mean_l2_unit_frame", corr.mean},
                           {"pairs", corr.pairs},
                           {"keypoints", corr.keypoints}};
  }
  j["eval_seconds"] = bench::seconds_since(t0) - train_seconds;
  return j;
}

json read_run(const std::string& path, const Args& a) {
  std::ifstream in(path);
  json j;
  try {
    in >> j;
  } catch (const std::exception& e) {
    throw InputError(path + ": not a readable run file (" + e.what() +
                     "); delete it to redo the run");
  }
  if (!j.contains("budget") || j["budget"] != budget_json(a))
    throw InputError(
        path +
        ": was run at another budget or on other inputs than this command's; use another --out "
        "(or delete " +
        (fs::path(a.out) / "runs").string() + ")");
  return j;
}

struct Stat {
  std::vector<double> v;
  std::string str() const {
    if (v.empty()) return "-";
    double m = 0;
    for (double x : v) m += x / double(v.size());
    char buf[64];
    if (v.size() < 2) {
      std::snprintf(buf, sizeof buf, "%.2f", m);
      return buf;
    }
    double ss = 0;
    for (double x : v) ss += (x - m) * (x - m);
    std::snprintf(buf, sizeof buf, "%.2f ± %.2f", m, std::sqrt(ss / double(v.size() - 1)));
    return buf;
  }
};

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) {
      const auto c = line.find(':');
      return c == std::string::npos ? line : line.substr(line.find_first_not_of(' ', c + 1));
    }
  return "unknown CPU";
}

std::string seconds_text(double s) {
  char buf[48];
  if (s >= 3600)
    std::snprintf(buf, sizeof buf, "%.0f h %02.0f min", std::floor(s / 3600),
                  std::floor(std::fmod(s, 3600) / 60));
  else if (s >= 60)
    std::snprintf(buf, sizeof buf, "%.0f min %02.0f s", std::floor(s / 60), std::fmod(s, 60));
  else
    std::snprintf(buf, sizeof buf, "%.1f s", s);
  return buf;
}

void write_table(const Args& a, const std::map<std::pair<int, int>, json>& runs,
                 double session_seconds) {
  const FitOptions& f = a.fit;
  double run_seconds = 0;
  for (const auto& [key, j] : runs)
    run_seconds += j["train_seconds"].get<double>() + j["eval_seconds"].get<double>();
  std::ostringstream md;
  md << "# Table 1 reproduction: " << a.category << " (" << a.inputs.size()
     << " shapes, one collection)\n\n";
  md << "- Shapes:";
  for (const std::string& s : a.inputs) md << " `" << s << "`";
  md << "\n- Budget per run: " << f.iterations << " iterations, M = " << f.points
     << " points per shape per step, K = " << f.atlas.gaussians << " Gaussians (rows 6-11), MLPs "
     << f.atlas.hidden_layers << " x " << f.atlas.width
     << (f.atlas.softplus_beta > 0 ? " softplus " + std::to_string(f.atlas.softplus_beta)
                                   : std::string(" ReLU"))
     << " (phi and psi; each of the P patch MLPs of rows 1-4), latent codes D = "
     << f.atlas.code_size << ", Adam lr " << f.lr << " decayed x" << f.decay << " at";
  for (double d : f.decay_at) md << " " << d;
  md << " of the run, pool of " << f.pool << " surface samples per shape\n";
  if (std::find(a.rows.begin(), a.rows.end(), kRecipeRow) != a.rows.end())
    md << "- Row " << kRecipeRow
       << ": `jsatlas fit`'s collection defaults at these sizes (softplus, orientation mirror, "
          "dense L_6D, L_metric, D of "
       << kCollectionDeformLayers << " layers), its template start (medoid, 30% share, at most "
       << kTemplateMaxSteps << " steps) before the " << f.iterations
       << " joint iterations, from the spectral registration where its maps invert each other "
          "(--auto-register "
       << kCollectionAutoRegister << ")\n";
  md << "- Seeds: 1.." << a.seeds << "; runs done: " << runs.size() << " of "
     << a.rows.size() * size_t(a.seeds) << "\n";
  md << "- Evaluation: M' = " << a.samples
     << " samples of prediction and ground truth per shape, unit frame; "
     << "Chamfer and exact EMD (LAPJV) associations; correspondences "
     << (a.keypoint_dir.empty()
             ? "not measured (no --keypoints)"
             : "on the .vts keypoints of `" + a.keypoint_dir + "`, all ordered pairs")
     << "\n";
  md << "- Wall time: " << seconds_text(run_seconds)
     << " summed over the runs (train + eval); this invocation " << seconds_text(session_seconds)
     << "\n";
  md << "- Machine: " << cpu_model() << ", " << std::thread::hardware_concurrency()
     << " cores; threads used: " << max_threads() << "\n";
  md << "- Command: `" << a.command << "`\n\n";
  md << "All columns x 1e-2, mean ± sample standard deviation over the seeds of the mean over the "
        "shapes. Normal "
        "columns are the mean |n_p - n_q| of unit normals times alpha = 0.01, as the paper's Table "
        "1 reports them; "
        "Corresp. L2 is the mean keypoint distance in the target's unit frame.\n\n";
  md << "| | Method | Spatial Ch. | Spatial EMD | Normal Ch. | Normal EMD | Corresp. L2 | seeds | "
        "s/run |\n";
  md << "|---|---|---|---|---|---|---|---|---|\n";
  Stat floor_ch, floor_emd, floor_nch, floor_nemd;
  for (int row : a.rows) {
    if (row == 6) md << "| | *Ours* | | | | | | | |\n";
    if (row == kRecipeRow) md << "| | *Beyond the paper* | | | | | | | |\n";
    if (row <= 4 && row == a.rows.front()) md << "| | *Baselines* | | | | | | | |\n";
    Stat ch, emd, nch, nemd, l2, secs;
    int done = 0, failed = 0;
    for (int s = 1; s <= a.seeds; ++s) {
      const auto it = runs.find({row, s});
      if (it == runs.end()) continue;
      const json& j = it->second;
      ++done;
      if (j.contains("failed")) {
        ++failed;
        continue;
      }
      const json& m = j["mean_over_shapes"];
      ch.v.push_back(kUnits * m["chamfer_spatial"].get<double>());
      emd.v.push_back(kUnits * m["emd_spatial"].get<double>());
      nch.v.push_back(kUnits * kTableAlpha * m["chamfer_normal_unit"].get<double>());
      nemd.v.push_back(kUnits * kTableAlpha * m["emd_normal_unit"].get<double>());
      if (j.contains("correspondence"))
        l2.v.push_back(kUnits * j["correspondence"]["mean_l2_unit_frame"].get<double>());
      secs.v.push_back(j["train_seconds"].get<double>() + j["eval_seconds"].get<double>());
      floor_ch.v.push_back(kUnits * m["floor_chamfer_spatial"].get<double>());
      floor_emd.v.push_back(kUnits * m["floor_emd_spatial"].get<double>());
      floor_nch.v.push_back(kUnits * kTableAlpha * m["floor_chamfer_normal_unit"].get<double>());
      floor_nemd.v.push_back(kUnits * kTableAlpha * m["floor_emd_normal_unit"].get<double>());
    }
    double mean_secs = 0;
    for (double x : secs.v) mean_secs += x / double(secs.v.size());
    char secs_buf[32];
    std::snprintf(secs_buf, sizeof secs_buf, mean_secs < 10 ? "%.1f" : "%.0f", mean_secs);
    md << "| (" << row << ") | " << row_name(row) << " | " << ch.str() << " | " << emd.str()
       << " | " << nch.str() << " | " << nemd.str() << " | " << l2.str() << " | " << done
       << (failed ? " (" + std::to_string(failed) + " diverged)" : "") << " | "
       << (secs.v.empty() ? "-" : secs_buf) << " |\n";
  }
  md << "| | *sampling floor* | " << floor_ch.str() << " | " << floor_emd.str() << " | "
     << floor_nch.str() << " | " << floor_nemd.str() << " | | | |\n\n";
  md << "The sampling floor scores the ground truth against an independent sample of itself (the "
        "best a perfect fit "
        "can reach at M'); its spread over runs comes from each seed's unit frame.\n";
  write_file_atomically((fs::path(a.out) / ("table1_" + a.category + ".md")).string(),
                        [&](std::ostream& out) { out << md.str(); });
}

std::string quoted_command(int argc, char** argv) {
  std::string c;
  for (int i = 0; i < argc; ++i) {
    const std::string s = argv[i];
    c += (i ? " " : "") + (s.find_first_of(" \t'\"") == std::string::npos ? s : "'" + s + "'");
  }
  return c;
}

void run(Args& a) {
  set_threads(a.threads);
  for (int r : a.rows)
    if (r < 1 || r > kRecipeRow || r == 5)
      throw InputError("--rows: " + std::to_string(r) +
                       " is not a row this program runs (1-4: AtlasNet, 6-11: ours, 12: "
                       "jsatlas's collection recipe; row 5, DSR, is not implemented)");
  Category cat;
  for (const std::string& in : a.inputs) cat.meshes.push_back(load_shape(in));
  if (!a.keypoint_dir.empty()) {
    if (a.inputs.size() < 2)
      throw InputError("--keypoints: correspondences need at least two shapes");
    for (size_t i = 0; i < a.inputs.size(); ++i) {
      const fs::path f =
          fs::path(a.keypoint_dir) / (fs::path(a.inputs[i]).stem().string() + ".vts");
      if (!fs::exists(f))
        throw InputError("--keypoints: no keypoint file " + f.string() + " for " + a.inputs[i]);
      cat.keypoints.push_back(read_keypoints(f.string(), long(cat.meshes[i].vertices.rows())));
    }
  }
  fs::create_directories(fs::path(a.out) / "runs");
  const auto start = bench::Clock::now();
  std::map<std::pair<int, int>, json> runs;
  const size_t total = a.rows.size() * size_t(a.seeds);
  size_t k = 0;
  std::fprintf(stderr, "table1: %s, %zu shapes, rows", a.category.c_str(), a.inputs.size());
  for (int r : a.rows) std::fprintf(stderr, " %d", r);
  std::fprintf(stderr, ", seeds 1..%d, %lld iterations per run, %d threads -> %s\n", a.seeds,
               (long long)a.fit.iterations, max_threads(), a.out.c_str());
  // Seed by seed, so that a partial table already has every row.
  for (int seed = 1; seed <= a.seeds; ++seed)
    for (int row : a.rows) {
      ++k;
      const std::string path = run_path(a, row, seed);
      if (fs::exists(path)) {
        runs[{row, seed}] = read_run(path, a);
        std::fprintf(stderr, "[%zu/%zu] row %d (%s) seed %d: read back from %s\n", k, total, row,
                     row_name(row).c_str(), seed, path.c_str());
        continue;
      }
      std::fprintf(stderr, "[%zu/%zu] row %d (%s) seed %d ...\n", k, total, row,
                   row_name(row).c_str(), seed);
      const json j = run_one(a, cat, row, seed);
      write_file_atomically(path, [&](std::ostream& out) { out << j.dump(2) << "\n"; });
      runs[{row, seed}] = j;
      if (j.contains("failed")) {
        std::fprintf(stderr, "    diverged after %.1f s: %s\n", j["train_seconds"].get<double>(),
                     j["failed"].get<std::string>().c_str());
      } else {
        const json& m = j["mean_over_shapes"];
        std::fprintf(
            stderr, "    train %.2f s, eval %.2f s: Ch %.2f  EMD %.2f  nCh %.2f  nEMD %.2f",
            j["train_seconds"].get<double>(), j["eval_seconds"].get<double>(),
            kUnits * m["chamfer_spatial"].get<double>(), kUnits * m["emd_spatial"].get<double>(),
            kUnits * kTableAlpha * m["chamfer_normal_unit"].get<double>(),
            kUnits * kTableAlpha * m["emd_normal_unit"].get<double>());
        if (j.contains("correspondence"))
          std::fprintf(stderr, "  L2 %.2f",
                       kUnits * j["correspondence"]["mean_l2_unit_frame"].get<double>());
        std::fprintf(stderr, "  (x 1e-2)\n");
      }
      write_table(a, runs, bench::seconds_since(start));
    }
  write_table(a, runs, bench::seconds_since(start));
  std::fprintf(stderr, "table1: done in %s; table in %s\n",
               seconds_text(bench::seconds_since(start)).c_str(),
               (fs::path(a.out) / ("table1_" + a.category + ".md")).string().c_str());
}

}  // namespace

int main(int argc, char** argv) {
  Args a;
  // Rows 6-11 are the paper's ablation, so they run the paper's method and
  // nothing beyond it (ReLU, alpha = 0.01, Chamfer between M and M samples, its
  // lambda_cycle; no orientation mirror, wrap or reseed), at the sizes below.
  // The AtlasNet rows 1-4 are ReLU MLPs too.
  jsa::apply_paper_method(a.fit);
  CLI::App app{
      "Table 1 of Learning Joint Surface Atlases for one category: AtlasNet baselines (rows 1-4) "
      "and the "
      "ablation (rows 6-11), several seeds, resumable"};
  app.add_option("shapes", a.inputs,
                 "The category's shapes (meshes or builtin:NAME), fitted as one collection")
      ->required();
  app.add_option("--out", a.out, "Output directory: runs/*.json and table1_<category>.md")
      ->required();
  app.add_option("--category", a.category, "Name of the category (file names, table title)")
      ->required();
  app.add_option("--keypoints", a.keypoint_dir,
                 "Directory holding <shape stem>.vts for every shape (Corresp. L2)");
  app.add_option("--iters", a.fit.iterations, "Training iterations per run")
      ->capture_default_str()
      ->check(CLI::Range(int64_t(1), int64_t(100000000)));
  app.add_option("--seeds", a.seeds, "Seeds 1..S per row")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000));
  app.add_option("--rows", a.rows, "Table 1 rows (1-4, 6-11; 12: jsatlas's collection recipe)")
      ->delimiter(',')
      ->capture_default_str();
  app.add_option("--threads", a.threads, "Threads (0: all cores)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1024));
  app.add_option("--points,-M", a.fit.points, "M: points per shape per step")
      ->capture_default_str()
      ->check(CLI::Range(Index(16), Index(1000000)));
  app.add_option("--gaussians,-K", a.fit.atlas.gaussians, "K: Gaussians of P (rows 6-11)")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000000));
  app.add_option("--width", a.fit.atlas.width, "Hidden units of every MLP")
      ->capture_default_str()
      ->check(CLI::Range(4, 4096));
  app.add_option("--depth", a.fit.atlas.hidden_layers, "Hidden layers of every MLP")
      ->capture_default_str()
      ->check(CLI::Range(1, 32));
  app.add_option("--softplus", a.fit.atlas.softplus_beta,
                 "Rows 6-11: softplus of this sharpness in phi and psi (0: ReLU, the paper)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1e6));
  app.add_option("--code-size", a.fit.atlas.code_size, "Width of the latent codes")
      ->capture_default_str()
      ->check(CLI::Range(1, 4096));
  app.add_option("--lr", a.fit.lr, "Adam learning rate")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--pool", a.fit.pool, "Surface samples drawn once per shape")
      ->capture_default_str()
      ->check(CLI::Range(Index(100), Index(10000000)));
  app.add_option("--samples", a.samples, "M': evaluation samples per shape")
      ->capture_default_str()
      ->check(CLI::Range(Index(10), Index(100000)));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  a.command = quoted_command(argc, argv);
  try {
    run(a);
  } catch (const InputError& e) {
    std::cerr << "bench_table1: error: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "bench_table1: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
