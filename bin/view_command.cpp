// `jsatlas view RUN [-o page.html]`: one self-contained HTML page to look at a
// run: every shape turnable, coloured through its UVs, beside the domain P; for
// a collection, a clicked vertex carried to every other shape through psi then
// phi (the map of `jsatlas correspond`, computed here for every vertex).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "bin/commands.h"
#include "engine/parallel.h"
#include "io/atomic_write.h"
#include "io/geometry/nearest.h"
#include "io/keypoints.h"
#include "io/pictures/view_page.h"
#include "model/tool/chart_mesh.h"
#include "model/tool/checkpoint.h"
#include "model/tool/correspondence.h"
#include "model/tool/domain_mesh.h"
#include "model/tool/fit_config.h"
#include "model/tool/loss_log.h"
#include "model/tool/shape_input.h"

namespace jsa::cli {
namespace {

namespace fs = std::filesystem;

struct ViewArgs {
  std::string run, out, keypoints, three_dir;
  int resolution = 256;
  double threshold = 0.05;
  int threads = 0;
};

// The image the run's MTLs name (map_Kd of domain_mesh.mtl), if it is there.
std::string run_texture_path(const std::string& shape_dir) {
  std::ifstream in(fs::path(shape_dir) / "domain_mesh.mtl");
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string key, name;
    if (s >> key >> name && key == "map_Kd") {
      const fs::path p = fs::path(shape_dir) / name;
      if (fs::is_regular_file(p)) return p.string();
    }
  }
  return "";
}

// A box-filtered copy no larger than `size` pixels on a side: the page carries
// the texture as PNG, and 512 pixels is plenty for a turnable preview.
Image shrink(const Image& in, int size) {
  const int f = std::max(1, (std::max(in.width, in.height) + size - 1) / size);
  if (f == 1) return in;
  Image out(in.width / f, in.height / f);
  for (int y = 0; y < out.height; ++y)
    for (int x = 0; x < out.width; ++x) {
      Colour c = Colour::Zero();
      for (int j = 0; j < f; ++j)
        for (int i = 0; i < f; ++i) c += in.get(x * f + i, y * f + j);
      out.set(x, y, c / double(f * f));
    }
  return out;
}

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

// Scalar fields of a JSON report as table rows (arrays such as face lists are left out).
void add_report(std::vector<ViewTableRow>& table, const std::string& group, const fs::path& file) {
  if (!fs::is_regular_file(file)) return;
  std::ifstream in(file);
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  if (j.is_discarded() || !j.is_object()) throw InputError(file.string() + ": not a JSON report");
  for (auto it = j.begin(); it != j.end(); ++it) {
    const nlohmann::json& v = it.value();
    if (v.is_number())
      table.push_back({group, it.key(), number(v.get<double>())});
    else if (v.is_string() || v.is_boolean())
      table.push_back({group, it.key(), v.is_string() ? v.get<std::string>() : v.dump()});
  }
}

ViewCurves curves_of(const LossLog& log) {
  ViewCurves c;
  c.names = {"total", "surface_6d", "chart_2d", "cycle_2d", "cycle_6d", "isometry", "repulsion"};
  c.values.resize(c.names.size());
  for (const LossLog::Row& r : log.rows) {
    c.iterations.push_back(double(r.iteration));
    const LossTerms& t = r.terms;
    const double v[] = {t.total,    t.surface,  t.chart,    t.cycle_2d,
                        t.cycle_6d, t.isometry, t.repulsion};
    for (size_t k = 0; k < c.names.size(); ++k) c.values[k].push_back(v[k]);
  }
  return c;
}

void run_view(const ViewArgs& a) {
  set_threads(a.threads);
  const ThreeJs three = read_three_js(a.three_dir);  // first: a missing package fails fast
  const std::string ckpt = (fs::path(a.run) / "model.ckpt").string();
  const CheckpointContents contents = read_checkpoint(ckpt);
  auto atlas = load_atlas(contents, ckpt);
  const FitOptions options = fit_options_from_json(contents.settings_json, ckpt);
  const size_t n = contents.inputs.size();
  const bool collection = n > 1;
  const std::string out = a.out.empty() ? (fs::path(a.run) / "view.html").string() : a.out;

  std::vector<Mesh> meshes;
  for (const std::string& input : contents.inputs) meshes.push_back(load_shape(input));
  std::vector<std::vector<int>> keypoints(n);
  if (!a.keypoints.empty()) {
    if (!collection)
      throw InputError("view: --keypoints needs a collection (the run has one shape)");
    for (size_t i = 0; i < n; ++i) {
      const fs::path f =
          fs::path(a.keypoints) / (fs::path(contents.inputs[i]).stem().string() + ".vts");
      if (!fs::exists(f))
        throw InputError("view: no keypoint file " + f.string() + " for " + contents.inputs[i]);
      keypoints[i] = read_keypoints(f.string(), long(meshes[i].vertices.rows()));
    }
  }

  const TextureFrame frame = texture_frame(*atlas);
  const DomainMesh dm = mesh_domain(*atlas, DomainMeshOptions{a.resolution, a.threshold});
  if (dm.faces.rows() == 0)
    throw InputError("view: no domain above --mesh-threshold " + std::to_string(a.threshold));
  CorrespondenceOptions co;
  co.use_chart = options.components.chart;

  ViewPage page;
  page.title = "jsatlas view: " + fs::path(a.run).filename().string();
  if (page.title.back() == ' ') page.title = "jsatlas view: " + a.run;
  for (size_t i = 0; i < n; ++i) {
    const Mesh& m = meshes[i];
    const Normalization& f = contents.normalizations[i];
    ViewShape s;
    s.name = fs::path(contents.inputs[i]).filename().string();
    s.vertices = f.to_unit(m.vertices);
    s.faces = m.faces;
    if (co.use_chart) s.uv = frame.to_texture(chart_vertices(*atlas, m, f, int(i)));
    Block<double> normals;
    evaluate_surface(*atlas, dm.uv, s.domain_vertices, normals, int(i));
    s.domain_faces = dm.faces;
    s.domain_uv = frame.to_texture(dm.uv);
    if (collection) {
      // Every vertex of shape i to every other shape j, exactly as `jsatlas
      // correspond --from i --to j --vertices ... --snap` does: q = phi_j(psi_i(p)),
      // then the nearest vertex of j's input, in j's own frame.
      // In the unit frame, as the points: turned by the shape's pose (rotations.json).
      const Block<double> vertex_normals = f.normals_to_unit(vertex_normals_of(m));
      s.correspondence.resize(n);
      s.keypoint_error.resize(n);
      for (size_t j = 0; j < n; ++j) {
        if (j == i) continue;
        const Normalization& fj = contents.normalizations[j];
        const Block<double> q =
            fj.from_unit(correspond(*atlas, int(i), int(j), s.vertices, vertex_normals, co));
        nearest(q, meshes[j].vertices, s.correspondence[j]);
        // Keypoint m: the error of the paper's metric, |q - keypoint m of j| in j's unit frame.
        for (size_t k = 0; k < keypoints[i].size(); ++k) {
          const Eigen::RowVector3d qu = (q.row(keypoints[i][k]) - fj.center) / fj.scale;
          const Eigen::RowVector3d gt =
              (meshes[j].vertices.row(keypoints[j][k]) - fj.center) / fj.scale;
          s.keypoint_error[j].push_back((qu - gt).norm());
        }
      }
      s.keypoints = keypoints[i];
    }
    page.shapes.push_back(std::move(s));
  }
  page.domain.means = frame.to_texture(atlas->params.value(atlas->domain.means()).cast<double>());
  page.domain.sigma = atlas->domain.sigma() / frame.side;

  const std::string shape0_dir = collection ? a.run + "/shape_0" : a.run;
  const std::string texture = run_texture_path(shape0_dir);
  page.texture = shrink(texture.empty() ? colour_chart(512) : read_image(texture), 512);
  page.table.push_back(
      {"run", "texture",
       texture.empty() ? "built-in colour chart" : fs::path(texture).filename().string()});
  page.table.push_back({"run", "shapes", std::to_string(n)});
  page.table.push_back({"run", "iterations", std::to_string(options.iterations)});
  page.table.push_back(
      {"run", "gaussians K", std::to_string(atlas->params.value(atlas->domain.means()).rows())});
  page.curves = curves_of(read_loss_log(a.run + "/losses.csv", options.iterations));

  if (collection) {
    for (size_t i = 0; i < n; ++i) {
      const fs::path dir = fs::path(a.run) / ("shape_" + std::to_string(i));
      add_report(page.table, "eval_" + std::to_string(i) + ".json",
                 fs::path(a.run) / ("eval_" + std::to_string(i) + ".json"));
      add_report(page.table, "shape_" + std::to_string(i) + "/input_chart_uv.json",
                 dir / "input_chart_uv.json");
      add_report(page.table, "shape_" + std::to_string(i) + "/domain_mesh_uv.json",
                 dir / "domain_mesh_uv.json");
    }
    add_report(page.table, "eval_corr.json", fs::path(a.run) / "eval_corr.json");
    if (!a.keypoints.empty()) {
      const KeypointError e =
          keypoint_error(*atlas, meshes, contents.normalizations, keypoints, co);
      const std::string g = "keypoints (" + a.keypoints + ")";
      page.table.push_back({g, "mean L2 x1e-2, unit frame", number(100 * e.mean)});
      for (size_t t = 0; t < e.thresholds.size(); ++t)
        page.table.push_back(
            {g, "within " + number(e.thresholds[t]), number(100 * e.within[t]) + "%"});
    }
  } else {
    add_report(page.table, "eval.json", fs::path(a.run) / "eval.json");
    add_report(page.table, "input_chart_uv.json", fs::path(a.run) / "input_chart_uv.json");
    add_report(page.table, "domain_mesh_uv.json", fs::path(a.run) / "domain_mesh_uv.json");
  }

  const std::string html = view_page_html(page, three);
  write_file_atomically(
      out, [&](std::ostream& f) { f.write(html.data(), std::streamsize(html.size())); });
  std::printf("written: %s (%.2f MB; %zu shape%s)\n", out.c_str(), double(html.size()) / (1 << 20),
              n, n == 1 ? "" : "s");
}

}  // namespace

void add_view(CLI::App& app) {
  auto a = std::make_shared<ViewArgs>();
  CLI::App* c = app.add_subcommand("view",
                                   "Write one self-contained HTML page showing a run: shapes, UVs, "
                                   "domain, correspondences, losses");
  c->add_option("run", a->run, "Run directory (holds model.ckpt)")->required();
  c->add_option("-o,--out", a->out, "Page to write (default: RUN/view.html)");
  c->add_option("--keypoints", a->keypoints,
                "Collections: a directory holding <input stem>.vts per shape; the page shows each "
                "keypoint's error");
  c->add_option("--three-dir", a->three_dir,
                "Where three.min.js and examples/js/controls/OrbitControls.js are (default: "
                "/usr/share/javascript/three, Debian's libjs-three)");
  c->add_option("--mesh-resolution", a->resolution,
                "Grid cells across the domain for the meshed domain")
      ->capture_default_str()
      ->check(CLI::Range(8, 4096));
  c->add_option("--mesh-threshold", a->threshold, "Domain = {P >= t * median of P at the means}")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 100.0));
  c->add_option("--threads", a->threads, "Threads (0: all cores)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1024));
  c->callback([a]() { run_view(*a); });
}

}  // namespace jsa::cli
