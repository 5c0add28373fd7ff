// A valid starting UV map for one chart, as close to psi's as possible: psi's
// UVs when they are injective on the chart; else psi's UVs kept on the usable
// faces and the rest filled by least squares conformal maps (LSCM, Levy et al.
// 2002) with those vertices fixed, the free region grown (by rings and by
// surface distance) until the result is injective; else the chart's own LSCM
// with a free boundary when it is injective; else Tutte's embedding (always
// bijective on a disk).
#pragma once
#include <vector>

#include "io/geometry/mesh.h"

namespace jsa {

enum class ChartStart { psi, repaired, lscm, tutte, inherited, failed };
const char* to_string(ChartStart s);

struct ChartStartResult {
  Block<double> uv;  // Vc x 2, counter-clockwise triangles
  ChartStart start = ChartStart::failed;
  int rings = 0;  // rings grown around the unusable faces (repaired)
};

// positions: Vc x 3 (the chart's vertices), local: Fc x 3, psi: Vc x 2 (already
// mirrored for a mirrored chart, so usable faces are counter-clockwise),
// usable: Fc flags. failed only if even Tutte's map is not injective (a
// numerically degenerate chart), or when psi and its repair fail and `tutte`
// is false (the caller would rather split the chart); the caller then splits it.
ChartStartResult start_chart_uv(const Block<double>& positions, const Faces& local,
                                const Block<double>& psi, const std::vector<char>& usable,
                                int max_rings = 3, bool tutte = true);

// Minimises the LSCM energy over the vertices with free[v] set, the others held
// at uv; returns false if the system is singular (no fixed vertex in reach).
bool lscm_fill(const Block<double>& positions, const Faces& local, const std::vector<char>& free,
               Block<double>& uv);

}  // namespace jsa
