// The per-format readers behind read_shape (mesh_io.h). Each parses one format
// into a Mesh and reports syntax errors with the file and line or field; the
// shared content checks (indices, NaN, normals) happen afterwards in validate_mesh.
#pragma once
#include <string>

#include "io/geometry/mesh.h"

namespace jsa {

Mesh read_obj(const std::string& path);          // Wavefront, via tinyobjloader
Mesh read_off(const std::string& path);          // OFF / NOFF / COFF / CNOFF
Mesh read_ply(const std::string& path);          // ascii, binary little/big endian
Mesh read_point_table(const std::string& path);  // .xyz/.txt/.pts: x y z nx ny nz lines

}  // namespace jsa
