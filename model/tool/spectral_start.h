// L_map's data for a collection of meshes (model/objective.h, MapField; issue
// 19): for every shape i, where each vertex of the template t lands on i under
// a map between their Laplace-Beltrami eigenfunctions, refined by ZoomOut
// (io/geometry/functional_map.h) from the nearest vertices in space. The
// shapes are compared in their unit frames after the pose step, so the start
// agrees on which end is the head and which side is left; the eigenfunctions
// then decide the rest whatever the pose of an arm.
#pragma once
#include <string>
#include <vector>

#include "io/geometry/functional_map.h"
#include "io/geometry/normalization.h"

namespace jsa {

struct SpectralStartOptions {
  int functions = 40;  // eigenfunctions per shape (ZoomOut's last size)
  int k_start = 6;     // ZoomOut's first size
  int k_step = 4;
  int samples = 3000;  // ZoomOut's vertices per shape before its last size
  // ZoomOut's spatial prior on its sizes below prior_until, anchored on each
  // template vertex's own position (ZoomOutOptions::prior_weight; 0: none).
  double prior_weight = 0;
  int prior_until = 20;
};

// ZoomOut's settings for these sizes (orthogonal C, no prior: the prior is
// anchored on a template and set where one is).
ZoomOutOptions zoomout_options(const SpectralStartOptions& o);

struct SpectralStart {
  Block<double> template_vertices;    // V_t x 3, the template's unit frame
  std::vector<Block<double>> images;  // per shape: V_t x 3 in its unit frame (t's own: empty)
};

// Each mesh's Laplace-Beltrami basis of `functions` eigenfunctions, for the
// tools that map a collection by its spectra. Throws InputError naming
// `option` when an input is a point cloud (it has no Laplacian).
std::vector<LaplaceBasis> laplace_bases(const std::vector<Mesh>& meshes, int functions,
                                        const std::string& option);

// meshes in their input frames, frames the unit frames of the fit (with the
// pose step's rotations). bases: laplace_bases(meshes, o.functions, ...), when
// the caller has them already (nullptr: computed here, and a point cloud
// refused as --spectral-map's input).
SpectralStart spectral_start(const std::vector<Mesh>& meshes,
                             const std::vector<Normalization>& frames, int reference,
                             const SpectralStartOptions& o = {},
                             const std::vector<LaplaceBasis>* bases = nullptr);

}  // namespace jsa
