// A joint atlas's correspondences refined by ZoomOut (issue 19; beyond the
// paper). The atlas carries a point of shape I to shape J through the shared
// domain (q = phi_J(psi_I(p)), paper Sec. 4); where the Chamfer terms matched
// parts by distance in space (a folded arm to the chest it lies on) that map is
// wrong on a whole part, but right in its global layout: which end is the
// head, which side is left. ZoomOut (io/geometry/functional_map.h) keeps
// exactly that layout at its first, coarse size and replaces the local choices
// by intrinsic ones as the size grows. So the atlas gives ZoomOut its start,
// and ZoomOut gives back a vertex-to-vertex map that respects the parts.
#pragma once
#include <vector>

#include "io/geometry/mesh.h"
#include "io/geometry/normalization.h"
#include "model/tool/correspondence.h"

namespace jsa {

// The defaults were measured on four fixed-work collections (ant and teddy,
// two seeds each; docs/collections.md, "The atlas's map refined by ZoomOut").
struct SpectralRefinementOptions {
  int functions = 60;  // eigenfunctions per shape (ZoomOut's last size)
  int k_start = 6;     // ZoomOut's first size: the size of the layout kept from the atlas
  int k_step = 4;
  int samples = 3000;  // ZoomOut's vertices per shape before its last size
  uint64_t seed = 1;
  // ZoomOut's spatial prior toward the atlas's map (ZoomOutOptions), on the
  // sizes below prior_until: it keeps an intrinsic symmetry (an ant's left and
  // right) the atlas's way, and lets the larger sizes move a part the atlas
  // put in the wrong place (a teddy's folded hand).
  double prior_weight = 0.3;
  int prior_until = 20;
  // Both directions: a point x of I has two refined images on J, T_IJ(x) and
  // the vertex y of J whose T_JI(y) is nearest x; the one nearer the atlas's
  // own image is taken. ZoomOut refines each direction on its own, and a part
  // swapped with its symmetric twin (an ant's leg) is rarely swapped in both:
  // the atlas, right about which side is which, referees.
  bool both_directions = true;
  // The collection as referee (N >= 3): the image of x is the medoid (least
  // summed distance on J to the others) of every estimate the maps give: the
  // atlas's own, T_IJ(x), the inverse of T_JI, and T_KJ(T_IK(x)) through every
  // other shape K. An error one map makes on its own is outvoted by the maps
  // that go around it. Overrides both_directions' rule; fewer than three
  // shapes are refused (InputError).
  bool consensus = false;
};

// `base` refined: for each ordered pair (I, J) met, every vertex of I is
// carried by `base` to J and snapped to J's nearest vertex; ZoomOut refines
// that vertex map (C projected onto the orthogonal matrices at every size);
// a query point goes to its nearest vertex of I and on to that vertex's image,
// a vertex of J (unit frame). A shape's basis and a pair's map are computed on
// first use. meshes in their input frames, frames their unit frames. Throws
// InputError for a point cloud.
CorrespondenceMap spectral_refinement(CorrespondenceMap base, const std::vector<Mesh>& meshes,
                                      const std::vector<Normalization>& frames,
                                      const SpectralRefinementOptions& o = {});

}  // namespace jsa
