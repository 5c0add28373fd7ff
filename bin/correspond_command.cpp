// `jsatlas correspond RUN --from I --to J ...`: carry points from shape I of a
// collection to shape J through the shared domain; `jsatlas eval-corr RUN
// --keypoints ...`: the paper's correspondence metric on SHREC .vts keypoints.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "bin/commands.h"
#include "engine/parallel.h"
#include "io/atomic_write.h"
#include "io/geometry/nearest.h"
#include "io/keypoints.h"
#include "model/tool/checkpoint.h"
#include "model/tool/correspondence.h"
#include "model/tool/fit_config.h"
#include "model/tool/geodesic_refinement.h"
#include "model/tool/shape_input.h"
#include "model/tool/spectral_refinement.h"

namespace jsa::cli {
namespace {

namespace fs = std::filesystem;

struct Run {
  CheckpointContents contents;
  std::unique_ptr<Atlas<float>> atlas;
  FitOptions options;
};

Run open_run(const std::string& dir) {
  const std::string ckpt = (fs::path(dir) / "model.ckpt").string();
  Run r;
  r.contents = read_checkpoint(ckpt);
  r.atlas = load_atlas(r.contents, ckpt);
  r.options = fit_options_from_json(r.contents.settings_json, ckpt);
  return r;
}

void check_shape(const Run& r, int s, const char* flag) {
  if (s < 0 || s >= int(r.contents.inputs.size()))
    throw InputError(std::string(flag) + " " + std::to_string(s) + ": the run has " +
                     std::to_string(r.contents.inputs.size()) + " shape(s), numbered from 0");
}

Block<double> read_points(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open the points file");
  std::vector<Eigen::RowVector3d> rows;
  std::string line;
  int lineno = 0;
  while (std::getline(in, line)) {
    ++lineno;
    std::istringstream s(line);
    double x, y, z;
    std::string first;
    if (!(s >> first) || first[0] == '#') continue;
    std::istringstream s2(line);
    if (!(s2 >> x >> y >> z) || !std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z))
      throw InputError(path + ":" + std::to_string(lineno) +
                       ": expected three finite numbers x y z");
    rows.emplace_back(x, y, z);
  }
  if (rows.empty()) throw InputError(path + ": no points");
  Block<double> p(Index(rows.size()), 3);
  for (size_t i = 0; i < rows.size(); ++i) p.row(Index(i)) = rows[i];
  return p;
}

struct CorrespondArgs {
  std::string run, points_file, out;
  std::vector<long> vertices;
  int from = 0, to = 1, threads = 0;
  bool snap = false, nearest_rule = false, spectral = false, geodesic = false;
  SpectralRefinementOptions spectral_options;
  GeodesicRefinementOptions geodesic_options;
};

// Flags of the spectral refinement, shared by correspond and eval-corr.
void add_spectral_flags(CLI::App* c, bool& on, SpectralRefinementOptions& o) {
  c->add_flag("--spectral", on,
              "Refine the atlas's map by ZoomOut on the shapes' Laplace-Beltrami "
              "eigenfunctions (meshes only; docs/collections.md)");
  c->add_option("--spectral-functions", o.functions,
                "--spectral: eigenfunctions per shape, ZoomOut's last size")
      ->capture_default_str()
      ->check(CLI::Range(2, 500));
  c->add_option("--spectral-k-start", o.k_start,
                "--spectral: ZoomOut's first size (how much of the atlas's map is kept)")
      ->capture_default_str()
      ->check(CLI::Range(1, 500));
  c->add_option("--spectral-prior", o.prior_weight,
                "--spectral: weight of the atlas's map as a spatial prior in ZoomOut (0: none)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1e6));
  c->add_option("--spectral-prior-until", o.prior_until,
                "--spectral: the prior acts on ZoomOut's sizes below this")
      ->capture_default_str()
      ->check(CLI::Range(1, 1 << 30));
  c->add_flag("!--spectral-one-way", o.both_directions,
              "--spectral: refine the direction I -> J only (by default both directions are "
              "refined and, per point, the image nearer the atlas's own is taken)");
  c->add_flag("--spectral-consensus", o.consensus,
              "--spectral, 3 or more shapes: per point, the medoid of every map's estimate "
              "(the atlas's, both directions', and through each other shape)");
}

// Flags of the geodesic refinement, shared by correspond and eval-corr.
void add_geodesic_flags(CLI::App* c, bool& on, GeodesicRefinementOptions& o) {
  c->add_flag("--geodesic", on,
              "Finish the map by geodesic landmarks: I's farthest points carried by the map, "
              "each point matched by its distances along the surface to them (meshes only)");
  c->add_option("--geodesic-landmarks", o.landmarks, "--geodesic: landmarks per shape")
      ->capture_default_str()
      ->check(CLI::Range(1, 4096));
  c->add_option("--geodesic-tau", o.tau,
                "--geodesic: landmark k weighs exp(-d_k / tau), d_k in sqrt(A / 4 pi) (0: all 1)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1e6));
  c->add_option("--geodesic-cycle", o.cycle_tolerance,
                "--geodesic: leave out a landmark the map does not carry back to within this "
                "(unit frame; 0: keep all)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1e6));
}

// The map's image moved to the target's nearest input vertex.
CorrespondenceMap snapped(CorrespondenceMap base, const std::vector<Mesh>& meshes,
                          const std::vector<Normalization>& frames) {
  auto vertices = std::make_shared<std::vector<Block<double>>>();
  for (size_t s = 0; s < meshes.size(); ++s)
    vertices->push_back(frames[s].to_unit(meshes[s].vertices));
  return [base, vertices](int from, int to, const Block<double>& p, const Block<double>& n) {
    const Block<double> q = base(from, to, p, n);
    std::vector<int> at;
    nearest(q, (*vertices)[size_t(to)], at);
    Block<double> out(q.rows(), 3);
    for (Index m = 0; m < q.rows(); ++m) out.row(m) = (*vertices)[size_t(to)].row(at[size_t(m)]);
    return out;
  };
}

void run_correspond(const CorrespondArgs& a) {
  set_threads(a.threads);
  Run r = open_run(a.run);
  check_shape(r, a.from, "--from");
  check_shape(r, a.to, "--to");
  const Mesh source = load_shape(r.contents.inputs[size_t(a.from)]);
  const Normalization& fi = r.contents.normalizations[size_t(a.from)];
  const Normalization& fj = r.contents.normalizations[size_t(a.to)];
  const Block<double> source_normals = vertex_normals_of(source);
  Block<double> p, pn;
  if (!a.vertices.empty()) {
    p.resize(Index(a.vertices.size()), 3);
    pn.resize(p.rows(), 3);
    for (size_t k = 0; k < a.vertices.size(); ++k) {
      if (a.vertices[k] < 0 || a.vertices[k] >= source.vertices.rows())
        throw InputError("--vertices: " + std::to_string(a.vertices[k]) + " is not a vertex of " +
                         r.contents.inputs[size_t(a.from)] + " (" +
                         std::to_string(source.vertices.rows()) + " vertices)");
      p.row(Index(k)) = source.vertices.row(a.vertices[k]);
      pn.row(Index(k)) = source_normals.row(a.vertices[k]);
    }
  } else if (!a.points_file.empty()) {
    p = read_points(a.points_file);
    // A point's normal is that of the nearest vertex of the source mesh.
    std::vector<int> nn;
    nearest(p, source.vertices, nn);
    pn.resize(p.rows(), 3);
    for (Index i = 0; i < p.rows(); ++i) pn.row(i) = source_normals.row(nn[size_t(i)]);
  } else {
    throw InputError("correspond: give a POINTS file or --vertices");
  }
  CorrespondenceOptions co;
  co.use_chart = r.options.components.chart && !a.nearest_rule;
  CorrespondenceMap map = [&](int from, int to, const Block<double>& pu,
                              const Block<double>& normals) {
    return correspond(*r.atlas, from, to, pu, normals, co);
  };
  if (a.spectral) {
    std::vector<Mesh> meshes;
    for (const std::string& input : r.contents.inputs) meshes.push_back(load_shape(input));
    map = spectral_refinement(map, meshes, r.contents.normalizations, a.spectral_options);
  }
  if (a.geodesic) {
    std::vector<Mesh> meshes;
    for (const std::string& input : r.contents.inputs) meshes.push_back(load_shape(input));
    map = geodesic_refinement(map, meshes, r.contents.normalizations, a.geodesic_options);
  }
  const Block<double> q = fj.from_unit(map(a.from, a.to, fi.to_unit(p), fi.normals_to_unit(pn)));
  std::vector<int> snapped;
  if (a.snap) {
    const Mesh target = load_shape(r.contents.inputs[size_t(a.to)]);
    nearest(q, target.vertices, snapped);
  }
  std::ostringstream out;
  out.precision(9);
  out << "# x y z on shape " << a.to << " (" << r.contents.inputs[size_t(a.to)]
      << "), its own frame" << (a.snap ? "; nearest vertex index" : "") << "\n";
  for (Index i = 0; i < q.rows(); ++i) {
    out << q(i, 0) << " " << q(i, 1) << " " << q(i, 2);
    if (a.snap) out << " " << snapped[size_t(i)];
    out << "\n";
  }
  if (a.out.empty())
    std::cout << out.str();
  else
    write_file_atomically(a.out, [&](std::ostream& f) { f << out.str(); });
}

struct EvalCorrArgs {
  std::string run;
  std::vector<std::string> keypoints;
  bool nearest_rule = false, spectral = false, geodesic = false, snap = false;
  int threads = 0, refine = 0;
  SpectralRefinementOptions spectral_options;
  GeodesicRefinementOptions geodesic_options;
};

void run_eval_corr(const EvalCorrArgs& a) {
  set_threads(a.threads);
  Run r = open_run(a.run);
  const size_t n = r.contents.inputs.size();
  if (n < 2)
    throw InputError("eval-corr: the run has one shape; correspondences need a collection");
  std::vector<std::string> files;
  if (a.keypoints.size() == 1 && fs::is_directory(a.keypoints[0])) {
    for (const std::string& input : r.contents.inputs) {
      const fs::path f = fs::path(a.keypoints[0]) / (fs::path(input).stem().string() + ".vts");
      if (!fs::exists(f))
        throw InputError("eval-corr: no keypoint file " + f.string() + " for " + input);
      files.push_back(f.string());
    }
  } else {
    files = a.keypoints;
  }
  if (files.size() != n)
    throw InputError("eval-corr: " + std::to_string(files.size()) + " keypoint files for " +
                     std::to_string(n) +
                     " shapes (give one per shape, in the run's order, or a directory)");
  std::vector<Mesh> meshes;
  std::vector<std::vector<int>> keypoints;
  for (size_t i = 0; i < n; ++i) {
    meshes.push_back(load_shape(r.contents.inputs[i]));
    keypoints.push_back(read_keypoints(files[i], long(meshes.back().vertices.rows())));
  }
  CorrespondenceOptions co;
  co.use_chart = r.options.components.chart && !a.nearest_rule;
  co.refine_steps = a.refine;
  CorrespondenceMap map = [&](int from, int to, const Block<double>& p,
                              const Block<double>& normals) {
    return correspond(*r.atlas, from, to, p, normals, co);
  };
  if (a.spectral) {
    map = spectral_refinement(map, meshes, r.contents.normalizations, a.spectral_options);
    // Seconds a shape for its eigenfunctions, under one a pair: say so up front.
    std::fprintf(stderr, "refining by ZoomOut: %zu shapes x %d eigenfunctions, %zu ordered pairs\n",
                 n, a.spectral_options.functions, n * (n - 1));
  }
  if (a.geodesic)
    map = geodesic_refinement(map, meshes, r.contents.normalizations, a.geodesic_options);
  if (a.snap) map = snapped(map, meshes, r.contents.normalizations);
  const KeypointError e = keypoint_error(map, meshes, r.contents.normalizations, keypoints);
  std::string rule = !co.use_chart         ? "nearest-sample rule, no chart"
                     : co.refine_steps > 0 ? "q = phi_J(u), u = psi_I(p) refined by " +
                                                 std::to_string(co.refine_steps) + " steps"
                                           : "q = phi_J(psi_I(p))";
  if (a.spectral)
    rule += std::string(", refined by ZoomOut") +
            (a.spectral_options.consensus         ? " (consensus of the collection)"
             : a.spectral_options.both_directions ? " (both directions)"
                                                  : "");
  if (a.geodesic)
    rule += ", finished by " + std::to_string(a.geodesic_options.landmarks) + " geodesic landmarks";
  if (a.snap) rule += ", snapped to the target's vertices";
  std::printf("correspondence error over %lld ordered pairs x %lld keypoints (%s)\n",
              (long long)e.pairs, (long long)e.keypoints, rule.c_str());
  std::printf("  mean L2 in the target's unit frame: %.3f x 1e-2\n", 100 * e.mean);
  std::printf("  mean squared distance: %.3f x 1e-2 (the other reading of the paper's L2)\n",
              100 * e.mean_squared);
  for (size_t t = 0; t < e.thresholds.size(); ++t)
    std::printf("  within %.2f: %5.1f%%\n", e.thresholds[t], 100 * e.within[t]);
  std::printf("  self-map I -> I (reconstruction and inversion alone): %.3f x 1e-2\n",
              100 * e.self_mean);
  nlohmann::json j;
  j["run"] = a.run;
  j["rule"] = co.use_chart ? "chart" : "nearest-sample";
  j["refine_steps"] = co.use_chart ? co.refine_steps : 0;
  j["spectral_refinement"] = a.spectral;
  if (a.spectral) {
    const SpectralRefinementOptions& so = a.spectral_options;
    j["spectral"] = {{"functions", so.functions},     {"k_start", so.k_start},
                     {"k_step", so.k_step},           {"prior", so.prior_weight},
                     {"prior_until", so.prior_until}, {"both_directions", so.both_directions},
                     {"consensus", so.consensus}};
  }
  j["geodesic_refinement"] = a.geodesic;
  if (a.geodesic)
    j["geodesic"] = {{"landmarks", a.geodesic_options.landmarks},
                     {"tau", a.geodesic_options.tau},
                     {"cycle_tolerance", a.geodesic_options.cycle_tolerance}};
  j["snap"] = a.snap;
  j["mean_l2_unit_frame"] = e.mean;
  j["mean_l2_x1e-2"] = 100 * e.mean;
  j["mean_squared_unit_frame"] = e.mean_squared;
  j["pairs"] = e.pairs;
  j["keypoints"] = e.keypoints;
  j["thresholds"] = e.thresholds;
  j["within"] = e.within;
  j["pair_mean"] = e.pair_mean;  // the diagonal: the self-maps
  j["self_map_mean_x1e-2"] = 100 * e.self_mean;
  j["keypoint_mean"] = e.keypoint_mean;
  j["keypoint_self_map"] = e.keypoint_self;
  j["keypoint_files"] = files;
  write_file_atomically(a.run + "/eval_corr.json",
                        [&](std::ostream& out) { out << j.dump(2) << "\n"; });
  std::printf("written: %s/eval_corr.json\n", a.run.c_str());
}

}  // namespace

void add_correspond(CLI::App& app) {
  auto a = std::make_shared<CorrespondArgs>();
  CLI::App* c = app.add_subcommand(
      "correspond", "Carry points from shape I to shape J of a collection: q = phi_J(psi_I(p))");
  c->add_option("run", a->run, "Run directory of a collection fit")->required();
  c->add_option("points", a->points_file,
                "File of points on shape I (x y z per line, I's own frame)");
  c->add_option("--from", a->from, "Source shape I (0-based)")->capture_default_str();
  c->add_option("--to", a->to, "Target shape J (0-based)")->capture_default_str();
  c->add_option("--vertices", a->vertices,
                "Vertex indices of shape I's input mesh instead of a points file")
      ->delimiter(',');
  c->add_flag("--snap", a->snap, "Also print the nearest vertex of J's input mesh");
  c->add_flag("--nearest-rule", a->nearest_rule,
              "Use the paper's nearest-sample rule instead of the chart psi");
  add_spectral_flags(c, a->spectral, a->spectral_options);
  add_geodesic_flags(c, a->geodesic, a->geodesic_options);
  c->add_option("-o,--out", a->out, "Write the points to this file instead of standard output");
  c->add_option("--threads", a->threads, "Threads (0: all cores)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1024));
  c->callback([a]() { run_correspond(*a); });
}

void add_eval_corr(CLI::App& app) {
  auto a = std::make_shared<EvalCorrArgs>();
  CLI::App* c = app.add_subcommand(
      "eval-corr", "Correspondence error on SHREC .vts keypoints (paper Table 1, Corresp. L2)");
  c->add_option("run", a->run, "Run directory of a collection fit")->required();
  c->add_option(
       "--keypoints", a->keypoints,
       "A directory holding <input stem>.vts for each shape, or one .vts per shape in order")
      ->required();
  c->add_flag("--nearest-rule", a->nearest_rule,
              "Use the nearest-sample rule even if the run has a chart");
  c->add_option("--refine", a->refine,
                "Chart rule: Gauss-Newton steps moving psi_I(p) to the nearest point of phi_I "
                "before phi_J (0: psi alone, the paper)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1000));
  add_spectral_flags(c, a->spectral, a->spectral_options);
  add_geodesic_flags(c, a->geodesic, a->geodesic_options);
  c->add_flag("--snap", a->snap,
              "Move each image to the target's nearest input vertex (what the rule's error is "
              "without phi_J's distance from the mesh)");
  c->add_option("--threads", a->threads, "Threads (0: all cores)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1024));
  c->callback([a]() { run_eval_corr(*a); });
}

}  // namespace jsa::cli
