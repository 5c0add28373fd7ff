// A joint atlas's correspondences finished by geodesic landmarks (issue 19;
// beyond the paper). The atlas's map slides along a limb from shape to shape
// (docs/collections.md, "Thirty minutes of two cores on today's code"): its
// parts match, the place along each part does not. Distances measured along
// the surface tell the place along a limb whatever its pose, if one knows
// where to measure from. So the atlas supplies the landmarks and the surface
// the rest:
//
//   l_1..l_K     farthest points of shape I (geodesic), its landmarks,
//   T(l_k)       their images on J by the atlas's map (J's nearest vertex),
//   s_I(p)_k     = d_I(p, l_k) / r_I,   s_J(q)_k = d_J(q, T(l_k)) / r_J,
//   p -> argmin_q  sum_k w_k (s_I(p)_k - s_J(q)_k)^2,   q a vertex of J,
//
// d the shortest paths along the mesh's edges, r = sqrt(A / 4 pi) (so a pose
// or a size does not change s), w_k = exp(-s_I(p)_k / tau) (tau = 0: w = 1),
// which trusts the near landmarks, whose distances a non-isometric family
// changes least. Each landmark's image is one estimate of the atlas; K of them
// vote on every point, so the atlas's local errors average out where its
// layout is right.
#pragma once
#include <vector>

#include "io/geometry/mesh.h"
#include "io/geometry/normalization.h"
#include "model/tool/correspondence.h"

namespace jsa {

struct GeodesicRefinementOptions {
  int landmarks = 256;  // K
  double tau = 0.2;     // the landmarks' weights' length (0: all weigh 1)
  // A landmark whose image, carried back to I by the atlas, lands farther than
  // this from it (unit frame of I) is left out of the pair's (0: none left out).
  double cycle_tolerance = 0;
};

// `base` refined: for each ordered pair (I, J) met, I's landmarks are carried
// by `base`; a query point goes to its nearest vertex of I and on to the vertex
// of J whose distances to the landmarks' images match (unit frame). A shape's
// distances and a pair's are computed on first use. meshes in their input
// frames, frames their unit frames. Throws InputError for a point cloud.
CorrespondenceMap geodesic_refinement(CorrespondenceMap base, const std::vector<Mesh>& meshes,
                                      const std::vector<Normalization>& frames,
                                      const GeodesicRefinementOptions& o = {});

}  // namespace jsa
