// Reading shapes from disk (OBJ, OFF, PLY, xyz point tables) into a validated
// Mesh, and writing meshes and oriented point clouds back out. Reads dispatch on
// the extension; writes go through write_file_atomically.
#pragma once
#include <string>

#include "io/geometry/mesh.h"

namespace jsa {

// Reads .obj, .off, .ply, or .xyz/.txt/.pts (x y z nx ny nz per line). Throws
// InputError with "<path>:<line or field>: <what is wrong>" on bad input.
Mesh read_shape(const std::string& path);

// Wavefront OBJ: `v` lines, `vt` per vertex if `uv` (V x 2) is given, `vn` if the
// mesh has normals, then faces "f a/a/a" with only the parts present. `mtl_file`
// adds a `mtllib` line and `material` a `usemtl` line before the faces.
// With `uv_faces` (F x 3), `uv` may have any number of rows and face f takes its
// texture coordinates from uv_faces.row(f): "f v/t/v" (UVs split along seams).
void write_obj(const std::string& path, const Mesh& mesh, const Block<double>* uv = nullptr,
               const std::string& mtl_file = "", const std::string& material = "",
               const Faces* uv_faces = nullptr);

// A one-material MTL file whose diffuse map is `texture` (a path relative to the MTL).
void write_mtl(const std::string& path, const std::string& material, const std::string& texture);

// Ascii PLY oriented point cloud: N x 3 points and N x 3 normals.
void write_ply_points(const std::string& path, const Block<double>& points,
                      const Block<double>& normals);

}  // namespace jsa
