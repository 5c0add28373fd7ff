// Stanford PLY, ascii and binary (little or big endian). We read the `vertex`
// element (x y z, optional nx ny nz, any scalar type) and the `face` element's
// `vertex_indices` (or `vertex_index`) list, fan-triangulating polygons; other
// elements are skipped. Declared sizes are checked against the file's size
// before anything is allocated, so a lying header cannot exhaust memory.
#include <cmath>
#include <cstring>
#include <map>
#include <sstream>

#include "io/input_file.h"
#include "io/shape_readers.h"
#include "io/text_lines.h"

namespace jsa {
namespace {

enum class PlyFormat { ascii, binary_little_endian, binary_big_endian };

struct PlyType {
  int bytes = 0;
  bool is_float = false;
  bool is_signed = false;
};

struct PlyProperty {
  std::string name;
  PlyType type;  // the value type (the item type for a list)
  bool is_list = false;
  PlyType count_type;  // lists only
};

struct PlyElement {
  std::string name;
  std::int64_t count = 0;
  std::int64_t header_line = 0;
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  PlyFormat format = PlyFormat::ascii;
  std::vector<PlyElement> elements;
  std::size_t body_offset = 0;       // first byte after "end_header\n"
  std::int64_t body_first_line = 0;  // its line number (ascii)
};

bool type_named(const std::string& name, PlyType& type) {
  static const std::map<std::string, PlyType> types = {
      {"char", {1, false, true}},    {"int8", {1, false, true}},    {"uchar", {1, false, false}},
      {"uint8", {1, false, false}},  {"short", {2, false, true}},   {"int16", {2, false, true}},
      {"ushort", {2, false, false}}, {"uint16", {2, false, false}}, {"int", {4, false, true}},
      {"int32", {4, false, true}},   {"uint", {4, false, false}},   {"uint32", {4, false, false}},
      {"float", {4, true, true}},    {"float32", {4, true, true}},  {"double", {8, true, true}},
      {"float64", {8, true, true}}};
  const auto found = types.find(name);
  if (found == types.end()) return false;
  type = found->second;
  return true;
}

PlyType parse_type(const std::string& path, const TextLine& line, std::size_t k) {
  PlyType type;
  if (k >= line.tokens.size() || !type_named(std::string(line.tokens[k]), type))
    input_error(path, line_label(line.number),
                "unknown or missing PLY property type (expected char, uchar, short, ushort, "
                "int, uint, float, double or their int8..float64 names)");
  return type;
}

void read_property_line(const std::string& path, const TextLine& line, PlyHeader& header) {
  if (header.elements.empty())
    input_error(path, line_label(line.number), "'property' before any 'element'");
  PlyProperty property;
  if (line.tokens.size() >= 2 && line.tokens[1] == "list") {
    if (line.tokens.size() != 5)
      input_error(path, line_label(line.number),
                  "expected 'property list <count type> <item type> <name>'");
    property.is_list = true;
    property.count_type = parse_type(path, line, 2);
    if (property.count_type.is_float)
      input_error(path, line_label(line.number), "a list count must have an integer type");
    property.type = parse_type(path, line, 3);
    property.name = std::string(line.tokens[4]);
  } else {
    if (line.tokens.size() != 3)
      input_error(path, line_label(line.number), "expected 'property <type> <name>'");
    property.type = parse_type(path, line, 1);
    property.name = std::string(line.tokens[2]);
  }
  header.elements.back().properties.push_back(property);
}

PlyHeader read_header(const std::string& path, const std::string& bytes) {
  if (bytes.compare(0, 4, "ply\n") != 0 && bytes.compare(0, 5, "ply\r\n") != 0)
    input_error(path, line_label(1), "not a PLY file: the first line must be 'ply'");
  PlyHeader header;
  bool has_format = false;
  std::size_t pos = 0;
  for (std::int64_t number = 1;; ++number) {
    const std::size_t end = bytes.find('\n', pos);
    if (end == std::string::npos)
      input_error(path, line_label(number), "the header has no 'end_header' line");
    const std::string text = bytes.substr(pos, end - pos);
    pos = end + 1;
    TextLines one(text, 0, number);
    TextLine line;
    if (!one.next(line) || number == 1) continue;
    const std::string_view key = line.tokens[0];
    if (key == "comment" || key == "obj_info") continue;
    if (key == "end_header") {
      header.body_offset = pos;
      header.body_first_line = number + 1;
      break;
    }
    if (key == "format") {
      static const std::map<std::string, PlyFormat> formats = {
          {"ascii", PlyFormat::ascii},
          {"binary_little_endian", PlyFormat::binary_little_endian},
          {"binary_big_endian", PlyFormat::binary_big_endian}};
      const auto found =
          line.tokens.size() == 3 ? formats.find(std::string(line.tokens[1])) : formats.end();
      if (found == formats.end())
        input_error(path, line_label(number),
                    "expected 'format ascii|binary_little_endian|binary_big_endian 1.0'");
      header.format = found->second;
      has_format = true;
    } else if (key == "element") {
      PlyElement element;
      if (line.tokens.size() != 3 || !parse_number(line.tokens[2], element.count) ||
          element.count < 0)
        input_error(path, line_label(number), "expected 'element <name> <count>'");
      element.name = std::string(line.tokens[1]);
      element.header_line = number;
      header.elements.push_back(element);
    } else if (key == "property") {
      read_property_line(path, line, header);
    } else {
      input_error(path, line_label(number), "unexpected header keyword '" + std::string(key) + "'");
    }
  }
  if (!has_format) input_error(path, "header", "no 'format' line");
  return header;
}

// The fewest body bytes the declared elements could occupy: binary rows have a
// fixed part plus one count per list; an ascii value takes at least 2 characters.
void check_declared_sizes(const std::string& path, const PlyHeader& header, std::size_t file_size) {
  const double available = double(file_size - header.body_offset);
  double least = 0;
  for (const PlyElement& element : header.elements) {
    double row = 0;
    for (const PlyProperty& property : element.properties) {
      const int bytes = property.is_list ? property.count_type.bytes : property.type.bytes;
      row += header.format == PlyFormat::ascii ? 2 : bytes;
    }
    least += row * double(element.count);
    if (least > available + 1)
      input_error(path, line_label(element.header_line),
                  "declares " + std::to_string(element.count) + " '" + element.name +
                      "' rows, but only " + std::to_string(file_size - header.body_offset) +
                      " bytes follow the header: truncated file or corrupt header");
  }
}

// A value read from the file, printed as an integer when it is one, else with
// six significant digits ("-1e+300", not a 300-digit std::to_string).
std::string shown(double value) {
  if (value == std::floor(value) && std::abs(value) < 1e15)
    return std::to_string(static_cast<long long>(value));
  std::ostringstream text;
  text << value;
  return text.str();
}

// Reads one value at a time from the body, in either encoding, with a `where`
// for errors: "line N" (ascii) or "element 'face' row 3 field 'vertex_indices'".
class PlyBody {
 public:
  PlyBody(const std::string& path, const std::string& bytes, const PlyHeader& header)
      : path_(path),
        bytes_(bytes),
        format_(header.format),
        pos_(header.body_offset),
        lines_(bytes, header.body_offset, header.body_first_line) {
    const std::uint16_t probe = 1;
    unsigned char first;
    std::memcpy(&first, &probe, 1);
    const bool host_little = first == 1;
    swap_ = (format_ == PlyFormat::binary_little_endian) != host_little;
  }

