// Extension dispatch for reading; OBJ and PLY-points writers. Coordinates are
// written with 17 significant digits so that a double survives the round trip.
#include "io/mesh_io.h"

#include <iomanip>
#include <limits>

#include "engine/check.h"
#include "io/atomic_write.h"
#include "io/input_file.h"
#include "io/mesh_validation.h"
#include "io/shape_readers.h"

namespace jsa {

Mesh read_shape(const std::string& path) {
  check_regular_file(path);
  const std::string extension = extension_of(path);
  Mesh mesh;
  if (extension == ".obj")
    mesh = read_obj(path);
  else if (extension == ".off")
    mesh = read_off(path);
  else if (extension == ".ply")
    mesh = read_ply(path);
  else if (extension == ".xyz" || extension == ".txt" || extension == ".pts")
    mesh = read_point_table(path);
  else
    input_error(path, "",
                "unknown extension '" + extension +
                    "'; expected .obj, .off, .ply, or .xyz/.txt/.pts (x y z nx ny nz)");
  validate_mesh(path, mesh);
  return mesh;
}

void write_obj(const std::string& path, const Mesh& mesh, const Block<double>* uv,
               const std::string& mtl_file, const std::string& material, const Faces* uv_faces) {
  const Index count = mesh.vertices.rows();
  JSA_CHECK(uv == nullptr || ((uv_faces || uv->rows() == count) && uv->cols() == 2),
            "uv must be V x 2, got " << uv->rows() << " x " << uv->cols());
  JSA_CHECK(uv_faces == nullptr || (uv && uv_faces->rows() == mesh.faces.rows()),
            "uv_faces must be F x 3 and come with uv");
  JSA_CHECK(!mesh.has_normals() || mesh.normals.rows() == count, "normals must be V x 3");
  write_file_atomically(path, [&](std::ostream& out) {
    out << std::setprecision(std::numeric_limits<double>::max_digits10);
    out << "# jsatlas: " << count << " vertices, " << mesh.faces.rows() << " faces\n";
    if (!mtl_file.empty()) out << "mtllib " << mtl_file << "\n";
    for (Index v = 0; v < count; ++v)
      out << "v " << mesh.vertices(v, 0) << " " << mesh.vertices(v, 1) << " " << mesh.vertices(v, 2)
          << "\n";
    if (uv)
      for (Index v = 0; v < uv->rows(); ++v)
        out << "vt " << (*uv)(v, 0) << " " << (*uv)(v, 1) << "\n";
    if (mesh.has_normals())
      for (Index v = 0; v < count; ++v)
        out << "vn " << mesh.normals(v, 0) << " " << mesh.normals(v, 1) << " " << mesh.normals(v, 2)
            << "\n";
    if (!material.empty()) out << "usemtl " << material << "\n";
    for (Index f = 0; f < mesh.faces.rows(); ++f) {
      out << "f";
      for (int k = 0; k < 3; ++k) {
        const int i = mesh.faces(f, k) + 1;  // OBJ indices are 1-based
        const int t = uv_faces ? (*uv_faces)(f, k) + 1 : i;
        out << " " << i;
        if (uv && mesh.has_normals())
          out << "/" << t << "/" << i;
        else if (uv)
          out << "/" << t;
        else if (mesh.has_normals())
          out << "//" << i;
      }
      out << "\n";
    }
  });
}

void write_mtl(const std::string& path, const std::string& material, const std::string& texture) {
  write_file_atomically(path, [&](std::ostream& out) {
    out << "# jsatlas\nnewmtl " << material << "\nKa 1 1 1\nKd 1 1 1\nKs 0 0 0\nillum 1\nmap_Kd "
        << texture << "\n";
  });
}

void write_ply_points(const std::string& path, const Block<double>& points,
                      const Block<double>& normals) {
  JSA_CHECK(points.cols() == 3 && normals.cols() == 3 && points.rows() == normals.rows(),
            "points and normals must both be N x 3");
  write_file_atomically(path, [&](std::ostream& out) {
    out << "ply\nformat ascii 1.0\ncomment written by jsatlas\n"
        << "element vertex " << points.rows() << "\n"
        << "property double x\nproperty double y\nproperty double z\n"
        << "property double nx\nproperty double ny\nproperty double nz\nend_header\n";
    out << std::setprecision(std::numeric_limits<double>::max_digits10);
    for (Index i = 0; i < points.rows(); ++i)
      out << points(i, 0) << " " << points(i, 1) << " " << points(i, 2) << " " << normals(i, 0)
          << " " << normals(i, 1) << " " << normals(i, 2) << "\n";
  });
}

}  // namespace jsa
