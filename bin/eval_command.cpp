// `jsatlas eval RUN`: reconstruction metrics of a fitted atlas (paper Table 1,
// Chamfer association), next to the sampling floor of the shape itself.
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>

#include "bin/commands.h"
#include "engine/parallel.h"
#include "io/atomic_write.h"
#include "model/tool/checkpoint.h"
#include "model/tool/evaluate.h"
#include "model/tool/shape_input.h"

namespace jsa::cli {
namespace {

struct EvalArgs {
  std::string run, reference;
  // Ten draws: one draw's EMD ratio strays by about 0.36 (its standard
  // deviation on a fitted ant), the mean of ten by about a third of that.
  EvaluationOptions options = [] {
    EvaluationOptions o;
    o.draws = 10;
    return o;
  }();
  int threads = 0, shape = 0;
};

void run_eval(const EvalArgs& a) {
  set_threads(a.threads);
  const std::string ckpt = (std::filesystem::path(a.run) / "model.ckpt").string();
  const CheckpointContents c = read_checkpoint(ckpt);
  auto atlas = load_atlas(c, ckpt);
  if (a.shape < 0 || a.shape >= int(c.inputs.size()))
    throw InputError("--shape " + std::to_string(a.shape) + ": the run has " +
                     std::to_string(c.inputs.size()) + " shape(s), numbered from 0");
  const std::string reference = a.reference.empty() ? c.inputs[size_t(a.shape)] : a.reference;
  const Mesh shape = load_shape(reference);
  const Evaluation e =
      evaluate_reconstruction(*atlas, shape, c.normalizations[size_t(a.shape)], a.options, a.shape);
  nlohmann::json j;
  j["run"] = a.run;
  j["reference"] = reference;
  j["samples"] = a.options.samples;
  j["seed"] = a.options.seed;
  j["draws"] = a.options.draws;  // every metric below: the mean over the draws
  j["chamfer_ratio_per_draw"] = e.chamfer_ratio;
  j["emd_ratio_per_draw"] = e.emd_ratio;
  j["frame"] = "unit frame of the reference (centred, farthest point at 1)";
  j["chamfer_spatial"] = e.fit.chamfer_spatial;
  j["chamfer_normal_unit"] = e.fit.chamfer_normal;
  j["floor_chamfer_spatial"] = e.floor.chamfer_spatial;
  j["floor_chamfer_normal_unit"] = e.floor.chamfer_normal;
  j["back_facing"] = e.fit.back_facing;
  j["floor_back_facing"] = e.floor.back_facing;
  j["emd_spatial"] = e.fit_emd.spatial;
  j["emd_spatial_squared"] = e.fit_emd.spatial_squared;
  j["emd_normal_unit"] = e.fit_emd.normal;
  j["floor_emd_spatial"] = e.floor_emd.spatial;
  j["floor_emd_normal_unit"] = e.floor_emd.normal;
  j["emd_solve_seconds"] = e.fit_emd.seconds;
  // Table 1's normal columns: the same distances with normals of norm alpha = 0.01.
  j["chamfer_normal_alpha"] = 0.01 * e.fit.chamfer_normal;
  j["emd_normal_alpha"] = 0.01 * e.fit_emd.normal;
  j["floor_chamfer_normal_alpha"] = 0.01 * e.floor.chamfer_normal;
  j["floor_emd_normal_alpha"] = 0.01 * e.floor_emd.normal;
  const std::string json_path =
      a.run + (c.inputs.size() > 1 ? "/eval_" + std::to_string(a.shape) + ".json" : "/eval.json");
  write_file_atomically(json_path, [&](std::ostream& out) { out << j.dump(2) << "\n"; });
  std::printf("reconstruction of %s (M' = %lld, x 1e-2, unit frame, mean of %d draw%s)\n",
              reference.c_str(), (long long)a.options.samples, a.options.draws,
              a.options.draws == 1 ? "" : "s");
  std::printf("                     atlas   floor   ratio\n");
  std::printf("  Chamfer spatial   %6.3f  %6.3f  %5.2f\n", 100 * e.fit.chamfer_spatial,
              100 * e.floor.chamfer_spatial, e.fit.chamfer_spatial / e.floor.chamfer_spatial);
  std::printf(
      "  Chamfer normal    %6.3f  %6.3f  %5.2f   (unit normals; Table 1 uses alpha = 0.01 x "
      "these)\n",
      100 * e.fit.chamfer_normal, 100 * e.floor.chamfer_normal,
      e.fit.chamfer_normal / e.floor.chamfer_normal);
  std::printf("  back-facing %%      %6.2f  %6.2f          (Chamfer pairs with n_p . n_q < 0)\n",
              100 * e.fit.back_facing, 100 * e.floor.back_facing);
  std::printf("  EMD spatial       %6.3f  %6.3f  %5.2f   (exact assignment, %.2f s)\n",
              100 * e.fit_emd.spatial, 100 * e.floor_emd.spatial,
              e.fit_emd.spatial / e.floor_emd.spatial, e.fit_emd.seconds);
  std::printf("  EMD normal        %6.3f  %6.3f  %5.2f\n", 100 * e.fit_emd.normal,
              100 * e.floor_emd.normal, e.fit_emd.normal / e.floor_emd.normal);
  if (a.options.draws > 1) {
    const auto [cmin, cmax] = std::minmax_element(e.chamfer_ratio.begin(), e.chamfer_ratio.end());
    const auto [emin, emax] = std::minmax_element(e.emd_ratio.begin(), e.emd_ratio.end());
    std::printf(
        "  one draw's ratio ranged over: Chamfer spatial %.2f-%.2f, EMD spatial %.2f-%.2f\n", *cmin,
        *cmax, *emin, *emax);
  }
  std::printf(
      "  as Table 1 (normals of norm alpha = 0.01): normal Ch %.3f (floor %.3f), normal EMD %.3f "
      "(floor %.3f)\n",
      e.fit.chamfer_normal, e.floor.chamfer_normal, e.fit_emd.normal, e.floor_emd.normal);
  std::printf("written: %s\n", json_path.c_str());
}

}  // namespace

void add_eval(CLI::App& app) {
  auto a = std::make_shared<EvalArgs>();
  CLI::App* c = app.add_subcommand(
      "eval",
      "Reconstruction metrics of a fitted run (Table 1 Chamfer columns) and the sampling floor");
  c->add_option("run", a->run, "Run directory (holds model.ckpt)")->required();
  c->add_option("--reference", a->reference, "Ground-truth shape (default: the run's input)");
  c->add_option("--samples", a->options.samples, "M': points on each side")
      ->capture_default_str()
      ->check(CLI::Range(Index(10), Index(1000000)));
  c->add_option("--seed", a->options.seed, "Seed of the evaluation samples (draw d: seed + d)")
      ->capture_default_str();
  c->add_option("--draws", a->options.draws,
                "Independent draws of M' points, every metric their mean (one draw's EMD is "
                "noisy on thin shapes)")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000));
  c->add_option("--threads", a->threads, "Threads (0: all cores)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1024));
  c->add_option("--shape", a->shape, "Which shape of a collection (0-based)")
      ->capture_default_str();
  c->callback([a]() { run_eval(*a); });
}

}  // namespace jsa::cli
