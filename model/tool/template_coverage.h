// The template of a registered collection (`--register` with `--template-shape
// -1`; issue 19, docs/collections.md, twenty-second round): the shape whose
// registration covers the others best.
//
// A registration carries the template's surface onto each shape (the spectral
// maps of model/tool/spectral_start.h). Where the template lacks surface that
// the others have (a teddy's hand fused with its chest: no chest under the
// hand, no inside of the arm), no map can put any of it there, and the
// training must later stretch a neighbour over the gap: the coverage pull that
// took the registered hand back in the twentieth round. So each candidate is
// scored by how far the others' surface samples lie from the images of its
// own samples, summed over the others; the least wins. It needs the maps of
// every candidate (N (N - 1) ZoomOuts, the Laplace bases once per shape).
#pragma once
#include <vector>

#include "model/tool/spectral_start.h"

namespace jsa {

struct CoverageChoice {
  int shape = 0;
  // per candidate: sum over the other shapes j of the mean distance from j's
  // samples to the nearest image of the candidate's samples under its map to j
  std::vector<double> sums;
  SpectralStart start;  // the winner's maps (spectral_start with reference = shape)
};

// pools: each shape's surface samples in its unit frame (P x >= 3, the first
// `samples` rows are used; the fit's pools after the pose step), frames the
// same unit frames as spectral_start's. Ties go to the lowest index.
CoverageChoice template_by_coverage(const std::vector<Mesh>& meshes,
                                    const std::vector<Normalization>& frames,
                                    const std::vector<Block<double>>& pools,
                                    const SpectralStartOptions& o = {}, Index samples = 5000);

}  // namespace jsa
