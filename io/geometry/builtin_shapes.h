// Closed triangle meshes generated in code, with unit vertex normals, so that
// tests, examples and benchmarks need no files: sphere (radius 1), torus
// (R = 1, r = 0.4), cube (side 1, centred; each face an n x n grid with its own
// vertices so that normals are exactly the face normal), capsule (radius 0.5,
// cylinder length 1). All are centred at the origin, triangles oriented outward.
#pragma once
#include <string>
#include <vector>

#include "io/geometry/mesh.h"

namespace jsa {

// `resolution` is the number of segments around the axis (sphere, torus,
// capsule) or 1/4 of that per cube edge; at least 8. Unknown names throw
// InputError listing the valid ones.
Mesh builtin_shape(const std::string& name, int resolution = 32);

std::vector<std::string> builtin_shape_names();

}  // namespace jsa
