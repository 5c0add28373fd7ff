// The AtlasNet baselines of Table 1 (rows 1-4), in the same engine as the
// joint atlas: P patches, each mapped to 3D by its own MLP phi_p.
//  - ANv1-P (AtlasNet, Groueix et al. 2018): every step maps fresh uniform
//    samples of the unit square [0,1]^2 (M/P per patch).
//  - ANv2-P (AtlasNet v2, "points" variant, Deprelle et al. 2019): each patch
//    maps a learned set of M/P 2D points, a parameter like the weights.
// A collection gives each shape a latent code f_i, fed to every patch MLP as a
// first-layer bias (model/mlp.h), so one model fits N shapes (auto-decoder, as
// the joint atlas of Sec. 3.4). The loss is the 3D Chamfer (Eq. 6 on points
// only) summed over the shapes (as Eq. 12 sums L_single): no normals, no chart.
// Correspondences therefore use the paper's nearest-sample rule (Sec. 4).
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "engine/adam.h"
#include "io/geometry/mesh.h"
#include "io/geometry/normalization.h"
#include "model/parametrize.h"
#include "model/tool/evaluate.h"
#include "model/tool/trainer.h"

namespace jsa {

// Which baseline: Table 1 rows 1-4.
struct AtlasNetVariant {
  int patches = 1;              // P (Table 1: 1 or 10)
  bool learned_points = false;  // false: v1 (uniform squares); true: v2 (learned point sets)
  static AtlasNetVariant table_row(int row);  // 1: ANv1-1, 2: ANv2-1, 3: ANv1-10, 4: ANv2-10
  std::string name() const;                   // "ANv1-10", as Table 1 names them
};

struct AtlasNetOptions {
  AtlasNetVariant variant;
  Index points = 2500;    // M: points per step over all patches; v2: the learned sets' total size
  int width = 128;        // hidden units of each phi_p
  int hidden_layers = 5;  // hidden layers of each phi_p
  int shapes = 1;         // N; > 1 adds a latent code per shape
  int code_size = 256;    // D, width of f_i when shapes > 1
};

// The baseline with the sizes of a fit of ours (M, width, depth, code size),
// so that rows 1-4 and 6-11 of a table run at the same budget.
AtlasNetOptions atlasnet_options(const AtlasNetVariant& variant, const FitOptions& fit, int shapes);

template <class T>
class AtlasNet {
 public:
  explicit AtlasNet(const AtlasNetOptions& options);
  AtlasNet(const AtlasNet&) = delete;  // tape closures point into params: the model stays put
  AtlasNet& operator=(const AtlasNet&) = delete;

  // MLPs as PyTorch's default, v2 points ~ U[0,1]^2, codes ~ N(0, 0.01^2).
  void initialize(Rng& rng);

  int patches() const { return options_.variant.patches; }
  int shapes() const { return options_.shapes; }
  bool has_codes() const { return options_.shapes > 1; }
  const AtlasNetOptions& options() const { return options_; }
  // Rows of patch p among `count` points: count / P, the first count mod P one more.
  Index patch_share(Index count, int patch) const;
  // f_i (1 x D) of shape i on the tape; an invalid Var for a single shape.
  Var code(Tape<T>& t, int shape);
  // Patch p's 2D points of one step: v1, M/P uniform samples of [0,1]^2 drawn
  // from rng (constants); v2, its learned set (a parameter, rng unused).
  Var patch_points(Tape<T>& t, int patch, Rng& rng);
  // v2: parameter index of patch p's learned set (M/P x 2); -1 for v1.
  int learned_points(int patch) const { return points_.empty() ? -1 : points_[size_t(patch)]; }

  Parameters<T> params;
  std::vector<Parametrization<T>> phi;  // phi_p, one per patch ("patch<p>.w0", ...)