  void start_row(const PlyElement& element, std::int64_t row) {
    element_ = &element;
    row_ = row;
    if (format_ != PlyFormat::ascii) return;
    if (!lines_.next(line_))
      fail("", "file ends early: expected " + std::to_string(element.count) + " '" + element.name +
                   "' rows, found " + std::to_string(row));
    token_ = 0;
  }

  double value(const PlyType& type, const std::string& field) {
    field_ = &field;
    if (format_ == PlyFormat::ascii) return ascii_value();
    if (pos_ + type.bytes > bytes_.size())
      fail(field, "truncated: the value needs bytes past the end of the file (offset " +
                      std::to_string(pos_) + " of " + std::to_string(bytes_.size()) + ")");
    unsigned char raw[8];
    std::memcpy(raw, bytes_.data() + pos_, type.bytes);
    pos_ += type.bytes;
    if (swap_)
      for (int i = 0; i < type.bytes / 2; ++i) std::swap(raw[i], raw[type.bytes - 1 - i]);
    return decode(raw, type);
  }

  // The length that opens a list value; a negative one means a corrupt file.
  double list_length(const PlyProperty& property) {
    const double n = value(property.count_type, property.name);
    // shown(), not int64_t(n): an ascii length such as -1e300 does not fit an
    // integer, and converting it would be undefined behaviour (UBSan in fuzz_read_ply).
    if (n < 0) fail(property.name, "negative list length " + shown(n));
    return n;
  }

