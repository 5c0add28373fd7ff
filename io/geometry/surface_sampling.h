// Uniform samples on a shape's surface, the training targets of the paper's
// Chamfer term: a triangle is drawn with probability proportional to its area,
// then a point uniformly inside it. Oriented point clouds are resampled with
// replacement. Deterministic for a given Rng state.
#pragma once
#include "engine/rng.h"
#include "io/geometry/mesh.h"
#include "io/geometry/vertex_normals.h"

namespace jsa {

struct SurfaceSamples {
  Block<double> points;   // N x 3
  Block<double> normals;  // N x 3, unit
};

// `count` samples. Normals interpolate the vertex normals (then normalise) when
// the mesh has them, else they are the face normal. For a point cloud (no faces)
// draws `count` of its points uniformly with replacement.
SurfaceSamples sample_surface(const Mesh& mesh, Index count, Rng& rng);

}  // namespace jsa