 private:
  AtlasNetOptions options_;
  std::vector<int> points_;  // v2: per patch
  int codes_ = -1;           // N x D
};

// L = sum_i CD(phi_i(x), S_i) + l_code (1/N) sum_i |f_i|^2, CD the 3D Chamfer
// of Eq. 6 between all patches' points of shape i (M x 3) and its targets
// (targets[i]: M x C, C >= 3, the first 3 columns are used). `chamfer`, if
// given, receives the mean over the shapes of CD. A non-finite network output
// gives a NaN loss (and chamfer), for the trainer to catch, rather than a
// nearest-neighbour search among non-finite points.
template <class T>
Var atlasnet_objective(Tape<T>& t, AtlasNet<T>& net, const std::vector<Block<T>>& targets, Rng& rng,
                       double code_weight, double* chamfer = nullptr);

// The training loop of a baseline, with the fields of FitOptions that apply:
// iterations, points (M), lr with its step decay, seed, atlas.width,
// atlas.hidden_layers, atlas.code_size, weights.code, max_faults. Adam, M
// targets per shape per step drawn from a fixed pool, as Trainer does; the same
// seed and thread count give the same losses.
class AtlasNetTrainer {
 public:
  // pools: per shape, P x C rows (C >= 3) whose first 3 columns are surface
  // points in the shape's unit frame (Trainer's P x 6 pools do).
  AtlasNetTrainer(const FitOptions& options, const AtlasNetVariant& variant,
                  const std::vector<Block<double>>& pools);
  // One iteration. A NaN/Inf loss or gradient skips the step and halves the
  // learning rate; after max_faults in a row, NumericalFault.
  void step();
  double learning_rate() const;
  int64_t iteration() const { return iteration_; }
  bool finished() const { return iteration_ >= options_.iterations; }
  double last_loss() const { return last_loss_; }        // the objective of the last step
  double last_chamfer() const { return last_chamfer_; }  // its 3D Chamfer, mean over shapes
  AtlasNet<float>& net() { return *net_; }
  const FitOptions& options() const { return options_; }

 private:
  FitOptions options_;
  std::vector<Block<float>> pools_;  // per shape P x 3
  std::unique_ptr<AtlasNet<float>> net_;
  Adam<float> adam_;
  Tape<float> tape_;
  Rng rng_;
  std::vector<Block<float>> targets_;
  int64_t iteration_ = 0;
  double last_loss_ = 0, last_chamfer_ = 0, lr_scale_ = 1;
  int faults_in_a_row_ = 0;
};

// Where points of a patch model come from: patch[r] and its 2D point uv.row(r).
struct PatchPoints {
  std::vector<int> patch;  // N
  Block<double> uv;        // N x 2
};

// `count` 2D points spread over the patches (patch_share each). v1: uniform in
// [0,1]^2. v2: each patch's learned points in a seeded random order, cycled,
// so no point repeats before all of its set are used.
PatchPoints sample_patches(const AtlasNet<float>& net, Index count, Rng& rng);

// phi_p of shape i at every (patch, uv): points (unit frame) and unit normals
// n = (J_u x J_v) / |J_u x J_v| from each patch's Jacobian (Eq. 2, as
// Parametrization computes them).
void evaluate_patches(AtlasNet<float>& net, const PatchPoints& at, int shape, Block<double>& points,
                      Block<double>& normals);

// Shape i's reconstruction scored as the joint atlas' (model/tool/evaluate.h): M'
// points from sample_patches (Rng(o.seed, 10)) against the same ground-truth samples.
Evaluation evaluate_atlasnet(AtlasNet<float>& net, const Mesh& shape,
                             const Normalization& normalization, const EvaluationOptions& o,
                             int index = 0);

// The paper's nearest-sample rule (Sec. 4) for a patch model: a fixed set of
// (patch, 2D point) samples, v1 `count` seeded uniform ones, v2 every learned
// point. p on shape I goes to the image by shape J of the sample whose image by
// shape I is nearest to p. The images of the set are computed once per shape.
class AtlasNetCorrespondence {
 public:
  AtlasNetCorrespondence(AtlasNet<float>& net, Index count, uint64_t seed);
  // p_unit: N x 3 on shape `from`, its unit frame -> N x 3 on shape `to`, its unit frame.
  Block<double> operator()(int from, int to, const Block<double>& p_unit) const;
  const PatchPoints& samples() const { return samples_; }
  const Block<double>& image(int shape) const { return images_[size_t(shape)]; }

 private:
  PatchPoints samples_;
  std::vector<Block<double>> images_;  // per shape: the set mapped by phi_{., i}
};

}  // namespace jsa
