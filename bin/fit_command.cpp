// `jsatlas fit INPUT -o DIR`: learn the atlas of one shape (paper Sec. 3).
// Writes DIR/config.json, DIR/losses.csv, DIR/model.ckpt (every
// --checkpoint-every iterations and at the end) and DIR/domain_mesh.obj.
// Under `mpirun -np P` a collection's shapes are split over P ranks
// (docs/mpi.md); rank 0 prints and writes every file.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <vector>

#include "bin/commands.h"
#include "bin/run_files.h"
#include "engine/parallel.h"
#include "io/atomic_write.h"
#include "io/geometry/intrinsic_descriptors.h"
#include "io/pictures/image.h"
#include "model/tool/checkpoint.h"
#include "model/tool/fit_config.h"
#include "model/tool/gemm_choice.h"
#include "model/tool/mpi/mpi_team.h"
#include "model/tool/pose_by_fit.h"
#include "model/tool/registration_check.h"
#include "model/tool/shape_input.h"
#include "model/tool/spectral_start.h"
#include "model/tool/template_coverage.h"

namespace jsa::cli {
namespace {

std::atomic<int> g_signal{0};
extern "C" void on_signal(int s) { g_signal = s; }

struct FitArgs {
  std::vector<std::string> inputs;
  std::string list_file, out_dir, resume;
  FitOptions options;
  int threads = -1;  // -1: not given (a resumed run keeps its own)
  std::string gemm;  // --gemm auto|eigen|blas; "": not given (auto; a resumed run keeps its own)
  int checkpoint_every = 500;
  int table_row = 0;
  bool no_normals = false, no_repulsion = false, no_distribution = false, no_chart = false,
       no_isometry = false;
  std::string preset;
  int mesh_resolution = 256;
  double mesh_threshold = 0.05;
  std::string texture;
  double minutes = 0;  // > 0: size --iters to this wall-time budget
  // Under --minutes, the steps a single shape's run should have at least: a
  // shorter budget takes a smaller M instead (budgeted_points). -1: not given.
  int64_t min_steps = -1;
  int64_t stop_at = 0;  // > 0: stop after this iteration with a checkpoint (continue with --resume)
  bool quiet = false;
  int64_t inject_fault_at = -1;  // tests only: one NaN loss at this iteration
  // Whether --iters and --schedule were given: collections and --preset paper
  // have defaults of their own (kFixedScheduleIterations in model/tool/trainer.h).
  bool iters_given = false, schedule_given = false;
  bool even_given = false;  // --w-even
  bool emd_given = false;   // --w-emd
  bool lr_given = false;    // --lr
  bool points_given = false, gaussians_given = false, width_given = false, deform_given = false;
  bool auto_register_given = false;  // --auto-register
  bool chart_fourier_given = false;  // --chart-fourier
};

std::string format_duration(double seconds) {
  char buf[32];
  const int s = int(seconds + 0.5);
  if (s >= 3600)
    std::snprintf(buf, sizeof buf, "%dh%02dm", s / 3600, (s / 60) % 60);
  else
    std::snprintf(buf, sizeof buf, "%dm%02ds", s / 60, s % 60);
  return buf;
}

// The library names settings (FitOptions' fields); the user knows the flags:
// runs `f` and renames the setting that starts an InputError's message.
template <class F>
auto with_flag_names(F&& f) {
  static const std::pair<const char*, const char*> kFlags[] = {
      {"points", "--points"},
      {"iterations", "--iters"},
      {"batch_shapes", "--batch-shapes"},
      {"lr", "--lr"},
      {"decay", "--decay"},
      {"decay_at", "--decay-at"},
      {"atlas.alpha", "--alpha"},
      {"weights.surface_6d", "--w-6d"},
      {"weights.chart_2d", "--w-2d"},
      {"weights.cycle", "--w-cycle"},
      {"weights.isometry", "--w-iso"},
      {"weights.repulsion", "--w-rep"},
      {"weights.code", "--w-code"},
      {"weights.metric", "--w-metric"},
      {"weights.evenness", "--w-even"},
      {"weights.transport", "--w-emd"},
      {"weights.coverage", "--w-coverage"},
      {"metric_end", "--w-metric-end"},
      {"metric_until", "--w-metric-until"},
      {"repulsion_tolerance", "--repulsion-tolerance"},
      {"wrap_steps", "--wrap"},
      {"reseed_every", "--reseed"},
      {"template_steps", "--template-steps"},
      {"template_share", "--template-share"},
      {"template_max_steps", "--template-max-steps"},
      {"template_shape", "--template-shape"},
      {"chart_from", "--chart-from"},
      {"evenness_from", "--w-even-from"},
      {"transport_from", "--w-emd-from"},
      {"transport_points", "--emd-points"},
      {"code_lr_scale", "--code-lr-scale"},
      {"surface_lr_scale", "--surface-lr-scale"},
      {"intrinsic", "--intrinsic"},
      {"intrinsic_until", "--intrinsic-until"},
      {"spectral_map", "--spectral-map"},
      {"spectral_map_until", "--spectral-map-until"},
      {"register_prior", "--register-prior"},
      {"template_coverage", "--template-coverage"},
      {"nodes_lr_scale", "--nodes-lr-scale"},
      {"auto_register", "--auto-register"},
      {"nodes_width", "--nodes-width"},
      {"atlas.deform_nodes", "--deform-nodes"},
      {"atlas.fine_nodes", "--fine-nodes"},
      {"atlas.chart_width", "--chart-width"},
      {"atlas.chart_fourier", "--chart-fourier"},
      {"atlas.chart_fourier_sigma", "--chart-fourier-sigma"},
      {"fine_width", "--fine-width"},
      {"schedule.kind", "--schedule"},
      {"schedule.points_start", "--points-start"},
      {"schedule.ramp_until", "--ramp-until"},
      {"schedule.levels", "--ramp-levels"},
      {"schedule.warmup", "--warmup"},
      {"schedule.drop_at", "--lr-drop-at"},
      {"schedule.drop", "--lr-drop"}};
  try {
    return f();
  } catch (const InputError& e) {
    const std::string m = e.what();
    for (const auto& [setting, flag] : kFlags)
      if (m.rfind(std::string(setting) + " ", 0) == 0)
        throw InputError(std::string(flag) + m.substr(std::strlen(setting)));
    throw;
  }
}

// The maps of L_map and --register (model/tool/spectral_start.h).
SpectralStartOptions registration_options(const FitOptions& o) {
  SpectralStartOptions so;
  so.prior_weight = o.register_prior;
  return so;
}

Trainer make_trainer(const FitOptions& o, const std::vector<Block<double>>& pools, Team* team) {
  return with_flag_names([&] { return Trainer(o, pools, team); });
}

// The pose step's near ties decided by fitting each (model/tool/pose_by_fit.h):
// shapes with more than one pose within 1.25x of the lowest Chamfer are turned
// into the pose whose short fit ends lowest. Returns each shape's fit losses
// (no losses: no tie).
std::vector<PoseFitChoice> choose_near_poses(const FitOptions& o, std::vector<RunInput>& shapes,
                                             std::vector<RigidAlignment>& poses, bool quiet) {
  std::vector<PoseFitChoice> fits(shapes.size());
  std::vector<Block<double>> pools;
  std::vector<std::vector<Eigen::Matrix3d>> candidates;
  std::vector<size_t> which;
  for (size_t i = 1; i < shapes.size(); ++i) {
    if (poses[i].near_poses.size() < 2) continue;
    RunInput input = shapes[i];
    set_rotation(input, Eigen::Matrix3d::Identity());
    pools.push_back(std::move(input.pool));
    candidates.push_back(poses[i].near_poses);
    which.push_back(i);
  }
  if (which.empty()) return fits;
  PoseFitOptions p;
  p.steps = o.pose_fit_steps;
  p.scored = std::max<int64_t>(1, p.steps / 3);
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<PoseFitChoice> c = choose_poses_by_fit(o, shapes[0].pool, pools, candidates, p);
  for (size_t k = 0; k < which.size(); ++k) {
    const size_t i = which[k];
    const int chosen = c[k].chosen;
    fits[i] = c[k];
    poses[i].rotation = poses[i].near_poses[size_t(chosen)];
    poses[i].chamfer = poses[i].near_chamfers[size_t(chosen)];
    set_rotation(shapes[i], poses[i].rotation);
    if (!quiet) {
      std::cerr << "fit: shape " << i << " has " << candidates[k].size()
                << " near-tied poses (Chamfer";
      for (double v : poses[i].near_chamfers) std::fprintf(stderr, " %.4g", v);
      std::cerr << "); short fits end at L";
      for (double v : c[k].losses) std::fprintf(stderr, " %.4g", v);
      std::cerr << ", L_6D";
      for (double v : c[k].surfaces) std::fprintf(stderr, " %.4g", v);
      std::cerr << ": pose " << chosen << " (" << rotation_angle_degrees(poses[i].rotation)
                << " deg)\n";
    }
  }
  if (!quiet)
    std::cerr << "fit: near-tied poses decided by fitting in "
              << format_duration(
                     std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count())
              << "\n";
  return fits;
}

// The processes of this run: the MPI job when an MPI launcher started us, else one.
std::unique_ptr<Team> join_team() {
  if (!launched_by_mpi()) return std::make_unique<Team>();
  if (!mpi_available()) {
    for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"}) {
      const char* size = std::getenv(name);
      if (size && std::string(size) != "1")
        throw InputError("fit: started by an MPI launcher with " + std::string(size) +
                         " processes, but this jsatlas was built without MPI (install "
                         "libopenmpi-dev and rebuild)");
    }
    return std::make_unique<Team>();
  }
  return join_mpi_team();
}

void run_fit(FitArgs& a, Team& team) {
  namespace fs = std::filesystem;
  const bool root = team.rank() == 0, many = team.size() > 1;
  if (!root) a.quiet = true;  // rank 0 speaks for the job
  FitOptions o = a.options;
  std::vector<std::string> inputs = a.inputs;
  if (!a.list_file.empty()) {
    std::ifstream in(a.list_file);
    if (!in) throw InputError(a.list_file + ": cannot open the list of inputs");
    std::string line;
    while (std::getline(in, line)) {
      const auto b = line.find_first_not_of(" \t\r"), e = line.find_last_not_of(" \t\r");
      if (b != std::string::npos && line[b] != '#') inputs.push_back(line.substr(b, e - b + 1));
    }
    if (inputs.empty()) throw InputError(a.list_file + ": lists no inputs");
  }
  CheckpointContents resumed;
  const bool resuming = !a.resume.empty();
  if (resuming) {
    a.out_dir = a.resume;
    resumed = read_checkpoint((fs::path(a.resume) / "model.ckpt").string());
    o = fit_options_from_json(resumed.settings_json, a.resume + "/model.ckpt");
    inputs = resumed.inputs;
  } else {
    if (inputs.empty())
      throw InputError(
          "fit: give an INPUT (a mesh, a point cloud or builtin:NAME) or --resume DIR");
    if (a.out_dir.empty()) throw InputError("fit: give an output directory with -o DIR");
    if (!a.preset.empty()) {
      if (a.preset != "paper")
        throw InputError("--preset: unknown preset '" + a.preset + "' (known: paper)");
      apply_paper_preset(o);
      if (a.lr_given) o.lr = a.options.lr;  // the preset sets 1e-3 unless told
    }
    if (a.table_row) o.components = Components::table_row(a.table_row);
    if (a.no_normals) o.components.normals = false;
    if (a.no_repulsion) o.components.repulsion = false;
    if (a.no_distribution) o.components.distribution = false;
    if (a.no_chart) o.components.chart = false;
    if (a.no_isometry) o.components.isometry = false;
    // The ramp and its length were measured on single shapes (docs/results.md);
    // collections and the paper's sizes keep M fixed for 5000 steps, the
    // default before the ramp, unless told otherwise.
    const bool fixed_m = inputs.size() > 1 || !a.preset.empty();
    if (fixed_m && !a.schedule_given) o.schedule.kind = "step";
    if (fixed_m && !a.iters_given) o.iterations = kFixedScheduleIterations;
    // So does their learning rate (FitOptions::lr: a single shape's was measured).
    if (fixed_m && !a.lr_given) o.lr = kCollectionLearningRate;
    // L_even was measured on single shapes (docs/results.md); a collection
    // keeps the objective its rounds were measured with unless told.
    if (inputs.size() > 1 && !a.even_given) o.weights.evenness = 0;
    if (inputs.size() > 1 && !a.emd_given) o.weights.transport = 0;  // so does L_EMD
    if (inputs.size() > 1 && a.preset.empty()) {  // trainer.h: sized for a laptop's minutes
      if (!a.points_given) o.points = kCollectionPoints;
      if (!a.gaussians_given) o.atlas.gaussians = kCollectionGaussians;
      if (!a.width_given) o.atlas.width = kCollectionWidth;
      if (!a.deform_given) o.atlas.deform_layers = kCollectionDeformLayers;
      if (!a.auto_register_given) o.auto_register = kCollectionAutoRegister;
      if (!a.chart_fourier_given) o.atlas.chart_fourier = kCollectionChartFourier;
    }
    if (o.intrinsic > 0 && inputs.size() < 2)
      throw InputError("--intrinsic: needs a collection (two or more inputs)");
    if (o.spectral_map > 0 && inputs.size() < 2)
      throw InputError("--spectral-map: needs a collection (two or more inputs)");
    if (o.atlas.deform_nodes > 0 && inputs.size() < 2)
      throw InputError("--deform-nodes: needs a collection (two or more inputs)");
    if (o.atlas.fine_nodes > 0 && o.atlas.deform_nodes == 0)
      throw InputError("--fine-nodes: a second field of nodes, needs --deform-nodes > 0");
    if (o.register_nodes && o.atlas.deform_nodes == 0)
      throw InputError("--register: needs --deform-nodes > 0");
    if (o.template_coverage && (inputs.size() < 2 || o.template_shape >= 0))
      throw InputError(
          "--template-coverage: chooses the template of a collection (two or more inputs, "
          "without --template-shape)");
    // The nodes are placed when the template start ends (Trainer::finish_template).
    if (o.atlas.deform_nodes > 0 &&
        !(o.template_steps > 0 || (o.template_steps < 0 && o.template_share > 0)))
      throw InputError(
          "--deform-nodes: needs the template start (--template-steps > 0, or -1 "
          "with --template-share > 0)");
    if (o.atlas.deform_domain && (inputs.size() < 2 || o.atlas.deform_layers == 0))
      throw InputError(
          "--deform-domain: needs a collection (two or more inputs) with --deform-layers > 0");
  }
  if (a.threads >= 0) o.threads = a.threads;
  set_threads(o.threads);
  // The GEMMs' backend (engine/gemm.h), before anything multiplies. `auto`
  // measures on this run's own step, or reads the machine's earlier answer
  // (model/tool/gemm_choice.h: why a measured choice must be remembered);
  // rank 0 decides for an MPI job. A resumed run keeps its own, as its threads.
  GemmChoice gemm;
  std::string gemm_asked = resuming ? "resume" : "auto";
  if (!a.gemm.empty()) gemm_asked = a.gemm;
  if (gemm_asked == "auto") {
    if (root)
      gemm = with_flag_names([&] { return choose_gemm(o, int(inputs.size()), gemm_cache_path()); });
    if (many) {
      double blas = root && gemm.gemm == Gemm::blas ? 1.0 : 0.0;
      team.sum_in_rank_order(&blas, 1);
      gemm.gemm = blas > 0 ? Gemm::blas : Gemm::eigen;
    }
  } else if (gemm_asked == "resume") {
    gemm.gemm = o.gemm;
    gemm.source = "the run's own, from its checkpoint";
    if (o.gemm == Gemm::blas && !blas_built_in())
      throw InputError("fit --resume: " + a.resume +
                       " ran its GEMMs on the BLAS, which this jsatlas was built without "
                       "(rebuild with a CBLAS, or resume with --gemm eigen: the numbers then "
                       "differ from an uninterrupted run's)");
  } else {
    parse_gemm(gemm_asked, &gemm.gemm);  // CLI11 has checked the name
    gemm.source = "--gemm " + gemm_asked;
    if (gemm.gemm == Gemm::blas && !blas_built_in())
      throw InputError(
          "--gemm blas: this jsatlas was built without a CBLAS (install libblas-dev and "
          "libopenblas0-openmp, then rebuild; or use --gemm eigen)");
  }
  o.gemm = gemm.gemm;
  set_gemm(o.gemm);
  if (many && !resuming) {
    // Before the inputs are read and posed (minutes on large meshes). The
    // automatic template start (-1) is turned off below, not refused.
    FitOptions asked = o;
    if (asked.template_steps < 0) asked.template_steps = 0;
    if (asked.template_shape < 0) asked.template_shape = 0;
    with_flag_names([&] { Trainer::require_rank_support(asked, int(inputs.size()), team.size()); });
  }
  if (!a.texture.empty())
    (void)read_image(a.texture);  // a bad texture fails now, not after training

  // Each shape, a fixed pool of surface samples, and its unit frame (Sec. 4 data).
  // Over MPI each rank samples the pools of its own block of shapes; rank 0 also
  // reads the others' inputs (their frames for the checkpoint, their meshes for
  // the outputs) but keeps no pool of theirs. The pose step needs shape 0 (the
  // reference) on every rank.
  const auto [block_first, block_last] = shape_block(int(inputs.size()), team.size(), team.rank());
  const bool aligning = !resuming && inputs.size() > 1 && o.align_poses;
  std::vector<RunInput> shapes;
  std::vector<Block<double>> pools;
  std::vector<Normalization> frames;
  for (size_t i = 0; i < inputs.size(); ++i) {
    const bool mine = int(i) >= block_first && int(i) < block_last;
    pools.emplace_back(0, 6);
    frames.emplace_back();
    if (!mine && !root && !(i == 0 && aligning)) {
      shapes.emplace_back();
      continue;
    }
    shapes.push_back(load_run_input(inputs[i], o.pool, o.seed + 1000 * i));
    if (resuming) {
      // The checkpoint's frame, but the rotation the pool has (none yet): the
      // pose step below turns the pool into the checkpoint's rotation.
      const Eigen::Matrix3d drawn = shapes.back().normalization.rotation;
      shapes.back().normalization = resumed.normalizations[i];
      shapes.back().normalization.rotation = drawn;
    }
    for (const std::string& w : shapes.back().mesh.warnings)
      if (mine && !(a.quiet && root)) std::cerr << "warning: " << inputs[i] << ": " << w << "\n";
  }
  o.atlas.shapes = int(inputs.size());
  // The pose step (io/geometry/rigid_align.h): every shape turned into the
  // first one's pose; a resumed run takes the rotations of its checkpoint.
  // Deterministic, so every rank computes the rotations of its own shapes and
  // rank 0 those of all (for rotations.json and the frames it saves); the check
  // below makes sure they agree.
  std::vector<RigidAlignment> poses(inputs.size());
  std::vector<PoseFitChoice> pose_fits(inputs.size());
  double pose_fit_seconds = 0;  // counted against --minutes, like the wrap and the template
  if (resuming) {
    for (size_t i = 0; i < inputs.size(); ++i) {
      set_rotation(shapes[i], resumed.normalizations[i].rotation);
      poses[i].rotation = resumed.normalizations[i].rotation;
    }
  } else if (aligning) {
    const auto t0 = std::chrono::steady_clock::now();
    if (root) {
      poses = align_to_first(shapes);
      if (o.pose_fit_steps > 0 && !many) {
        const auto f0 = std::chrono::steady_clock::now();
        pose_fits = choose_near_poses(o, shapes, poses, a.quiet);
        pose_fit_seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - f0).count();
      }
    }
    if (many) {
      // Rank 0 poses every shape (the near ties are settled by the whole
      // collection, which no other rank holds); the others take its rotations
      // (summed with zeros: a broadcast) and turn their own shapes.
      std::vector<double> rotations(9 * inputs.size(), 0.0);
      if (root)
        for (size_t i = 0; i < inputs.size(); ++i)
          for (int k = 0; k < 9; ++k)
            rotations[9 * i + size_t(k)] = poses[i].rotation(k / 3, k % 3);
      team.sum_in_rank_order(rotations.data(), rotations.size());
      if (!root)
        for (size_t i = 0; i < inputs.size(); ++i) {
          for (int k = 0; k < 9; ++k)
            poses[i].rotation(k / 3, k % 3) = rotations[9 * i + size_t(k)];
          if (shapes[i].pool.rows() > 0) set_rotation(shapes[i], poses[i].rotation);
        }
    }
    if (!a.quiet) {
      std::cerr << "fit: poses aligned to shape 0 in "
                << format_duration(
                       std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count())
                << ":";
      for (size_t i = 1; i < poses.size(); ++i)
        std::fprintf(stderr, " %zu: %.1f deg;", i, poses[i].angle_degrees());
      std::cerr << "\n";
    }
  }
  for (size_t i = 0; i < inputs.size(); ++i) {
    const bool mine = int(i) >= block_first && int(i) < block_last;
    if (mine) pools[i] = shapes[i].pool;
    if (mine && o.intrinsic > 0) {
      // L_6D^h (model/objective.h): h at every pool sample, from the mesh's
      // vertices (in the pool's frame: to_unit turns them as the pool was turned).
      const IntrinsicDescriptors h = intrinsic_descriptors(shapes[i].mesh);
      Block<double> at = descriptors_at(shapes[i].pool.leftCols(3),
                                        shapes[i].normalization.to_unit(h.nodes), h.values);
      rank_normalize(at);
      pools[i].conservativeResize(Eigen::NoChange, 9);
      pools[i].rightCols(3) = at;
      if (!a.quiet)
        std::fprintf(stderr,
                     "fit: shape %zu: intrinsic descriptors on %lld nodes, mean geodesic "
                     "distance %.3f to %.3f\n",
                     i, static_cast<long long>(h.nodes.rows()), h.values.col(0).minCoeff(),
                     h.values.col(0).maxCoeff());
    }
    frames[i] = shapes[i].normalization;
    shapes[i].pool.resize(0, 6);                 // the trainer keeps its own copy
    if (!mine && !root) shapes[i] = RunInput{};  // shape 0, read for the pose step only
  }
  if (root) fs::create_directories(a.out_dir);
  const std::string dir = a.out_dir;
  auto rotations_json = [&]() {
    nlohmann::json r = nlohmann::json::array();
    for (size_t i = 0; i < inputs.size(); ++i) {
      nlohmann::json m = nlohmann::json::array();
      for (int row = 0; row < 3; ++row)
        m.push_back(
            {poses[i].rotation(row, 0), poses[i].rotation(row, 1), poses[i].rotation(row, 2)});
      nlohmann::json e = {
          {"input", inputs[i]}, {"rotation", m}, {"angle_degrees", poses[i].angle_degrees()}};
      if (i > 0 && !resuming && o.align_poses) {
        e["chamfer"] = poses[i].chamfer;
        e["runner_up_chamfer"] = poses[i].runner_up;
        e["candidates"] = poses[i].candidates;
        e["input_pose_chamfer"] = poses[i].input_chamfer;
        e["kept_input_pose"] = poses[i].kept_input;
        if (poses[i].near_poses.size() > 1) {
          nlohmann::json near = nlohmann::json::array();
          for (size_t k = 0; k < poses[i].near_poses.size(); ++k) {
            nlohmann::json n = {
                {"angle_degrees", rotation_angle_degrees(poses[i].near_poses[k])},
                {"chamfer", poses[i].near_chamfers[k]},
                {"degrees_from_chosen",
                 rotation_angle_degrees(poses[i].near_poses[k].transpose() * poses[i].rotation)}};
            if (k < poses[i].near_collection.size())
              n["collection_chamfer"] = poses[i].near_collection[k];
            if (k < pose_fits[i].losses.size()) {
              n["fit_loss"] = pose_fits[i].losses[k];
              n["fit_surface"] = pose_fits[i].surfaces[k];
            }
            near.push_back(n);
          }
          e["near_tied_poses"] = near;
        }
      }
      r.push_back(e);
    }
    return r;
  };
  if (root && inputs.size() > 1) {
    const nlohmann::json r = {{"convention",
                               "unit-frame rows: x_unit = ((x_input - center) / scale) * rotation; "
                               "shape 0 is the reference, turned into its principal axes "
                               "(longest first, towards the larger third moment); the others "
                               "onto it"},
                              {"shapes", rotations_json()}};
    write_file_atomically(dir + "/rotations.json",
                          [&](std::ostream& out) { out << r.dump(2) << "\n"; });
  }

