// Per-vertex normals for a mesh whose file carried none (or carried zero-length
// ones): each vertex gets the sum of its faces' cross products (e1 x e2 = 2 * area
// * unit normal), so larger faces weigh more, then normalised.
#pragma once
#include "io/geometry/mesh.h"

namespace jsa {

// Unit face normals, F x 3; a degenerate face gets a zero row.
Block<double> face_normals(const Block<double>& vertices, const Faces& faces);

// Area-weighted unit vertex normals, V x 3; a vertex touching no face of
// non-zero area gets a zero row (callers decide what to do with those).
Block<double> area_weighted_vertex_normals(const Block<double>& vertices, const Faces& faces);

}  // namespace jsa