  [[noreturn]] void fail(const std::string& field, const std::string& what) const {
    std::string where;
    if (format_ == PlyFormat::ascii) where = line_label(line_.number) + " (";
    where += "element '" + element_->name + "' row " + std::to_string(row_);
    if (!field.empty()) where += " field '" + field + "'";
    if (format_ == PlyFormat::ascii) where += ")";
    input_error(path_, where, what);
  }

 private:
  double ascii_value() {
    if (token_ >= line_.tokens.size()) fail(*field_, "the line has too few values");
    double value = 0;
    if (!parse_number(line_.tokens[token_], value))
      fail(*field_, "'" + std::string(line_.tokens[token_]) + "' is not a number");
    ++token_;
    return value;
  }

  static double decode(const unsigned char* raw, const PlyType& type) {
    if (type.is_float) {
      if (type.bytes == 4) {
        float f;
        std::memcpy(&f, raw, 4);
        return f;
      }
      double d;
      std::memcpy(&d, raw, 8);
      return d;
    }
    std::uint64_t bits = 0;
    for (int i = type.bytes - 1; i >= 0; --i) bits = (bits << 8) | raw[i];  // host little
    if (type.is_signed && (raw[type.bytes - 1] & 0x80))
      return double(std::int64_t(bits) - (std::int64_t(1) << (8 * type.bytes)));
    return double(bits);
  }

