// Wavefront OBJ through tinyobjloader (polygons triangulated by the loader). OBJ
// normals are indexed per face corner; we average the ones each vertex receives.
// A file with `v` and `vn` lines but no faces is read as an oriented point cloud.
#include <tiny_obj_loader.h>

#include <sstream>

#include "io/input_file.h"
#include "io/shape_readers.h"

namespace jsa {
namespace {

// tinyobjloader's scalar (double when built with TINYOBJLOADER_USE_DOUBLE).
using ObjRows = Eigen::Matrix<tinyobj::real_t, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

std::string first_line(const std::string& text) {
  std::string line = text.substr(0, text.find('\n'));
  while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
  return line;
}

void gather_faces(const std::string& path, const tinyobj::ObjReader& reader, Mesh& mesh) {
  const tinyobj::attrib_t& attrib = reader.GetAttrib();
  const Index vertex_count = mesh.vertices.rows();
  const bool with_normals = !attrib.normals.empty();
  Block<double> normal_sums = Block<double>::Zero(with_normals ? vertex_count : 0, 3);
  std::vector<int> corners;
  for (const tinyobj::shape_t& shape : reader.GetShapes())
    for (const tinyobj::index_t& corner : shape.mesh.indices) {
      corners.push_back(corner.vertex_index);
      const int n = corner.normal_index;
      if (!with_normals || n < 0 || corner.vertex_index < 0 || corner.vertex_index >= vertex_count)
        continue;
      // tinyobjloader does not check `vn` indices against the `vn` lines read
      // ("f 1//9" with one vn); found by fuzz_read_obj as a heap overflow here.
      if (3 * std::size_t(n) + 2 >= attrib.normals.size())
        input_error(path, "",
                    "a face refers to normal " + std::to_string(n + 1) + " but the file has " +
                        std::to_string(attrib.normals.size() / 3) + " 'vn' lines");
      normal_sums.row(corner.vertex_index) +=
          Eigen::RowVector3d(attrib.normals[3 * n], attrib.normals[3 * n + 1],
                             attrib.normals[3 * n + 2])
              .normalized();
    }
  mesh.faces = Eigen::Map<const Faces>(corners.data(), Index(corners.size() / 3), 3);
  if (with_normals && mesh.faces.rows() > 0) mesh.normals = normal_sums;
}

// tinyobjloader 2.0-rc10 converts a `vw` (skin weight) joint id to int without a
// range check: undefined behaviour for "vw 1 1e18" (UBSan in fuzz_read_obj).
// Weights do not matter for geometry, so such lines become comments before parsing.
// Lines end at '\n' or '\r', as tinyobjloader splits them.
std::string without_skin_weights(std::string text) {
  for (std::size_t start = 0; start < text.size();) {
    const std::size_t first = text.find_first_not_of(" \t", start);
    if (first != std::string::npos && text.compare(first, 2, "vw") == 0 &&
        first + 2 < text.size() && (text[first + 2] == ' ' || text[first + 2] == '\t'))
      text[first] = '#';
    const std::size_t end = text.find_first_of("\r\n", start);
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return text;
}

}  // namespace

Mesh read_obj(const std::string& path) {
  const std::string text = read_input_file(path);
  reject_binary_bytes(path, text);
  tinyobj::ObjReaderConfig config;
  config.triangulate = true;
  config.vertex_color = false;
  tinyobj::ObjReader reader;
  // Parsing from the string skips `mtllib`: materials do not matter for geometry.
  if (!reader.ParseFromString(without_skin_weights(text), "", config) || !reader.Error().empty())
    input_error(path, "", "tinyobjloader: " + first_line(reader.Error()));

  const tinyobj::attrib_t& attrib = reader.GetAttrib();
  Mesh mesh;
  mesh.vertices =
      Eigen::Map<const ObjRows>(attrib.vertices.data(), Index(attrib.vertices.size() / 3), 3)
          .cast<double>();
  mesh.normals.resize(0, 3);
  gather_faces(path, reader, mesh);
  if (mesh.faces.rows() == 0 && !attrib.normals.empty()) {
    if (attrib.normals.size() != attrib.vertices.size())
      input_error(path, "",
                  "point cloud has " + std::to_string(attrib.vertices.size() / 3) +
                      " 'v' lines but " + std::to_string(attrib.normals.size() / 3) +
                      " 'vn' lines; expected one normal per point");
    mesh.normals =
        Eigen::Map<const ObjRows>(attrib.normals.data(), Index(attrib.normals.size() / 3), 3)
            .cast<double>();
  }
  std::istringstream warnings(reader.Warning());
  for (std::string line; std::getline(warnings, line);)
    if (!line.empty()) mesh.warnings.push_back("tinyobjloader: " + line);
  return mesh;
}

}  // namespace jsa
