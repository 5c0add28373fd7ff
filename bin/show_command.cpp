// `jsatlas show RUN`: regenerate everything a fit writes at its end (meshes
// with UVs, UV reports, pictures) from the run's checkpoint and losses.csv.
#include <filesystem>

#include "bin/commands.h"
#include "bin/run_files.h"
#include "engine/parallel.h"
#include "model/tool/checkpoint.h"
#include "model/tool/fit_config.h"

namespace jsa::cli {
namespace {

struct ShowArgs {
  std::string run;
  MeshOutputOptions mesh;
  int threads = 0;
};

void run_show(const ShowArgs& a) {
  set_threads(a.threads);
  const std::string ckpt = (std::filesystem::path(a.run) / "model.ckpt").string();
  const CheckpointContents c = read_checkpoint(ckpt);
  auto atlas = load_atlas(c, ckpt);
  const FitOptions o = fit_options_from_json(c.settings_json, ckpt);
  std::vector<RunInput> inputs;
  for (size_t i = 0; i < c.inputs.size(); ++i) {
    RunInput in;
    in.mesh = load_shape(c.inputs[i]);
    in.normalization = c.normalizations[i];
    inputs.push_back(std::move(in));
  }
  const LossLog log = read_loss_log(a.run + "/losses.csv", o.iterations);
  write_run_outputs(*atlas, inputs, log, a.run, a.mesh);
}

}  // namespace

void add_show(CLI::App& app) {
  auto a = std::make_shared<ShowArgs>();
  CLI::App* c = app.add_subcommand(
      "show", "Regenerate a run's meshes, UV reports and pictures from its checkpoint");
  c->add_option("run", a->run, "Run directory (holds model.ckpt)")->required();
  c->add_option("--mesh-resolution", a->mesh.resolution, "Grid cells across the domain")
      ->capture_default_str()
      ->check(CLI::Range(8, 4096));
  c->add_option("--mesh-threshold", a->mesh.threshold,
                "Domain = {P >= t * median of P at the means}")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 100.0));
  c->add_option("--threads", a->threads, "Threads (0: all cores)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1024));
  c->add_option("--texture", a->mesh.texture,
                "An image for every MTL; also writes texture_transfer.png (the image on every "
                "input through its chart)");
  c->add_flag("-q,--quiet", a->mesh.quiet, "No reports on the terminal");
  c->callback([a]() { run_show(*a); });
}

}  // namespace jsa::cli