  const std::string& path_;
  const std::string& bytes_;
  PlyFormat format_;
  bool swap_ = false;
  std::size_t pos_;
  TextLines lines_;
  TextLine line_;
  std::size_t token_ = 0;
  const PlyElement* element_ = nullptr;
  std::int64_t row_ = 0;
  const std::string* field_ = nullptr;
};

int find_property(const PlyElement& element, const std::string& name) {
  for (std::size_t i = 0; i < element.properties.size(); ++i)
    if (element.properties[i].name == name) return int(i);
  return -1;
}

void read_vertices(const std::string& path, const PlyElement& element, PlyBody& body, Mesh& mesh) {
  int slot[6];
  const char* names[6] = {"x", "y", "z", "nx", "ny", "nz"};
  for (int c = 0; c < 6; ++c) slot[c] = find_property(element, names[c]);
  for (int c = 0; c < 3; ++c)
    if (slot[c] < 0 || element.properties[slot[c]].is_list)
      input_error(path, line_label(element.header_line),
                  std::string("element 'vertex' has no scalar property '") + names[c] + "'");
  const bool with_normals = slot[3] >= 0 && slot[4] >= 0 && slot[5] >= 0;
  mesh.vertices.resize(element.count, 3);
  mesh.normals.resize(with_normals ? element.count : 0, 3);
  std::vector<double> row(element.properties.size());
  for (std::int64_t v = 0; v < element.count; ++v) {
    body.start_row(element, v);
    for (std::size_t p = 0; p < element.properties.size(); ++p) {
      const PlyProperty& property = element.properties[p];
      if (property.is_list) {
        const double n = body.list_length(property);
        for (double k = 0; k < n; ++k) body.value(property.type, property.name);
      } else {
        row[p] = body.value(property.type, property.name);
        if (!std::isfinite(row[p])) body.fail(property.name, "value is NaN or infinite");
      }
    }
    for (int c = 0; c < 3; ++c) mesh.vertices(v, c) = row[slot[c]];
    if (with_normals)
      for (int c = 0; c < 3; ++c) mesh.normals(v, c) = row[slot[3 + c]];
  }
}

void read_faces(const std::string& path, const PlyElement& element, PlyBody& body,
                std::int64_t vertex_count, std::vector<int>& corners) {
  int slot = find_property(element, "vertex_indices");
  if (slot < 0) slot = find_property(element, "vertex_index");
  if (slot < 0 || !element.properties[slot].is_list)
    input_error(path, line_label(element.header_line),
                "element 'face' has no list property 'vertex_indices' or 'vertex_index'");
  std::vector<int> polygon;
  for (std::int64_t f = 0; f < element.count; ++f) {
    body.start_row(element, f);
    for (std::size_t p = 0; p < element.properties.size(); ++p) {
      const PlyProperty& property = element.properties[p];
      if (!property.is_list) {
        body.value(property.type, property.name);
        continue;
      }
      const double n = body.list_length(property);
      if (int(p) == slot && (n < 3 || n != std::floor(n)))
        body.fail(property.name, "a face needs at least 3 vertex indices, found " + shown(n));
      polygon.clear();
      for (double k = 0; k < n; ++k) {
        const double index = body.value(property.type, property.name);
        if (int(p) != slot) continue;
        const double limit = vertex_count >= 0 ? double(vertex_count) : 2147483647.0;
        if (index < 0 || index != std::floor(index) || index >= limit)
          body.fail(property.name, "vertex index " + shown(index) + " is out of range [0, " +
                                       std::to_string(vertex_count) + ")");
        polygon.push_back(int(index));
      }
      for (std::size_t k = 1; k + 1 < polygon.size(); ++k)
        corners.insert(corners.end(), {polygon[0], polygon[k], polygon[k + 1]});
    }
  }
}

void skip_element(const PlyElement& element, PlyBody& body) {
  // Rows without properties hold no values: nothing to skip. Reading them anyway
  // would take one ascii line per row that belongs to the next element, and spin
  // through a declared count of 10^15 such rows in a binary file.
  if (element.properties.empty()) return;
  for (std::int64_t r = 0; r < element.count; ++r) {
    body.start_row(element, r);
    for (const PlyProperty& property : element.properties) {
      const double n = property.is_list ? body.list_length(property) : 1;
      for (double k = 0; k < n; ++k) body.value(property.type, property.name);
    }
  }
}

}  // namespace

Mesh read_ply(const std::string& path) {
  const std::string bytes = read_input_file(path);
  const PlyHeader header = read_header(path, bytes);
  check_declared_sizes(path, header, bytes.size());
  if (header.format == PlyFormat::ascii) reject_binary_bytes(path, bytes);

  Mesh mesh;
  mesh.vertices.resize(0, 3);
  mesh.normals.resize(0, 3);
  std::vector<int> corners;
  std::int64_t vertex_count = -1;  // unknown until the vertex element is read
  bool has_vertex = false;
  PlyBody body(path, bytes, header);
  for (const PlyElement& element : header.elements) {
    if (element.name == "vertex") {
      read_vertices(path, element, body, mesh);
      vertex_count = element.count;
      has_vertex = true;
    } else if (element.name == "face") {
      read_faces(path, element, body, vertex_count, corners);
    } else {
      skip_element(element, body);
    }
  }
  if (!has_vertex) input_error(path, "header", "no 'vertex' element");
  mesh.faces = Eigen::Map<const Faces>(corners.data(), Index(corners.size() / 3), 3);
  return mesh;
}

}  // namespace jsa
