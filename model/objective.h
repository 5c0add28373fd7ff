// L_single, Eq. (5): the weighted sum of the five terms for one shape,
//   l_6D L_6D + l_2D L_2D + l_cycle L_cycle + l_iso L_iso + l_rep L_rep,
// built on the tape for one iteration, with the switches of the paper's
// ablation (Table 1 rows 6-11).
//
// Convention: every term is a MEAN over its points (as Eqs. 6-10 write them),
// so the paper's weights are l_6D = 1, l_2D = 1e-2, l_cycle = 1, l_iso = 1e-4,
// l_rep = 1 (LossWeights' defaults; `jsatlas fit` lowers l_cycle, model/tool/trainer.h).
// This reads the paper's l_cycle = 1/M and l_iso = 1e-4/M as weights of losses
// written as sums over the M points: an inference from the text, one of three
// readings compared in docs/method.md (D1).
#pragma once
#include "io/geometry/nearest.h"
#include "model/atlas.h"

namespace jsa {

struct LossWeights {
  double surface = 1.0;    // l_6D, on L_6D (Eq. 7)
  double chart = 1e-2;     // l_2D, on L_2D (Eq. 8)
  double cycle = 1.0;      // l_cycle, on L_cycle (Eq. 9), mean convention (FitOptions: 0.1)
  double isometry = 1e-4;  // l_iso, on L_iso (Eq. 10), mean convention
  double repulsion = 1.0;  // l_rep, on L_rep (Eq. 11)
  double code = 1e-4;      // collections: weight of the mean squared norm of the latent codes
  double metric = 0;       // collections: on L_metric (beyond the paper; losses/isometry.h)
  double evenness = 0;     // on L_even, samples spread evenly (beyond the paper; losses/evenness.h)
  double map = 0;          // collections: on L_map, the pull of a spectral map (MapField below)
  double transport =
      0;  // on L_EMD, the exact assignment as a term (beyond the paper; losses/transport.h)
  // Inside L_6D: the weight of its coverage direction (each target's distance
  // to the nearest phi6(x_P)) against its accuracy direction; 1 is Eq. 6.
  double coverage = 1.0;
};

// Which parts of the method are on. The default is Table 1 row 11, the full method.
struct Components {
  bool normals = true;       // n in phi6 and in the Chamfer (row 7)
  bool repulsion = true;     // L_rep (row 8)
  bool distribution = true;  // sample P rather than the means alone (row 9)
  bool chart = true;         // psi with L_2D and L_cycle (row 10)
  bool isometry = true;      // L_iso (row 11)
  // Table 1 row 6..11 (row 6: phi on learned points, 3D Chamfer only).
  static Components table_row(int row);
};

// The value of each term at the last evaluation (unweighted), and the total.
struct LossTerms {
  double total = 0, surface = 0, chart = 0, cycle_2d = 0, cycle_6d = 0, isometry = 0, repulsion = 0;
  double evenness = 0;  // 0 when l_even is 0 (not computed)
  double map = 0;       // L_map; 0 when off
};

struct ObjectiveOptions {
  LossWeights weights;
  Components components;
  double repulsion_tolerance = 1e-7;  // bound on the error of L_rep from its cut-off
  // Collections: the shape whose metric every other shape's is compared with
  // by L_metric at the same domain points (-1: none).
  int metric_reference = -1;
  // L_metric compares the forms up to a scale per point (conformal_metric_mismatch).
  bool metric_conformal = false;
  // L_EMD's n: the first n of the step's samples and targets (at most M).
  Index transport_points = 256;
};

// Beyond the paper (issue 19, docs/collections.md, twelfth round): L_6D with
// pose-invariant descriptors h (io/geometry/intrinsic_descriptors.h) appended to
// both sides, so that one domain point lands where the shapes' surfaces agree
// intrinsically (the hand on the hand, whether the arm is folded or held out):
//
//   L_6D^h = CD( [phi6_i(x_P), beta h_t(phi_t(x_P))],  [x_S, alpha n_S, beta h_i(x_S)] )
//
// t the reference shape (the template), h_t(y) the descriptor of t's sample
// nearest to y: every shape is asked to carry at x the descriptor the reference
// carries there. The targets then have 9 columns, the pool index too; h_t is a
// constant of the step (no gradient flows through the look-up). Measured: the
// teddies' hand moves (46 -> 38-42 x 1e-2) but every variant tried carries the
// keypoints no better and reconstructs worse, so it is off by default.
template <class T>
struct IntrinsicField {
  int reference = 0;                         // t
  const NearestIndex<T>* surface = nullptr;  // t's samples (3D points)
  const Block<T>* descriptors = nullptr;     // beta h_t at those samples
};

// Beyond the paper (issue 19, docs/collections.md, "A spectral map as the
// layouts' start"): a vertex-to-vertex map T_i from the template t to each shape
// i, found before training by ZoomOut on the shapes' Laplace-Beltrami
// eigenfunctions (io/geometry/functional_map.h), which do not change when an
// arm bends. L_map asks shape i to put each domain point where T_i sends the
// template's point there:
//
//   L_map = (1/M) sum_m | phi_i(x_m) - T_i(phi_t(x_m)) |^2
//
// with T_i(y) the image of t's vertex nearest to y: a constant of the step, as
// h_t in L_6D^h. It decides, at the start, which part of each shape a part of
// the domain covers; the Chamfer terms then finish the surfaces (the trainer
// fades its weight to 0, FitOptions::spectral_map_until).
template <class T>
struct MapField {
  int reference = 0;                              // t
  const NearestIndex<T>* surface = nullptr;       // t's vertices (unit frame)
  const std::vector<Block<T>>* images = nullptr;  // per shape i: T_i of each of t's vertices
};

// Builds L_single of shape `shape` (0 for a single shape) on the tape and returns
// it (1 x 1). targets: rows [x_S, alpha n_S] sampled on the shape; `samples` 2D
// points are drawn from P. surface: if given, L_6D is the dense variant (see
// losses/chamfer.h) against this index over the shape's whole pool, rows
// [x_S, alpha n_S] (or [x_S] when the normals are off).
// intrinsic: L_6D^h instead of L_6D (targets M x 9 [x_S, alpha n_S, beta h_S]).
template <class T>
Var single_shape_objective(Tape<T>& t, Atlas<T>& atlas, int shape, const Block<T>& targets,
                           Index samples, Rng& rng, const ObjectiveOptions& o, LossTerms* terms,
                           const NearestIndex<T>* surface = nullptr,
                           const IntrinsicField<T>* intrinsic = nullptr,
                           const MapField<T>* map = nullptr);

// L_full, Eq. (12): sum over the shapes of L_single. L_rep depends on mu alone,
// so it is computed once and counted N times (as the sum does); a collection
// adds l_code * mean |f|^2 over its codes (the auto-decoder's prior). terms
// receives the per-shape terms averaged over the shapes.
// batch: the shapes targets[b] belong to, when a step uses a subset of B of the
// N shapes (empty: all, in order). The subset's sum is scaled by N / B, so that
// over a uniformly drawn subset its expectation is the full sum of Eq. (12).
// surfaces: empty, or one index per shape of the atlas (dense L_6D).
template <class T>
Var collection_objective(Tape<T>& t, Atlas<T>& atlas, const std::vector<Block<T>>& targets,
                         Index samples, Rng& rng, const ObjectiveOptions& o, LossTerms* terms,
                         const std::vector<int>& batch = {},
                         const std::vector<NearestIndex<T>>& surfaces = {});

// One process's share of L_full (Eq. 12) in a data-parallel fit (docs/mpi.md):
// L_full is a sum, so the shares of P processes add up to it. A share holds
// some of the step's shapes (each with its own generator of the draws from P,
// so that a shape draws the same x_P whichever process holds it), the prior of
// some codes, and N l_rep L_rep in exactly one share (L_rep depends on mu alone).
template <class T>
struct ObjectiveShare {
  std::vector<int> shapes;                       // the shape of each target set
  std::vector<Rng*> rngs;                        // per target set: the draws of x_P
  std::vector<const NearestIndex<T>*> surfaces;  // empty, or per target set (dense L_6D)
  const IntrinsicField<T>* intrinsic = nullptr;  // L_6D^h (targets M x 9), or L_6D
  const MapField<T>* map = nullptr;              // L_map (weights.map > 0), or none
  int batch = 0;                     // B: the step's shapes over all shares (scale N / B)
  bool repulsion = true;             // this share adds N l_rep L_rep
  int code_begin = 0, code_end = 0;  // this share adds the prior of codes [begin, end)
};

// The share's part of L_full. sums receives the per-shape terms SUMMED over the
// share's shapes (not averaged: shares are added, then divided by B), the share's
// L_rep (0 without it) and its total.
template <class T>
Var objective_share(Tape<T>& t, Atlas<T>& atlas, const std::vector<Block<T>>& targets,
                    Index samples, const ObjectiveOptions& o, const ObjectiveShare<T>& share,
                    LossTerms* sums);

}  // namespace jsa
