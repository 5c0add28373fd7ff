// Tutte's embedding (Tutte 1963, "How to draw a graph"; Floater 1997 for
// triangulated disks): the boundary loop on a circle, spaced by 3D edge length,
// and every inner vertex at a convex combination of its neighbours, here with
// Floater's (2003) mean value weights. For a disk with a
// strictly convex boundary the result is bijective: no triangle flips and
// nothing overlaps. The bijective start for charts where psi is unusable.
#pragma once
#include "io/geometry/mesh.h"

namespace jsa {

// positions: the 3D vertices of the chart (Vc x 3), local: its faces (Fc x 3,
// one boundary loop: a disk). Returns Vc x 2 UVs on a circle of the chart's 3D
// area, counter-clockwise. Throws InputError if the chart has no boundary loop
// or a disconnected inner vertex; the caller checks for a disk first.
Block<double> tutte_embedding(const Block<double>& positions, const Faces& local);

}  // namespace jsa
