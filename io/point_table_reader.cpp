// Oriented point clouds as plain text (.xyz, .txt, .pts): one point per line,
// "x y z nx ny nz". Normals are required: estimating them from a bare cloud is a
// modelling choice (orientation!) that should be made before jsatlas sees the data.
#include <cmath>

#include "io/input_file.h"
#include "io/shape_readers.h"
#include "io/text_lines.h"

namespace jsa {

Mesh read_point_table(const std::string& path) {
  const std::string text = read_input_file(path);
  reject_binary_bytes(path, text);
  TextLines lines(text);
  TextLine line;
  std::vector<double> values;
  bool first = true;
  while (lines.next(line)) {
    std::int64_t declared = 0;  // some .pts files open with a lone point count
    if (first && line.tokens.size() == 1 && parse_number(line.tokens[0], declared)) {
      first = false;
      continue;
    }
    first = false;
    if (line.tokens.size() == 3)
      input_error(path, line_label(line.number),
                  "3 columns (x y z) but oriented points are required: write 6 columns "
                  "'x y z nx ny nz' (compute normals in your mesh tool)");
    if (line.tokens.size() != 6)
      input_error(path, line_label(line.number),
                  "expected 6 numbers 'x y z nx ny nz', found " +
                      std::to_string(line.tokens.size()) + " columns");
    for (std::size_t c = 0; c < 6; ++c) {
      double value = 0;
      if (!parse_number(line.tokens[c], value) || !std::isfinite(value))
        input_error(path, line_label(line.number),
                    "column " + std::to_string(c + 1) + " '" + std::string(line.tokens[c]) +
                        "' is not a finite number");
      values.push_back(value);
    }
  }
  // Without a point, the map below would be an offset from a null pointer
  // (UBSan, found by fuzz_read_xyz on a file of comments).
  if (values.empty()) input_error(path, "", "no points: expected lines 'x y z nx ny nz'");
  const Index count = Index(values.size() / 6);
  const Eigen::Map<const Block<double>> table(values.data(), count, 6);
  Mesh mesh;
  mesh.vertices = table.leftCols(3);
  mesh.normals = table.rightCols(3);
  mesh.faces.resize(0, 3);
  return mesh;
}

}  // namespace jsa
