// Where a collection's node displacement starts (AtlasOptions::deform_nodes;
// issue 19, docs/collections.md "A registration as the start"): after the
// template start, n kernel centres c_k are spread over the template's surface
// (farthest points in 3D, their domain points kept), and, when a registration
// of the template to each shape is given (the spectral maps of
// model/tool/spectral_start.h), every shape's t_k,i is the least-squares fit of
// sum_k w_k(x) t_k,i to where that map sends the template's points. The
// correspondence is then decided by the map, which puts a folded hand where it
// belongs, and the joint training refines from there; a Chamfer term alone
// leaves the hand on the chest (docs/collections.md, sixteenth round).
#pragma once
#include <vector>

#include "model/atlas.h"

namespace jsa {

struct NodePlacementOptions {
  int samples = 20000;      // domain points drawn from P to place and fit the nodes
  double width = 2.0;       // sigma as a multiple of the centres' mean spacing in the domain
  double fine_width = 1.0;  // the same for the second field (AtlasOptions::fine_nodes)
  double ridge = 1e-4;      // Tikhonov weight, relative to the mean diagonal of G^T G
  uint64_t seed = 1;
};

struct NodePlacementReport {
  double sigma = 0, fine_sigma = 0;  // the fields' widths (fine_sigma 0: no second field)
  // per shape: RMS of the registration's displacement, and of what the nodes
  // leave of it after the fit (0 / 0 for the template and without a registration)
  std::vector<double> target_rms, residual_rms;
};

// Writes the centres, sigma and (with a registration) every shape's t_k,i into
// atlas.params. template_vertices: V_t x 3 in the template's unit frame;
// images[i]: V_t x 3, where each lands on shape i in its unit frame (empty for
// the template). Without them (nullptr) the t_k,i stay zero: nodes the
// training alone moves.
NodePlacementReport place_nodes(Atlas<float>& atlas, int template_shape,
                                const Block<float>* template_vertices,
                                const std::vector<Block<float>>* images,
                                const NodePlacementOptions& o = {});

}  // namespace jsa
