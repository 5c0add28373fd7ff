// From the learned density to a mesh (Sec. 3.2, "From probability distribution
// to 2D continuous domain"): threshold P on a grid over the domain, triangulate
// the cells inside, and map the vertices through phi.
#pragma once
#include "io/geometry/mesh.h"
#include "model/atlas.h"

namespace jsa {

// Domain coordinates -> texture coordinates in [0,1]^2: the square around the
// means +- 3 sigma. Every UV the tool writes (meshed domain, charts of input
// meshes, every shape of a collection) uses this one frame, so one texture
// image lines up on all of them.
struct TextureFrame {
  Eigen::RowVector2d lo = Eigen::RowVector2d::Zero();
  double side = 1;
  Block<double> to_texture(const Block<double>& uv) const;
};
TextureFrame texture_frame(const Atlas<float>& atlas);

struct DomainMeshOptions {
  int resolution = 256;     // grid cells along the longer side of the domain's bounding box
  double threshold = 0.05;  // keep P(x) >= threshold * (median of P at the means); measured on
                            // teddy_1: 0.3 kept 93% of the mass, 0.05 kept 99.5% and the legs
};

struct DomainMesh {
  Block<double> uv;                                              // V x 2 domain coordinates
  Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor> faces;  // F x 3, counter-clockwise in uv
  double level = 0;           // the absolute density threshold used
  double mass_fraction = 0;   // share of P's mass where P >= level (grid estimate)
  Eigen::RowVector2d lo, hi;  // the grid's bounding box (vt = (uv - lo) / (hi - lo))
};

DomainMesh mesh_domain(const Atlas<float>& atlas, const DomainMeshOptions& options);

}  // namespace jsa