  // The template start trains one shape alone, which a data-parallel run cannot
  // share out: its automatic length (-1, the default for collections) is 0 on
  // more than one rank; an explicit length is refused by the trainer.
  if (many && o.template_steps < 0) {
    o.template_steps = 0;
    if (!a.quiet)
      std::cerr << "fit: no template start with " << team.size()
                << " MPI ranks (--template-steps 0)\n";
  }
  // The template (FitOptions::template_shape): -1 asks for the medoid of the
  // aligned pools (model/tool/shape_input.h). A data-parallel run has no
  // template start and keeps shape 0 as L_metric's reference.
  // With --template-coverage (meshes) the candidates are scored instead by how
  // well their spectral registrations cover the others
  // (model/tool/template_coverage.h); with --register the winner's maps are
  // the registration.
  std::optional<SpectralStart> registration;
  if (!resuming && o.template_shape < 0) {
    o.template_shape = 0;
    if (!many && inputs.size() > 1 && o.template_coverage) {
      const auto s0 = std::chrono::steady_clock::now();
      std::vector<Mesh> meshes;
      for (const RunInput& s : shapes) meshes.push_back(s.mesh);
      CoverageChoice c = template_by_coverage(meshes, frames, pools, registration_options(o));
      o.template_shape = c.shape;
      if (o.register_nodes || o.spectral_map > 0) registration = std::move(c.start);
      const double coverage_seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - s0).count();
      pose_fit_seconds += coverage_seconds;  // counted against --minutes, as the pose step
      if (!a.quiet) {
        std::cerr << "fit: template shape " << c.shape << " (" << inputs[size_t(c.shape)]
                  << "), whose registration covers the others best (in "
                  << format_duration(coverage_seconds) << "); distances summed:";
        for (double v : c.sums) std::fprintf(stderr, " %.4g", v);
        std::cerr << "\n";
      }
    } else if (!many && inputs.size() == 2) {
      // Two shapes have no medoid (each Chamfer sum is the other's). The
      // coverage as the tie-break was measured and lost on the ants
      // (docs/collections.md, thirty-second round): the first stays.
      if (!a.quiet)
        std::cerr << "fit: template shape 0 (" << inputs[0]
                  << "), the first of two (two shapes have no medoid; --template-shape 1 takes "
                     "the other)\n";
    } else if (!many && inputs.size() > 2) {
      const MedoidChoice m = medoid_shape(pools);
      o.template_shape = m.shape;
      if (!a.quiet) {
        std::cerr << "fit: template shape " << m.shape << " (" << inputs[size_t(m.shape)]
                  << "), the medoid; Chamfer sums to the others:";
        for (double v : m.sums) std::fprintf(stderr, " %.4g", v);
        std::cerr << "\n";
      }
    }
  }
  // --auto-register (model/tool/registration_check.h): a collection of meshes
  // for which neither nodes nor a registration were asked starts from the
  // registration when its maps invert each other about as well as the
  // nearest points in space do; the choice is kept in config.json as the
  // options it sets, so a resumed run builds the same atlas.
  // (A template the collection does not have is refused by the trainer.)
  const bool may_register = !resuming && o.auto_register > 0 && inputs.size() > 1 &&
                            o.atlas.deform_nodes == 0 && !o.register_nodes &&
                            o.template_shape >= 0 && size_t(o.template_shape) < inputs.size();
  if (may_register && many && !a.quiet)
    std::cerr << "fit: no registration with " << team.size()
              << " MPI ranks (--auto-register: one process only)\n";
  if (may_register && !many) {
    const auto s0 = std::chrono::steady_clock::now();
    std::vector<Mesh> meshes;
    for (const RunInput& s : shapes) meshes.push_back(s.mesh);
    // A collection the maps cannot be made for (a point cloud, a mesh with
    // fewer vertices than eigenfunctions) is fitted as before: the check is
    // a choice of start, not a requirement of the run.
    std::optional<RegistrationCheck> c;
    std::string why_not;
    try {
      c = check_registration(meshes, frames, o.template_shape, o.auto_register,
                             registration_options(o));
    } catch (const InputError& e) {
      why_not = e.what();
    }
    const double took =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - s0).count();
    pose_fit_seconds += took;  // counted against --minutes, as the pose step
    if (c && c->trusted) {
      o.atlas.deform_nodes = kAutoRegisterNodes;
      o.register_nodes = true;
      o.nodes_lr_scale = 0;
      registration = std::move(c->start);
    }
    if (!a.quiet && !c) std::cerr << "fit: no registration (--auto-register: " << why_not << ")\n";
    if (!a.quiet && c) {
      std::fprintf(stderr,
                   "fit: the template's spectral maps come back %.3g x 1e-2 off, the nearest "
                   "points %.3g (%.2fx; trusted up to %.2gx, in %s): ",
                   100 * c->spectral, 100 * c->spatial, c->spectral / std::max(c->spatial, 1e-12),
                   o.auto_register, format_duration(took).c_str());
      std::cerr << (c->trusted
                        ? "registration as the start (--deform-nodes " +
                              std::to_string(kAutoRegisterNodes) + " --register --nodes-lr-scale 0)"
                        : std::string("no registration"))
                << "\n";
    }
  }
  Trainer trainer = make_trainer(o, pools, &team);
  // --register's registration is needed once, before the joint training (a
  // checkpoint is only written after it: a resumed run has its nodes).
  const bool registers = o.register_nodes && !resuming;
  if (o.spectral_map > 0 || registers) {
    // L_map's maps and --register's registration (model/tool/spectral_start.h),
    // from the meshes in their fit's frames; a resumed run finds the same ones
    // (they depend on nothing else).
    if (many)
      throw InputError(o.spectral_map > 0 ? "--spectral-map: not over MPI yet"
                                          : "--register: not over MPI yet");
    const auto s0 = std::chrono::steady_clock::now();
    if (!registration) {
      std::vector<Mesh> meshes;
      for (const RunInput& s : shapes) meshes.push_back(s.mesh);
      registration = spectral_start(meshes, frames, o.template_shape, registration_options(o));
    }
    trainer.set_spectral_map(registration->template_vertices, registration->images);
    const double took =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - s0).count();
    pose_fit_seconds += took;  // counted against --minutes, as the pose step
    if (!a.quiet)
      std::cerr << "fit: spectral maps from the template (shape " << o.template_shape
                << ") to the others in " << format_duration(took) << "\n";
  }
  LossLog log;
  if (resuming) {
    restore_trainer(trainer, resumed, a.resume);
    log = read_loss_log(dir + "/losses.csv", trainer.iteration(), trainer.faults());
  }
  const Index first_points = scheduled_points(o.schedule, o.points, 0, o.iterations);
  if (!a.quiet)
    std::cerr << "fit: "
              << (inputs.size() == 1 ? inputs[0] : std::to_string(inputs.size()) + " shapes")
              << " -> " << dir << "  (" << o.iterations << " iterations, M = " << o.points
              << (first_points < o.points ? " ramped from " + std::to_string(first_points)
                                          : std::string())
              << ", K = " << o.atlas.gaussians << ", MLP " << o.atlas.hidden_layers << "x"
              << o.atlas.width << ", " << max_threads() << " threads"
              << (many ? " on each of " + std::to_string(team.size()) + " MPI ranks"
                       : std::string())
              << (resuming ? ", resumed at " + std::to_string(trainer.iteration()) : std::string())
              << ")\n"
              << "fit: " << describe(gemm) << "\n";

  // What chose the backend, for config.json: a resumed run keeps its first
  // record (the settings hold the backend itself).
  nlohmann::json gemm_record = {{"backend", gemm_name(gemm.gemm)},
                                {"asked", gemm_asked},
                                {"source", gemm.source},
                                {"eigen_ms", gemm.timing.eigen_seconds * 1e3},
                                {"blas_ms", gemm.timing.blas_seconds * 1e3},
                                {"repeats", gemm.timing.repeats},
                                {"blas", blas_description()},
                                {"cache", gemm.cache},
                                {"cache_key", gemm.key}};
  if (gemm_asked == "resume") {
    try {
      std::ifstream in(dir + "/config.json");
      const nlohmann::json old = nlohmann::json::parse(in);
      if (old.contains("gemm") && old["gemm"].is_object()) gemm_record = old["gemm"];
    } catch (const std::exception&) {
      // no earlier record (a run from before --gemm): the one above
    }
  }
  // config.json: the settings, and what the run has done so far (faults and
  // the action taken for each, mirrors, reseeds), and the GEMMs' choice.
  auto write_config = [&]() {
    if (!root) return;
    write_file_atomically(dir + "/config.json", [&](std::ostream& out) {
      out << "{\n\"inputs\": [";
      for (size_t i = 0; i < inputs.size(); ++i) out << (i ? ", " : "") << json_quote(inputs[i]);
      out << "],\n\"settings\": " << fit_options_to_json(o);
      if (inputs.size() > 1) out << ",\n\"rotations\": " << rotations_json().dump();
      out << ",\n\"gemm\": " << gemm_record.dump();
      out << ",\n\"report\": {\"iteration\": " << trainer.iteration()
          << ", \"faults\": " << trainer.faults() << ", \"fault_actions\": [";
      for (size_t i = 0; i < trainer.fault_log().size(); ++i)
        out << (i ? ", " : "") << json_quote(describe(trainer.fault_log()[i]));
      out << "], \"mirrors\": " << trainer.mirrors()
          << ", \"reseeded_gaussians\": " << trainer.reseeded() << "}\n}\n";
    });
  };
  write_config();
  // Every rank calls save() at the same iteration: the codes are gathered from
  // their ranks (a collective), then rank 0 writes.
  auto save = [&]() {
    trainer.gather_codes();
    if (!root) return;
    write_config();
    write_checkpoint(dir + "/model.ckpt", inputs, o, frames, trainer);
    write_loss_log(dir + "/losses.csv", log);
  };
  // What every rank must decide alike is decided by rank 0's value (the others add 0).
  auto rank0_value = [&](double v) {
    if (!many) return v;
    double x = root ? v : 0.0;
    team.sum_in_rank_order(&x, 1);
    return x;
  };
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  using clock = std::chrono::steady_clock;
  double wrap_seconds = pose_fit_seconds;
  if (!resuming && o.wrap_steps > 0) {
    const auto w0 = clock::now();
    const WrapReport w = trainer.wrap([] { return g_signal != 0; });
    const double wrapping = std::chrono::duration<double>(clock::now() - w0).count();
    wrap_seconds += wrapping;
    if (g_signal) {
      // Nothing trained yet: a checkpoint would hold a half-fitted wrap.
      std::cerr << "fit: interrupted while wrapping (before training); no checkpoint written\n";
      throw ExitCode{130};
    }
    if (!a.quiet)
      std::cerr << "fit: phi and psi wrapped around the shape's ellipsoid (" << o.wrap_steps
                << " steps, " << format_duration(wrapping) << "; RMS error phi " << w.phi_error
                << ", psi " << w.psi_error << ")\n";
  }
  const bool collection = inputs.size() > 1;
  if (!resuming && collection &&
      (o.template_steps > 0 || (o.template_steps < 0 && o.template_share > 0))) {
    // The template start (FitOptions::template_steps): the template alone, then its
    // codes copied to every shape. Under --minutes its length is the share of
    // the budget, timed on its own steps (a fifth of a joint step for N = 4).
    const auto t0 = clock::now();
    auto cancelled = [] { return g_signal != 0; };
    int64_t steps = o.template_steps;
    if (steps < 0 && a.minutes > 0) {
      const int64_t warm = 5, timed = 20;
      trainer.train_template(warm, cancelled);
      const auto p0 = clock::now();
      trainer.train_template(timed, cancelled);
      double per = std::chrono::duration<double>(clock::now() - p0).count() / double(timed);
      // Its share of the budget in seconds, trained in stretches of about a
      // 25th, each re-timed: a step rate measured once goes stale when the
      // machine's load changes (one timed start on a busy machine gave the
      // template 8 of 10 minutes instead of 3).
      const double target = o.template_share * a.minutes * 60.0;
      const int64_t stretch = std::max<int64_t>(25, int64_t(target / per / 25.0));
      const int64_t cap =
          o.template_max_steps > 0 ? o.template_max_steps : std::numeric_limits<int64_t>::max();
      for (;;) {
        const double left = target - std::chrono::duration<double>(clock::now() - t0).count();
        const int64_t n = std::min({stretch, int64_t(left / per), cap - trainer.template_done()});
        if (n < 1 || g_signal) break;
        const auto s0 = clock::now();
        trainer.train_template(n, cancelled);
        per = std::chrono::duration<double>(clock::now() - s0).count() / double(n);
      }
      steps = trainer.template_done();
    } else if (steps < 0) {
      steps = Trainer::template_steps_for(o, o.iterations, int(inputs.size()));
    }
    trainer.train_template(steps - trainer.template_done(), cancelled);
    if (g_signal) {
      std::cerr << "fit: interrupted while fitting the template (before training); no checkpoint "
                   "written\n";
      throw ExitCode{130};
    }
    trainer.finish_template();
    o.template_steps = trainer.template_done();
    trainer.set_template_steps(o.template_steps);
    const double seconds = std::chrono::duration<double>(clock::now() - t0).count();
    wrap_seconds += seconds;
    if (!a.quiet)
      std::cerr << "fit: template start: shape " << o.template_shape << " alone for "
                << o.template_steps << " steps (" << format_duration(seconds) << ", L "
                << trainer.last().total << "), its codes copied to every shape\n";
    const NodePlacementReport& nodes = trainer.node_report();
    if (!a.quiet && !nodes.target_rms.empty()) {
      std::fprintf(stderr, "fit: %d nodes in the domain, sigma %.4g", o.atlas.deform_nodes,
                   nodes.sigma);
      if (nodes.fine_sigma > 0)
        std::fprintf(stderr, "; %d fine nodes from zero, sigma %.4g", o.atlas.fine_nodes,
                     nodes.fine_sigma);
      if (o.register_nodes) {
        std::fprintf(stderr, "; registration RMS / left by the nodes:");
        for (size_t i = 0; i < nodes.target_rms.size(); ++i)
          if (int(i) != o.template_shape)
            std::fprintf(stderr, " %.3g / %.3g", nodes.target_rms[i], nodes.residual_rms[i]);
      }
      std::fprintf(stderr, "\n");
    }
  }
  if (a.inject_fault_at >= 0) trainer.inject_faults(a.inject_fault_at, 1);
  const auto start = clock::now();
  auto last_print = start;
  const int64_t first = trainer.iteration();
  bool advanced = false;  // the last step moved on (a fault goes back instead)
  trainer.set_progress([&](const StepReport& r) {
    record_step(log, r);
    advanced = !r.fault;
    if (r.fault) {  // printed even with --quiet: the run's result depends on it
      // Every rank takes the same recovery (the NaN flag is summed over the
      // team): rank 0 speaks for the job.
      if (root)
        std::fprintf(stderr, "  it %6lld: %s\n", (long long)r.fault->iteration,
                     describe(*r.fault).c_str());
      return;
    }
    if (a.quiet) return;
    if (r.mirrored)
      std::fprintf(stderr,
                   "  it %6lld: most normals faced inward; mirrored the domain (u, v) -> (v, u)\n",
                   (long long)r.iteration);
    if (r.reseeded > 0)
      std::fprintf(stderr, "  it %6lld: moved %d Gaussians off back-facing flaps\n",
                   (long long)r.iteration, r.reseeded);
    const auto now = clock::now();
    if (std::chrono::duration<double>(now - last_print).count() > 2.0 ||
        r.iteration >= r.iterations) {
      last_print = now;
      const double rate = double(r.iteration - first) / std::max(1e-9, r.elapsed);
      const LossTerms& l = r.terms;
      std::fprintf(
          stderr,
          "  it %6lld/%lld  %5.1f it/s  ETA %s  L %.3e  6D %.3e  2D %.3e  cyc %.2e/%.2e  iso %.3f  "
          "rep %.3e\n",
          (long long)r.iteration, (long long)r.iterations, rate,
          format_duration(double(r.iterations - r.iteration) / std::max(rate, 1e-9)).c_str(),
          l.total, l.surface, l.chart, l.cycle_2d, l.cycle_6d, l.isometry, l.repulsion);
    }
  });
  // A time budget: time a few iterations, then set the run's length (and so its
  // learning-rate schedule) to what fits. The first iterations allocate the
  // tape and warm the caches, so they are left out of the timing. The length is
  // recorded in the checkpoint, so a resumed run follows the same schedule.
  // Under the ramp the timed steps are the cheap ones of its first level: the
  // later, larger steps are counted in by the schedule's cost model
  // (model/tool/schedule.h: a step costs kStepOverheadPoints + M; an estimate,
  // so a budget may end a little short or long).
  const int64_t warmup = 5, probe = 20;
  auto probe_start = start;
  bool sized = !(a.minutes > 0) || resuming;
  const bool budgeted = !sized;
  int64_t recheck_from = 0, recheck = 0;
  auto recheck_time = start;
  if (!sized && o.iterations < first + warmup + probe) {
    // Too short to be timed (the loop below would wait for iteration 25
    // forever): the timed steps run as those of a default-length run.
    o.iterations = FitOptions().iterations;
    trainer.set_iterations(o.iterations);
  }
  while (!trainer.finished() || !sized) {
    if (!sized && trainer.iteration() - first == warmup) probe_start = clock::now();
    if (!sized && trainer.iteration() - first == warmup + probe) {
      const auto now = clock::now();
      const double per = std::chrono::duration<double>(now - probe_start).count() / double(probe);
      const double left =
          a.minutes * 60.0 - wrap_seconds - std::chrono::duration<double>(now - start).count();
      // Seconds per point of work in the timed steps, then the mean step of a whole run.
      const double timed_cost =
          scheduled_mean_cost(o.schedule, o.points, kStepOverheadPoints, first + warmup,
                              first + warmup + probe, o.iterations);
      const double per_cost = per / timed_cost;
      // A budget too short for the steps a fit needs at this M takes a
      // smaller M (model/tool/schedule.h, budgeted_points): a single shape's
      // run asks for kBudgetMinSteps unless told; an M given with -M is kept,
      // and collections and --preset paper keep theirs (not measured).
      const int64_t min_steps =
          a.min_steps >= 0 ? a.min_steps
                           : (inputs.size() == 1 && a.preset.empty() ? kBudgetMinSteps : 0);
      if (!a.points_given && min_steps > 0) {
        const Index m = Index(rank0_value(
            double(budgeted_points(o.schedule, o.points, kStepOverheadPoints, per_cost, 0.97 * left,
                                   min_steps, Index(kBudgetLeastPoints * double(o.points))))));
        if (m < o.points) {
          if (!a.quiet)
            std::cerr << "fit: " << a.minutes << " min holds fewer than " << min_steps
                      << " steps at M = " << o.points << "; M = " << m
                      << " instead (--min-steps)\n";
          o.points = m;
          trainer.set_points(m);
        }
      }
      const double mean_step =
          per_cost * scheduled_run_cost(o.schedule, o.points, kStepOverheadPoints);
      const int64_t n = int64_t(rank0_value(
          double(warmup + probe + std::max<int64_t>(1, int64_t(left / mean_step * 0.97)))));
      trainer.set_iterations(n);
      o.iterations = n;
      sized = true;
      recheck_from = trainer.iteration();
      recheck_time = now;
      recheck = std::max<int64_t>(10, n / 25);
      if (!a.quiet)
        std::cerr << "fit: " << a.minutes << " min at " << per * 1e3 << " ms/iteration -> " << n
                  << " iterations\n";
    }
    // Keeping the budget: the first estimate comes from 20 cheap steps and a
    // cost model, and a machine whose load changes (or a model that is off)
    // would overrun it. Every `recheck` steps, the time per unit of modelled
    // cost over the last stretch re-estimates what is left; until the first
    // learning-rate decay the run is shortened to fit, or at a fixed M
    // lengthened when the steps got cheaper (budgeted_iterations), and past
    // the budget it stops where it is. Ranks decide on rank 0's numbers.
    if (budgeted && sized && trainer.iteration() - recheck_from >= recheck && !trainer.finished()) {
      const auto now = clock::now();
      const int64_t i = trainer.iteration(), n = o.iterations;
      const double stretch = std::chrono::duration<double>(now - recheck_time).count();
      const double done_cost =
          scheduled_mean_cost(o.schedule, o.points, kStepOverheadPoints, recheck_from, i, n) *
          double(i - recheck_from);
      const double per_cost = stretch / std::max(done_cost, 1e-9);
      const double left =
          a.minutes * 60.0 - wrap_seconds - std::chrono::duration<double>(now - start).count();
      const int64_t first_decay = o.decay_at.empty() ? n : int64_t(o.decay_at.front() * double(n));
      int64_t fit_n = budgeted_iterations(o.schedule, o.points, kStepOverheadPoints, i, n,
                                          first_decay, per_cost, left);
      fit_n = int64_t(rank0_value(double(fit_n)));
      if (fit_n != n) {
        trainer.set_iterations(fit_n);
        o.iterations = fit_n;
        if (!a.quiet)
          std::cerr << "fit: " << per_cost * (kStepOverheadPoints + double(o.points)) * 1e3
                    << " ms per full step now; the run is "
                    << (fit_n < n ? "shortened" : "lengthened") << " to " << fit_n
                    << " iterations to fill --minutes " << a.minutes << "\n";
      }
      recheck_from = i;
      recheck_time = now;
      recheck = std::max<int64_t>(10, o.iterations / 25);
      if (trainer.finished()) continue;
    }
    if (trainer.finished()) continue;
    try {
      trainer.step();
    } catch (const NumericalFault& e) {
      save();  // the trainer is back at its last good state
      throw InputError(std::string("fit: ") + e.what() + "; last good state saved in " + dir +
                       "/model.ckpt");
    }
    if (advanced && a.checkpoint_every > 0 && trainer.iteration() % a.checkpoint_every == 0) save();
    // A signal reaches the ranks at different steps: stop when any rank has one.
    double signalled = g_signal != 0 ? 1.0 : 0.0;
    if (many) team.sum_in_rank_order(&signalled, 1);
    if (advanced && a.stop_at > 0 && trainer.iteration() == a.stop_at && !trainer.finished()) {
      save();
      if (!a.quiet)
        std::cerr << "fit: stopped at iteration " << trainer.iteration()
                  << " (--stop-at); continue with: jsatlas fit --resume " << dir << "\n";
      return;
    }
    if (signalled > 0) {
      save();
      std::cerr << "fit: interrupted; checkpoint written at iteration " << trainer.iteration()
                << " (continue with: jsatlas fit --resume " << dir << ")\n";
      throw ExitCode{130};
    }
  }
  const double seconds = std::chrono::duration<double>(clock::now() - start).count();
  const uint64_t bytes = team.bytes_exchanged();
  save();
  if (!root) return;
  // The surface samples back for the outputs' back-facing measure (the
  // trainer held the only copy; their normals' length does not matter there).
  for (size_t i = 0; i < shapes.size(); ++i)
    if (trainer.pool(int(i)).rows() > 0) shapes[i].pool = trainer.pool(int(i)).cast<double>();
  write_run_outputs(trainer.atlas(), shapes, log, dir,
                    MeshOutputOptions{a.mesh_resolution, a.mesh_threshold, a.quiet, a.texture});
  if (!a.quiet) {
    const int64_t steps = std::max<int64_t>(1, trainer.iteration() - first);
    std::cerr << "fit: done in " << format_duration(seconds) << " ("
              << seconds * 1e3 / double(steps) << " ms/iteration";
    if (many) std::cerr << ", rank 0 exchanged " << bytes / uint64_t(steps) << " bytes/iteration";
    std::cerr << "); results in " << dir << "\n";
  }
  // The report (stdout): what the run did beyond plain Adam steps.
  std::cout << "fit: " << trainer.iteration() << " iterations, " << trainer.faults()
            << " NaN/Inf fault" << (trainer.faults() == 1 ? "" : "s") << ", " << trainer.mirrors()
            << " mirror" << (trainer.mirrors() == 1 ? "" : "s") << ", " << trainer.reseeded()
            << " Gaussians reseeded\n";
  for (const FaultRecovery& f : trainer.fault_log())
    std::cout << "  fault: " << describe(f) << "\n";
}

}  // namespace

