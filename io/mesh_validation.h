// The checks every freshly read shape passes before anyone else sees it: finite
// coordinates, face indices in range, something to sample (faces or normals),
// not only degenerate faces, unit normals. Oddities that training survives
// (non-manifold edges, several components) become warnings, not errors.
#pragma once
#include <string>

#include "io/geometry/mesh.h"

namespace jsa {

// Validates `mesh` read from `path` in place: throws InputError naming `path` and
// the vertex or face at fault; normalises normals and recomputes zero-length ones
// from the faces; appends warnings.
void validate_mesh(const std::string& path, Mesh& mesh);

}  // namespace jsa
