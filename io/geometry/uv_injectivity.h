// Is a chart's UV map injective? A disk whose triangles all keep their
// orientation (positive signed area) is injective exactly when its boundary
// curve does not cross itself, so two checks suffice: flips, and boundary
// segment intersections (found with a uniform grid over the segments).
#pragma once
#include <vector>

#include "io/geometry/mesh.h"

namespace jsa {

// Faces whose UV triangle has signed area <= min_area2 / 2 (0: any collapse or flip).
Index count_inverted(const Faces& local, const Block<double>& uv, double min_area2 = 0);

// True when two boundary edges that share no vertex intersect or touch.
bool boundary_self_intersects(const Faces& local, const Block<double>& uv);
// The same with the chart's boundary loops given (boundary_loops(local, V)):
// they do not change while a chart's UVs move, so an optimiser finds them once.
bool boundary_self_intersects(const std::vector<std::vector<int>>& loops, const Block<double>& uv);

// Both checks: every triangle positive and the boundary simple.
inline bool chart_is_injective(const Faces& local, const Block<double>& uv) {
  return count_inverted(local, uv) == 0 && !boundary_self_intersects(local, uv);
}

}  // namespace jsa
