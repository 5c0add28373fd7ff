// Point-to-point maps between two surfaces through their Laplace-Beltrami
// eigenfunctions: functional maps (Ovsjanikov et al. 2012) refined by ZoomOut
// (Melzi et al. 2019). Beyond the paper (issue 19): the joint atlas's Chamfer
// terms decide which part of one shape lands on which part of another by
// distances in space, so a folded arm is matched to the chest it lies on
// (docs/collections.md, sixth to twelfth rounds). Eigenfunctions of the
// Laplacian do not change when an arm bends (they are intrinsic), so a map
// that carries the low ones of one shape onto the other's respects the parts
// of the shapes whatever their pose.
//
// ZoomOut in one line: a map T (every vertex y of the target to a vertex T(y)
// of the source) gives the k x k matrix C = Phi_t^T M_t Pi Phi_s that carries
// the source's first k eigenfunctions onto the target's (Pi the 0/1 matrix of
// T); C gives a new T, each y sent to the source vertex whose spectral
// coordinates Phi_s[x] are nearest to Phi_t[y] C; k grows a few at a time.
// Starting at a small k from a rough map (here: nearest vertices in space,
// the shapes posed in one frame by the pose step), the coarse k keeps the
// rough map's global layout (which end is the head, which side is left, which
// intrinsic symmetry the map takes) and the growing k replace its local
// choices by intrinsic ones.
#pragma once
#include <cstdint>
#include <vector>

#include "io/geometry/mesh.h"

namespace jsa {

// The k lowest eigenpairs of the cotangent Laplacian, W phi = lambda M phi,
// with M the lumped vertex areas scaled to a total of 1 (so eigenvalues and
// functions do not depend on the shape's size).
struct LaplaceBasis {
  Eigen::VectorXd eigenvalues;  // k, ascending (the first is 0: the constant)
  Eigen::MatrixXd functions;    // V x k, orthonormal in the inner product of M
  Eigen::VectorXd mass;         // V lumped vertex areas, summing to 1
};

// Throws InputError for a point cloud (no faces) or a mesh without area.
// Shift-invert subspace iteration on (W + sigma M), k + k/2 + 8 vectors,
// Rayleigh-Ritz every sweep, until the k eigenvalues move by less than 1e-9
// relative (at most 60 sweeps); the start is random (Rng(seed)), so the
// result is deterministic.
LaplaceBasis laplace_basis(const Mesh& mesh, int k, uint64_t seed = 1);

struct ZoomOutOptions {
  int k_start = 6;  // the size of the first C (the rough map's layout)
  int k_end = 60;   // at most the bases' size
  int k_step = 2;
  bool orthogonal = false;  // C projected onto the orthogonal matrices at every size
  int samples = 3000;       // vertices per shape at every size but the last (0: all)
  uint64_t seed = 1;        // of their draw
  // A spatial prior (empty: none). Each size's map step also weighs how far
  // source vertex x lies from where the start put y: the query row is
  // [Phi_t[y] C, w a_y], the database row [Phi_s[x], w p_x], with a_y the
  // start's image of target vertex y and p_x source vertex x, both in the
  // source's frame (V_t x 3 and V_s x 3). w = prior_weight times
  // sqrt(lambda_1 + ... + lambda_k) of the target: a displacement d moves the
  // first k spectral coordinates by about that times d, so prior_weight = 1
  // counts distance in space about as much as distance along the surface.
  // Why: an intrinsic symmetry (an ant's left and right legs) leaves the
  // spectral distances tied; the prior breaks the tie the start's way.
  Eigen::MatrixXd prior_on_target, prior_on_source;
  double prior_weight = 0;
  int prior_until = 1 << 30;  // the prior acts on sizes k < prior_until only
};

// ZoomOut from `map` (target vertex -> source vertex, one entry per target
// vertex); returns the refined map.
std::vector<int> zoomout(const LaplaceBasis& source, const LaplaceBasis& target,
                         std::vector<int> map, const ZoomOutOptions& o = {});

// For every row of `queries` (M x k) the index of the nearest row of `points`
// (N x k): a brute-force search by products (exact up to float rounding, for
// the spectral coordinates of ZoomOut, too many dimensions for a kd-tree).
std::vector<int> nearest_by_products(const Eigen::MatrixXd& queries, const Eigen::MatrixXd& points);

}  // namespace jsa
