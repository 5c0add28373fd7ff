// The chart of a user's own mesh: every vertex through psi (Sec. 3.1), vertex
// and face order kept, so the UVs can be reused with the original file.
//
// A chart is continuous, but a closed surface must be cut to lie flat: a
// triangle whose corners fall on both sides of the cut is "torn" (its UV edges
// are much longer than its 3D edges). split_torn() gives each torn triangle its
// own UV corners, linearised from one corner through the directional derivative
// of psi, so the written UVs have a seam along mesh edges instead of a triangle
// smeared across the whole domain.
#pragma once
#include <vector>

#include "io/geometry/mesh.h"
#include "io/geometry/normalization.h"
#include "model/atlas.h"

namespace jsa {

// psi([x, alpha n]) for each vertex of `mesh` (input frame, normalised with
// `normalization`); vertex normals from the file or area-weighted from faces.
// `shape`: which shape's chart psi_i in a collection (0 for a single shape).
Block<double> chart_vertices(Atlas<float>& atlas, const Mesh& mesh,
                             const Normalization& normalization, int shape = 0);
// psi_i at rows [x, alpha n] (unit frame), in batches.
Block<double> chart_points(Atlas<float>& atlas, const Block<double>& x6, int shape = 0);

struct SplitUv {
  Block<double> uv;  // U x 2 domain coordinates: the V per-vertex ones, then 3 per split face
  Faces uv_faces;    // F x 3 indices into uv
};
SplitUv split_torn(Atlas<float>& atlas, const Mesh& mesh, const Normalization& normalization,
                   const Block<double>& vertex_uv, const std::vector<int>& torn_faces,
                   int shape = 0);

}  // namespace jsa
