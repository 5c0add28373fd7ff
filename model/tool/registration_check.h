// Whether a collection of meshes should start from its spectral registration
// (`--auto-register`; issue 19, docs/collections.md, twenty-ninth round).
//
// The registration (model/tool/spectral_start.h) puts a folded arm where it
// belongs, which no extrinsic term does (the teddies: 7.2 x 1e-2 against the
// default's 10), but where a family's eigenfunctions are alike (an ant's six
// legs) ZoomOut swaps parts from pair to pair and the registration does worse
// than the atlas alone. Which of the two a family is shows before any
// training, without labels, in how well the maps invert each other: a vertex
// of the template t carried to shape i and back,
//
//   e_i = mean_v | x_t(T_it(T_ti(v))) - x_t(v) |   (unit frame of t),
//
// stays near v when the eigenfunctions tell the parts apart and jumps to
// another part when they do not. The nearest-point maps in space give the
// same round trip its scale on these shapes (thin parts make even they come
// back off by a little): the registration is trusted when its mean round
// trip is at most `ratio` times theirs. Measured from the medoid template in
// `jsatlas fit`'s frames, seeds 1-3: teddies 4.6-4.8 x 1e-2 against 3.0
// (1.54-1.59x), ants 13.0-14.6 against 5.5-5.6 (2.34-2.68x); over all ordered
// pairs (bench_functional_maps): 1.19x and 2.0x.
#pragma once
#include <vector>

#include "model/tool/spectral_start.h"

namespace jsa {

struct RegistrationCheck {
  // per shape i != t: the round trip through ZoomOut's maps and through the
  // nearest points in space (0 for the template itself)
  std::vector<double> spectral_trip, spatial_trip;
  double spectral = 0, spatial = 0;  // their means over the shapes other than t
  bool trusted = false;              // spectral <= ratio * spatial
  SpectralStart start;               // the registration from t (spectral_start's)
};

// meshes in their input frames, frames the fit's unit frames, t the template.
// Throws InputError for a point cloud. The maps use o's sizes (and its prior
// for the maps from t, as spectral_start).
RegistrationCheck check_registration(const std::vector<Mesh>& meshes,
                                     const std::vector<Normalization>& frames, int t, double ratio,
                                     const SpectralStartOptions& o = {});

}  // namespace jsa
