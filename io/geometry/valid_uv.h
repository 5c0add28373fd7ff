// From psi's per-vertex UVs to a valid UV map of the same mesh: cut where psi
// tears or folds (uv_cut), start each chart from psi's UVs or a repair of them
// (uv_repair: LSCM, then Tutte as the last resort), lower its symmetric Dirichlet energy
// without inverting a triangle (uv_slim), align it back onto psi's layout by a
// similarity (uv_align), and pack the charts into the unit square (uv_pack).
// Every chart ends injective, counter-clockwise and a topological disk.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "io/geometry/uv_cut.h"
#include "io/geometry/uv_pack.h"
#include "io/geometry/uv_slim.h"

namespace jsa {

struct ValidUvOptions {
  CutOptions cut;
  SlimOptions slim;
  PackOptions pack;
  // true: charts packed into [0, 1]^2 without overlap. false: each chart stays
  // where psi put it (the shared domain's layout, for texture transfer across a
  // collection); charts are then injective but may overlap one another.
  bool pack_charts = true;
  // A chart with at least this many faces, and more than all the others
  // together, runs alone with OpenMP inside (over triangles); otherwise the
  // charts run in parallel with each other.
  int large_chart_faces = 20000;
  // A chart whose symmetric Dirichlet energy (4 for an isometry) stays above
  // this after optimisation is optimised again with its boundary free; unless
  // that map is injective and below this, the chart is cut in two and each
  // half redone from its part of that map, at most max_split_depth times:
  // more charts, less distortion.
  double split_energy = 4.5;
  int max_split_depth = 12;
  // A chart of at least this many faces, mostly usable, whose psi UVs cannot
  // be repaired into an injective start is split before Tutte is tried.
  Index split_before_tutte_faces = 2000;
};

// stage ("cut", "charts", "pack") and the fraction of it done, from the calling thread only.
using UvProgress = std::function<void(const std::string& stage, double fraction)>;

struct ValidUvStats {
  Index charts = 0;           // charts written (excluding skipped faces)
  Index from_psi = 0;         // charts started from psi's UVs as they were
  Index repaired = 0;         // charts started from psi's UVs with an LSCM repair
  Index lscm = 0;             // charts started from their own free-boundary LSCM
  Index inherited = 0;        // halves of a split chart started from their part of its map
  Index tutte = 0;            // charts started from Tutte's embedding
  Index single_faces = 0;     // faces laid out alone because their chart could not be embedded
  Index slim_reverted = 0;    // charts whose optimised map overlapped itself: the start kept
  Index mirrored_charts = 0;  // charts psi maps mirrored (a fold's far side): written unmirrored
  Index slim_iterations = 0;  // summed over charts
  double energy_start =
      0;  // area-weighted symmetric Dirichlet of the starts (per chart, at the 3D scale)
  double energy_end = 0;          // the same after optimisation
  double packing_efficiency = 0;  // UV area / unit square (packed maps only)
  double padding_texels = 0;      // padding used by the packer
  CutResult cut;                  // the cut's counts and warnings (charts emptied)
  double seconds = 0;
  std::vector<std::string> warnings;
};

struct ValidUv {
  Block<double> uv;             // U x 2
  Faces uv_faces;               // F x 3 into uv, corner for corner with the input faces
  std::vector<int> face_chart;  // F: the chart of each face, -1 for skipped faces
  ValidUvStats stats;
};

// positions: V x 3, faces: F x 3, psi_uv: V x 2 (psi's UVs per vertex, any
// frame; the unpacked output is in the same frame). Deterministic for a given
// thread count and iteration cap (the time cap is a safety net that makes it
// depend on the machine only when it is hit).
ValidUv make_valid_uv(const Block<double>& positions, const Faces& faces,
                      const Block<double>& psi_uv, const ValidUvOptions& options = {},
                      const UvProgress& progress = {});

}  // namespace jsa