// CLI11's number checks let NaN through (every comparison with NaN is false).
const CLI::Validator kFinite(
    [](std::string& s) {
      try {
        return std::isfinite(std::stod(s)) ? std::string() : "must be a finite number, got " + s;
      } catch (const std::exception&) {
        return "must be a number, got " + s;
      }
    },
    "FINITE");

void add_fit(CLI::App& app) {
  auto a = std::make_shared<FitArgs>();
  FitOptions& o = a->options;
  // Collections start from one shape's atlas (the template start), 30% of the
  // run: measured on the SHREC ants and teddies (docs/collections.md).
  o.template_steps = -1;
  o.template_share = 0.3;
  o.template_max_steps = kTemplateMaxSteps;
  // ... of its medoid, the most typical shape (docs/collections.md, sixth round).
  o.template_shape = -1;
  CLI::App* c = app.add_subcommand(
      "fit", "Learn the atlas of a shape: domain P, parametrization phi, chart psi");
  c->add_option("inputs", a->inputs,
                "Mesh (.obj .off .ply), oriented point cloud (.ply with normals, .xyz x y z nx ny "
                "nz), or builtin:NAME (sphere, torus, cube, capsule); several inputs fit a "
                "collection with one shared domain (Sec. 3.4)");
  c->add_option("--list", a->list_file, "A file naming one input per line (collections)");
  c->add_option("--code-size", o.atlas.code_size,
                "Collections: width of the latent codes f_phi,i and f_psi,i")
      ->capture_default_str()
      ->check(CLI::Range(1, 4096));
  c->add_option("--w-code", o.weights.code,
                "Collections: weight of the mean squared norm of the codes")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber)
      ->check(kFinite);
  c->add_option("--w-coverage", o.weights.coverage,
                "Weight of L_6D's coverage direction (every target near the reconstruction) "
                "against its accuracy direction (1: the paper's Chamfer, Eq. 6)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber)
      ->check(kFinite);
  c->add_option("--w-metric", o.weights.metric,
                "Collections: lambda_metric on L_metric, each shape's metric J^T J against shape "
                "0's at the same domain points (beyond the paper; 0: off; docs/collections.md)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber)
      ->check(kFinite);
  c->add_option("--w-even", o.weights.evenness,
                "lambda_even on L_even, the variance of log(P's density / phi's area element) "
                "at the samples: phi(x_P) spread evenly over the surface (beyond the paper; "
                "0: off; docs/results.md)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber)
      ->check(kFinite);
  c->add_option("--w-emd", o.weights.transport,
                "lambda_EMD on L_EMD, the exact assignment of --emd-points samples to as many "
                "targets as a term: every target a sample of its own (beyond the paper; 0: off; "
                "docs/results.md)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber)
      ->check(kFinite);
  c->add_option("--w-metric-end", o.metric_end,
                "Collections: lambda_metric moves from --w-metric at the first joint step to this "
                "at --w-metric-until (geometrically; linearly to 0), then stays (-1: constant)")
      ->capture_default_str()
      ->check(kFinite);
  c->add_option("--w-metric-until", o.metric_until,
                "Collections: the fraction of the joint steps where --w-metric-end is reached (-1: "
                "the first learning-rate decay); by default L_metric guards the first quarter, "
                "where the layouts are decided")
      ->capture_default_str()
      ->check(CLI::Range(-1.0, 1.0))
      ->check(kFinite);
  c->add_flag("--metric-conformal", o.metric_conformal,
              "Collections: L_metric compares the shapes' metrics up to a scale per point "
              "(conformal) instead of exactly (isometric)");
  c->add_option("-o,--out", a->out_dir, "Output directory (created if needed)");
  c->add_option("--resume", a->resume,
                "Continue the run in DIR from its model.ckpt (settings come from the checkpoint)");
  c->add_option("--iters", o.iterations,
                "Training iterations (collections and --preset paper: " +
                    std::to_string(kFixedScheduleIterations) + ")")
      ->capture_default_str()
      ->check(CLI::Range(int64_t(0), int64_t(100000000)));
  c->add_option("--points,-M", o.points,
                "M: points sampled on P and on the shape per iteration (collections: " +
                    std::to_string(kCollectionPoints) + ")")
      ->capture_default_str()
      ->check(CLI::Range(Index(16), Index(1000000)));
  c->add_option("--gaussians,-K", o.atlas.gaussians,
                "K: Gaussians in the domain P (sigma = 1/sqrt(K); collections: " +
                    std::to_string(kCollectionGaussians) + ")")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000000));
  c->add_option(
       "--width", o.atlas.width,
       "Hidden units of phi and psi (collections: " + std::to_string(kCollectionWidth) + ")")
      ->capture_default_str()
      ->check(CLI::Range(4, 4096));
  c->add_option("--chart-width", o.atlas.chart_width,
                "Hidden units of psi alone (0: --width); beyond the paper, for a chart that "
                "inverts phi where one as wide as phi cannot")
      ->capture_default_str()
      ->check(CLI::Range(0, 4096));
  c->add_option("--chart-fourier", o.atlas.chart_fourier,
                "psi's input widened by this many random Fourier features of the point, "
                "[p, alpha n, sin(p B), cos(p B)] (collections: " +
                    std::to_string(kCollectionChartFourier) +
                    "; 0: the paper's psi, the default for a single shape and --preset paper); "
                    "beyond the paper")
      ->capture_default_str()
      ->check(CLI::Range(0, 4096));
  c->add_option("--chart-fourier-sigma", o.atlas.chart_fourier_sigma,
                "With --chart-fourier: the frequencies' standard deviation (unit frame)")
      ->capture_default_str()
      ->check(CLI::Range(1e-3, 1e3))
      ->check(kFinite);
  c->add_option("--depth", o.atlas.hidden_layers, "Hidden layers of phi and psi")
      ->capture_default_str()
      ->check(CLI::Range(1, 32));
  c->add_option("--alpha", o.atlas.alpha, "Norm of the scaled normals (Eq. 2)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber)
      ->check(kFinite);
  c->add_option("--lr", o.lr, "Adam learning rate (collections and --preset paper: 1e-3)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber)
      ->check(kFinite);
  c->add_option("--decay", o.decay, "Learning-rate factor at each decay point")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0))
      ->check(kFinite);
  c->add_option("--decay-at", o.decay_at, "Fractions of --iters where the learning rate decays")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  c->add_option("--schedule", o.schedule.kind,
                "ramp: M grows from --points-start x M to M by --ramp-until of the run; step: M "
                "fixed (the paper's, and the default for collections and --preset paper); both "
                "decay lr at --decay-at")
      ->capture_default_str()
      ->check(CLI::IsMember({"ramp", "step"}));
  c->add_option("--points-start", o.schedule.points_start,
                "ramp: M at the start, as a fraction of --points")
      ->capture_default_str()
      ->check(CLI::Range(0.001, 1.0))
      ->check(kFinite);
  c->add_option("--ramp-until", o.schedule.ramp_until,
                "ramp: fraction of the run by which M reaches --points")
      ->capture_default_str()
      ->check(CLI::Range(0.001, 1.0))
      ->check(kFinite);
  c->add_option("--ramp-levels", o.schedule.levels, "ramp: M grows in this many equal steps")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000));
  c->add_option("--warmup", o.schedule.warmup,
                "Fraction of the run over which lr rises linearly from lr/10 (0: none)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0))
      ->check(kFinite);
  c->add_option("--lr-drop-at", o.schedule.drop_at,
                "Fraction of the run from which the learning rate is multiplied by --lr-drop "
                "(0: never)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0))
      ->check(kFinite);
  c->add_option("--lr-drop", o.schedule.drop, "Learning-rate factor from --lr-drop-at on")
      ->capture_default_str()
      ->check(CLI::Range(1e-6, 1.0))
      ->check(kFinite);
  c->add_option("--minutes", a->minutes,
                "Time budget: after 5 warm-up and 20 timed iterations, set --iters to fill it (the "
                "schedule follows; the ramp's later, larger steps counted in)")
      ->check(CLI::Range(0.01, 100000.0));
  c->add_option("--min-steps", a->min_steps,
                "With --minutes: the steps a single shape's run should have at least; a budget "
                "too short for them at M takes a smaller M (down to M/2; 0: keep M; default " +
                    std::to_string(kBudgetMinSteps) +
                    " for a single shape, 0 for collections and --preset paper; an M given "
                    "with -M is kept)")
      ->check(CLI::Range(int64_t(0), int64_t(100000000)));
  c->add_option("--stop-at", a->stop_at,
                "Stop after this iteration with a checkpoint, exit 0; continue with --resume (job "
                "time limits; the schedule is --iters')")
      ->check(CLI::Range(int64_t(1), int64_t(100000000)));
  c->add_option("--seed", o.seed, "Random seed (same seed and threads -> same run)")
      ->capture_default_str();
  c->add_option(
       "--threads", a->threads,
       "Threads (default: all cores; a resumed run keeps its own, as results depend on it)")
      ->check(CLI::Range(0, 1024));
  c->add_option("--gemm", a->gemm,
                "The float GEMMs' backend: auto (the faster here, measured once per machine and "
                "kept in ~/.cache/jsatlas/gemm.json; Eigen where nothing can be kept), eigen, or "
                "blas (default: auto; a resumed run keeps its own, as results depend on it)")
      ->check(CLI::IsMember({"auto", "eigen", "blas"}));
  c->add_option("--w-6d", o.weights.surface, "lambda_6D on L_6D (Eq. 7)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber)
      ->check(kFinite);
  c->add_option("--w-2d", o.weights.chart, "lambda_2D on L_2D (Eq. 8)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber)
      ->check(kFinite);
  c->add_option("--w-cycle", o.weights.cycle,
                "lambda_cycle on L_cycle (Eq. 9; mean convention, = paper's 1/M on sums)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber)
      ->check(kFinite);
  c->add_option("--w-iso", o.weights.isometry,
                "lambda_iso on L_iso (Eq. 10; mean convention, = paper's 1e-4/M on sums)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber)
      ->check(kFinite);
  c->add_option("--w-rep", o.weights.repulsion, "lambda_rep on L_rep (Eq. 11)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber)
      ->check(kFinite);
  c->add_option("--table-row", a->table_row,
                "Ablation of the paper's Table 1: row 6..11 (11 = full method)")
      ->check(CLI::Range(6, 11));
  c->add_flag("--no-normals", a->no_normals, "Ablation: 3D Chamfer without normals");
  c->add_flag("--no-repulsion", a->no_repulsion, "Ablation: no L_rep");
  c->add_flag("--no-distribution", a->no_distribution,
              "Ablation: sample the Gaussian means only (a learned point set)");
  c->add_flag("--no-chart", a->no_chart, "Ablation: no chart psi, no L_2D, no L_cycle");
  c->add_flag("--no-isometry", a->no_isometry, "Ablation: no L_iso");
  c->add_option(
      "--preset", a->preset,
      "paper: the paper's method at its sizes: M = K = 10^4, 5 x 256 ReLU MLPs, alpha 0.01, "
      "lambda_cycle 1, and none of the heuristics beyond the paper (no orientation mirror, wrap, "
      "reseed, dense surface, pose alignment or template start; slow on a laptop; these win over "
      "the same settings' flags)");
  c->add_option("--pool", o.pool, "Surface samples drawn once from the input")
      ->capture_default_str()
      ->check(CLI::Range(Index(100), Index(10000000)));
  c->add_option("--repulsion-tolerance", o.repulsion_tolerance,
                "Bound on the error of L_rep from its cut-off radius")
      ->capture_default_str()
      ->check(CLI::Range(1e-15, 1e-2))
      ->check(kFinite);
  c->add_option("--softplus", o.atlas.softplus_beta,
                "Activation of phi and psi: BETA > 0 softplus log(1 + e^(BETA z)) / BETA (smooth "
                "normals), 0 ReLU (the paper)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1e6))
      ->check(kFinite);
  c->add_option("--code-layer", o.atlas.code_layer,
                "Collections: where the codes enter phi and psi: 0 the input (concatenation), 1 "
                "after the first layer")
      ->capture_default_str()
      ->check(CLI::Range(0, 1));
  c->add_option("--deform-layers", o.atlas.deform_layers,
                "Collections: phi_i(x) = phi(x) + D(phi(x), f_i), each shape a deformation of "
                "one surface by an MLP D of this many hidden layers (0: phi(x, f_i), the paper's; "
                "collections: " +
                    std::to_string(kCollectionDeformLayers) + ")")
      ->capture_default_str()
      ->check(CLI::Range(0, 64));
  c->add_flag("--deform-domain", o.atlas.deform_domain,
              "Collections, with --deform-layers > 0: D also reads the domain point, "
              "phi_i(x) = phi(x) + D(phi(x), x, f_i)");
  c->add_option("--reseed", o.reseed_every,
                "Every N steps before the first decay, move the Gaussians of back-facing flaps to "
                "the surface's holes (0: never, as the paper; see model/heuristics/reseed.h)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1000000));
  c->add_flag("--dense-surface,!--no-dense-surface", o.dense_surface,
              "L_6D matches phi6(x_P) in the whole pool of surface samples, not only the step's M "
              "(sharper pull; see losses/chamfer.h)")
      ->capture_default_str();
  c->add_option("--wrap", o.wrap_steps,
                "Steps fitting phi and psi to a closed ellipsoid around the shape before training "
                "(0: random start, as the paper; see model/heuristics/wrap.h)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1000000));
  c->add_flag("--parallel-shapes,!--serial-shapes", o.parallel_shapes,
              "Collections: split each step's shapes over the threads, a tape per thread "
              "(--serial-shapes: one shape at a time, the threads inside each kernel)")
      ->capture_default_str();
  c->add_option("--code-lr-scale", o.code_lr_scale,
                "Collections: learning rate of the latent codes as a multiple of the networks'")
      ->capture_default_str()
      ->check(CLI::Range(1e-3, 1e3))
      ->check(kFinite);
  c->add_option("--surface-lr-scale", o.surface_lr_scale,
                "Collections with --deform-layers > 0: learning rate of the shared surface phi "
                "in the joint training as a multiple of the rest's (0: the template's surface "
                "stays fixed, every shape a deformation of it)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1e3))
      ->check(kFinite);
  c->add_option("--intrinsic", o.intrinsic,
                "Collections: beta, the weight of pose-invariant descriptors (geodesic distance "
                "statistics) appended to L_6D, so each domain point lands where the shapes agree "
                "along their surfaces (0: off)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1e3))
      ->check(kFinite);
  c->add_option("--intrinsic-until", o.intrinsic_until,
                "With --intrinsic: the descriptors in the template start and this fraction of "
                "--iters, then L_6D alone")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0))
      ->check(kFinite);
  c->add_option(
       "--spectral-map", o.spectral_map,
       "Collections of meshes: lambda_map, the pull of each shape towards the image of "
       "the template under a map between their Laplace-Beltrami eigenfunctions (ZoomOut), "
       "which an arm's pose does not change; fades to 0 over --spectral-map-until (0: off)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1e3))
      ->check(kFinite);
  c->add_option(
       "--deform-nodes", o.atlas.deform_nodes,
       "Collections: add to phi_i a displacement sum_k w_k(x) t_k,i over this many "
       "normalised Gaussian kernels in the domain, placed after the template start, which can move "
       "a part that touches another in 3D alone (0: none)")
      ->capture_default_str()
      ->check(CLI::Range(0, 4096));
  c->add_flag("--register", o.register_nodes,
              "Collections of meshes, with --deform-nodes: start each shape's node displacements "
              "from a spectral registration of the template to it (ZoomOut), fitted by least "
              "squares, so the maps decide the correspondence and the training refines it");
  c->add_option("--auto-register", o.auto_register,
                "Collections of meshes without --deform-nodes: start from the spectral "
                "registration (as --deform-nodes " +
                    std::to_string(kAutoRegisterNodes) +
                    " --register --nodes-lr-scale 0) when the template's maps to the others "
                    "and back come back at most this many times farther off than the nearest "
                    "points in space do (collections: 2; 0: never)")
      ->check(CLI::Range(0.0, 1e3))
      ->check(kFinite);
  c->add_option("--nodes-lr-scale", o.nodes_lr_scale,
                "With --deform-nodes: learning rate of the node displacements as a multiple of "
                "the rest's (0: they keep the registration's start)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1e3))
      ->check(kFinite);
  c->add_option("--nodes-width", o.nodes_width,
                "With --deform-nodes: the kernels' width as a multiple of the centres' spacing in "
                "the domain (wider: a smoother displacement)")
      ->capture_default_str()
      ->check(CLI::Range(0.1, 100.0))
      ->check(kFinite);
  c->add_option("--fine-nodes", o.atlas.fine_nodes,
                "With --deform-nodes: a second field of this many nodes, its own kernels "
                "(--fine-width), started from zero and learning at the networks' rate whatever "
                "--nodes-lr-scale says: local changes next to a held registration (0: none)")
      ->capture_default_str()
      ->check(CLI::Range(0, 4096));
  c->add_option("--fine-width", o.fine_width,
                "With --fine-nodes: the second field's width as a multiple of its centres' "
                "spacing in the domain")
      ->capture_default_str()
      ->check(CLI::Range(0.1, 100.0))
      ->check(kFinite);
  c->add_flag("--template-coverage", o.template_coverage,
              "Collections of meshes, with --template-shape -1: take as the template the shape "
              "whose spectral registration covers the others best instead of the medoid (one "
              "ZoomOut per ordered pair of shapes; the time counts against --minutes)");
  c->add_option("--register-prior", o.register_prior,
                "With --register: weight of the maps' spatial prior (each template vertex kept "
                "near its place in space on ZoomOut's small sizes; 0: none)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1e3))
      ->check(kFinite);
  c->add_option("--spectral-map-until", o.spectral_map_until,
                "With --spectral-map: the fraction of --iters over which lambda_map falls to 0")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0))
      ->check(kFinite);
  c->add_option("--w-even-from", o.evenness_from,
                "L_even (--w-even) from this fraction of --iters on (0: all along)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0))
      ->check(kFinite);
  c->add_option("--w-emd-from", o.transport_from,
                "L_EMD (--w-emd) from this fraction of --iters on (0: all along)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0))
      ->check(kFinite);
  c->add_option("--emd-points", o.transport_points,
                "L_EMD's n: the first n of a step's samples and targets (at most M)")
      ->capture_default_str()
      ->check(CLI::Range(Index(1), Index(100000)));
  c->add_option("--chart-from", o.chart_from,
                "Staged objective: phi and P alone (no psi, L_2D, L_cycle) until this fraction of "
                "--iters, then the full method (0: full from the start)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0))
      ->check(kFinite);
  c->add_option(
       "--template-steps", o.template_steps,
       "Collections: steps fitting the template shape alone before the joint training, then its "
       "codes copied to every shape (-1: from --template-share)")
      ->capture_default_str()
      ->check(CLI::Range(int64_t(-1), int64_t(100000000)));
  c->add_option(
       "--template-shape", o.template_shape,
       "Collections: the shape the template start fits and copies, and L_metric's "
       "reference (-1: the medoid, the shape closest to all others; of two shapes, the first)")
      ->capture_default_str()
      ->check(CLI::Range(-1, 1 << 20));
  c->add_option("--template-share", o.template_share,
                "Collections, with --template-steps -1: share of the run's time (or cost) spent on "
                "the template start")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 0.95))
      ->check(kFinite);
  c->add_option("--template-max-steps", o.template_max_steps,
                "Collections, with --template-steps -1: at most this many template steps, the "
                "rest of the share going to the joint training (0: no cap)")
      ->capture_default_str()
      ->check(CLI::Range(int64_t(0), int64_t(100000000)));
  c->add_flag("--align,!--no-align", o.align_poses,
              "Collections: turn the first shape onto its principal axes and every other into "
              "its pose (principal axes, ICP, lowest Chamfer) before fitting; rotations.json "
              "lists them")
      ->capture_default_str();
  c->add_option("--pose-fit", o.pose_fit_steps,
                "Collections, with --align: a shape with several poses within 1.25x of the lowest "
                "Chamfer (near-symmetric) takes the pose whose short fit of N joint steps ends "
                "lowest (0: the lowest Chamfer)")
      ->capture_default_str()
      ->check(CLI::Range(int64_t(0), int64_t(1) << 20));
  c->add_option("--batch-shapes", o.batch_shapes,
                "Collections: shapes per iteration, a seeded random subset (0: all); the loss is "
                "scaled by N/B")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  c->add_option("--orient-every", o.orient_every,
                "Choose phi's global orientation every N iterations until the first decay (0: "
                "never; see model/heuristics/orientation.h)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  c->add_option("--checkpoint-every", a->checkpoint_every,
                "Write model.ckpt every N iterations (0: only at the end)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  c->add_option("--mesh-resolution", a->mesh_resolution,
                "Grid cells across the domain for domain_mesh.obj")
      ->capture_default_str()
      ->check(CLI::Range(8, 4096));
  c->add_option("--mesh-threshold", a->mesh_threshold,
                "Domain = {P >= t * median of P at the means}")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 100.0))
      ->check(kFinite);
  c->add_option("--texture", a->texture,
                "An image for the MTLs of the results; also writes texture_transfer.png");
  c->add_flag("-q,--quiet", a->quiet, "No progress output");
  // Hidden (no group): lets the CLI tests see a NaN/Inf recovery end to end.
  c->add_option("--inject-fault-at", a->inject_fault_at, "Tests: one NaN loss at this iteration")
      ->group("");
  c->callback([a, c]() {
    a->iters_given = c->count("--iters") > 0;
    a->schedule_given = c->count("--schedule") > 0;
    a->points_given = c->count("--points") > 0;
    a->gaussians_given = c->count("--gaussians") > 0;
    a->width_given = c->count("--width") > 0;
    a->deform_given = c->count("--deform-layers") > 0;
    a->auto_register_given = c->count("--auto-register") > 0;
    a->chart_fourier_given = c->count("--chart-fourier") > 0;
    a->even_given = c->count("--w-even") > 0;
    a->emd_given = c->count("--w-emd") > 0;
    a->lr_given = c->count("--lr") > 0;
    std::unique_ptr<Team> team = join_team();
    if (team->size() == 1) return run_fit(*a, *team);
    try {
      run_fit(*a, *team);
    } catch (const ExitCode& e) {
      if (e.code == 130)
        throw;  // an interrupt all ranks agreed on: each leaves through MPI_Finalize
      abort_mpi_job(e.code);
    } catch (const std::exception& e) {
      // Perhaps this rank alone (its input, its disk): the others would wait for it forever.
      std::cerr << "jsatlas: error on MPI rank " << team->rank() << " of " << team->size() << ": "
                << e.what() << "\n";
      abort_mpi_job(1);
    }
  });
}

}  // namespace jsa::cli
