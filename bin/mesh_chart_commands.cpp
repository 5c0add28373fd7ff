// `jsatlas mesh RUN -o OUT.obj`: the learned domain, thresholded, meshed and
// mapped through phi. `jsatlas chart RUN INPUT -o OUT.obj`: the UV map of a
// mesh of the user's through psi, vertex and face order kept.
#include <filesystem>

#include "bin/commands.h"
#include "bin/run_files.h"
#include "engine/parallel.h"
#include "model/tool/checkpoint.h"

namespace jsa::cli {
namespace {

struct LoadedRun {
  CheckpointContents contents;
  std::unique_ptr<Atlas<float>> atlas;
};

LoadedRun load_run(const std::string& run) {
  const std::string ckpt = (std::filesystem::path(run) / "model.ckpt").string();
  LoadedRun r;
  r.contents = read_checkpoint(ckpt);
  r.atlas = load_atlas(r.contents, ckpt);
  return r;
}

struct MeshArgs {
  std::string run, out;
  MeshOutputOptions options;
  int threads = 0, shape = 0;
};

struct ChartArgs {
  std::string run, input, out;
  ChartOutputOptions options;
  int threads = 0, shape = 0;
};

int checked_shape(const LoadedRun& r, int shape) {
  if (shape < 0 || shape >= int(r.contents.inputs.size()))
    throw InputError("--shape " + std::to_string(shape) + ": the run has " +
                     std::to_string(r.contents.inputs.size()) + " shape(s), numbered from 0");
  return shape;
}

// The options `mesh` and `chart` share: threads, shape, and the texture the UVs are for.
template <class Args>
void add_shared_options(CLI::App* c, Args& a, const std::string& padding_help) {
  c->add_option("--threads", a.threads, "Threads (0: all cores)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1024));
  c->add_option("--shape", a.shape, "Which shape of a collection (0-based)")->capture_default_str();
  c->add_option("--texture", a.options.texture,
                "An image for the MTL instead of the built-in colour chart (a texture made for one "
                "shape of a collection fits every shape)");
  c->add_option("--texture-size", a.options.texture_size,
                "Texels per side of the texture the UVs are for")
      ->capture_default_str()
      ->check(CLI::Range(16, 65536));
  c->add_option("--padding", a.options.padding, padding_help)
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1024.0));
  c->add_flag("-q,--quiet", a.options.quiet, "No report on the terminal");
}

}  // namespace

void add_mesh(CLI::App& app) {
  auto a = std::make_shared<MeshArgs>();
  CLI::App* c = app.add_subcommand(
      "mesh", "Mesh the learned domain (threshold of P) and map it through phi: OBJ with UVs");
  c->add_option("run", a->run, "Run directory (holds model.ckpt)")->required();
  c->add_option(
       "-o,--out", a->out,
       "Output OBJ (an .mtl, texture PNG, _uv.json report and .png views are written next to it)")
      ->required();
  c->add_option("--resolution", a->options.resolution, "Grid cells across the domain")
      ->capture_default_str()
      ->check(CLI::Range(8, 4096));
  c->add_option("--threshold", a->options.threshold, "Domain = {P >= t * median of P at the means}")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 100.0));
  add_shared_options(c, *a, "Texels between the layout and the texture's border");
  c->callback([a]() {
    set_threads(a->threads);
    LoadedRun r = load_run(a->run);
    const int i = checked_shape(r, a->shape);
    write_domain_mesh(*r.atlas, r.contents.normalizations[size_t(i)], a->out, a->options, i);
  });
}

void add_chart(CLI::App& app) {
  auto a = std::make_shared<ChartArgs>();
  CLI::App* c = app.add_subcommand(
      "chart", "UV map of a mesh through the chart psi (vertex and face order kept): OBJ with vt");
  c->add_option("run", a->run, "Run directory (holds model.ckpt)")->required();
  c->add_option("input", a->input, "The mesh to chart (default: the run's own input)");
  c->add_option("-o,--out", a->out,
                "Output OBJ (.mtl, texture, _uv.json report, .png and _layout.png next to it)")
      ->required();
  c->add_flag("--psi-only", a->options.psi_only,
              "Write psi's UVs as they are (flips, overlap and torn triangles included): no cut, "
              "repair or packing");
  c->add_flag("--split-cuts", a->options.split_cuts,
              "With --psi-only: give triangles torn across the cut their own UV corners");
  c->add_flag(
      "--no-pack", [a](std::int64_t) { a->options.pack = false; },
      "Keep each valid chart where psi puts it (the shared-domain layout, for texture transfer "
      "across a collection; charts may overlap each other)");
  c->add_option("--torn-ratio", a->options.torn_ratio,
                "A UV edge this many times longer than its 3D edge (areas equalised) is torn")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 1e6));
  add_shared_options(c, *a, "Texels between packed charts and along the border");
  c->callback([a]() {
    set_threads(a->threads);
    LoadedRun r = load_run(a->run);
    const int i = checked_shape(r, a->shape);
    const Mesh mesh = load_shape(a->input.empty() ? r.contents.inputs[size_t(i)] : a->input);
    write_chart(*r.atlas, r.contents.normalizations[size_t(i)], mesh, a->out, a->options, i);
  });
}

}  // namespace jsa::cli
