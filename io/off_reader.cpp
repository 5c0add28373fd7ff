// Object File Format: an "OFF" line (or NOFF with per-vertex normals, COFF/CNOFF
// with colours, which we skip), "V F E" counts, V vertex lines, F face lines
// "n i0 .. i(n-1) [colour]". Polygons are fan-triangulated.
#include <cmath>
#include <set>

#include "io/input_file.h"
#include "io/shape_readers.h"
#include "io/text_lines.h"

namespace jsa {
namespace {

std::int64_t count_field(const std::string& path, const TextLine& line, std::size_t k,
                         const char* name) {
  std::int64_t value = -1;
  if (k >= line.tokens.size() || !parse_number(line.tokens[k], value) || value < 0)
    input_error(path, line_label(line.number),
                std::string("expected the ") + name + " count as a non-negative integer");
  return value;
}

void next_line_or_fail(const std::string& path, TextLines& lines, TextLine& line,
                       const std::string& expecting) {
  if (!lines.next(line))
    input_error(path, line_label(lines.last_number()), "file ends early: expected " + expecting);
}

}  // namespace

Mesh read_off(const std::string& path) {
  const std::string text = read_input_file(path);
  reject_binary_bytes(path, text);
  TextLines lines(text);
  TextLine line;
  next_line_or_fail(path, lines, line, "an OFF header");
  const std::string keyword(line.tokens[0]);
  static const std::set<std::string> known = {"OFF", "NOFF", "COFF", "CNOFF", "NCOFF"};
  if (!known.count(keyword))
    input_error(path, line_label(line.number),
                "expected 'OFF' (or NOFF, COFF, CNOFF), found '" + keyword + "'");
  const bool with_normals = keyword.find('N') != std::string::npos;
  std::size_t first = 1;  // counts may follow the keyword on the same line
  if (line.tokens.size() == 1) {
    next_line_or_fail(path, lines, line, "the 'vertices faces edges' counts");
    first = 0;
  }
  const std::int64_t vertex_count = count_field(path, line, first, "vertex");
  const std::int64_t face_count = count_field(path, line, first + 1, "face");
  // Each vertex needs >= 3 numbers and each face >= 4, each at least "0 ": check the
  // declared sizes against the file before allocating anything.
  const double least_bytes = 2.0 * (3.0 * double(vertex_count) + 4.0 * double(face_count)) - 1;
  if (least_bytes > double(text.size()))
    input_error(path, line_label(line.number),
                "declares " + std::to_string(vertex_count) + " vertices and " +
                    std::to_string(face_count) + " faces, more than a " +
                    std::to_string(text.size()) + "-byte file can hold");

  Mesh mesh;
  const int columns = with_normals ? 6 : 3;
  mesh.vertices.resize(vertex_count, 3);
  mesh.normals.resize(with_normals ? vertex_count : 0, 3);
  for (std::int64_t v = 0; v < vertex_count; ++v) {
    next_line_or_fail(path, lines, line,
                      std::to_string(vertex_count) + " vertices, found " + std::to_string(v));
    if (int(line.tokens.size()) < columns)
      input_error(path, line_label(line.number),
                  "vertex line has " + std::to_string(line.tokens.size()) + " numbers, expected " +
                      std::to_string(columns));
    for (int c = 0; c < columns; ++c) {
      double value = 0;
      if (!parse_number(line.tokens[c], value) || !std::isfinite(value))
        input_error(path, line_label(line.number),
                    "'" + std::string(line.tokens[c]) + "' is not a finite number");
      (c < 3 ? mesh.vertices(v, c) : mesh.normals(v, c - 3)) = value;
    }
  }
  std::vector<int> corners;
  corners.reserve(3 * face_count);
  for (std::int64_t f = 0; f < face_count; ++f) {
    next_line_or_fail(path, lines, line,
                      std::to_string(face_count) + " faces, found " + std::to_string(f));
    std::int64_t n = 0;
    if (!parse_number(line.tokens[0], n) || n < 3 || std::int64_t(line.tokens.size()) < n + 1)
      input_error(path, line_label(line.number),
                  "face line must be 'n i0 .. i(n-1)' with n >= 3 indices");
    std::vector<int> polygon(n);
    for (std::int64_t k = 0; k < n; ++k) {
      std::int64_t index = -1;
      if (!parse_number(line.tokens[k + 1], index) || index < 0 || index >= vertex_count)
        input_error(path, line_label(line.number),
                    "vertex index '" + std::string(line.tokens[k + 1]) +
                        "' is not an integer in [0, " + std::to_string(vertex_count) + ")");
      polygon[k] = int(index);
    }
    for (std::int64_t k = 1; k + 1 < n; ++k)
      corners.insert(corners.end(), {polygon[0], polygon[k], polygon[k + 1]});
  }
  mesh.faces = Eigen::Map<const Faces>(corners.data(), Index(corners.size() / 3), 3);
  return mesh;
}

}  // namespace jsa
