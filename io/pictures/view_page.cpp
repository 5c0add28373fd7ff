#include "io/pictures/view_page.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "engine/check.h"

namespace jsa {

// The template, io/pictures/view_page.html, as CMake embedded it.
extern const char* const view_page_template;

namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

void put_u16(std::vector<std::uint8_t>& out,
             std::uint32_t v) {  // little-endian, as JS typed arrays read it
  out.push_back(std::uint8_t(v & 0xff));
  out.push_back(std::uint8_t(v >> 8));
}
void put_u32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  put_u16(out, v & 0xffff);
  put_u16(out, v >> 16);
}

// N x C values -> {lo, hi, b64 of Uint16 row-major}: value = lo + q / 65535 * (hi - lo)
// per column. 16 bits over a unit-frame bounding box is 3e-5 of its side, far
// below a pixel; it halves the bytes of Float32.
json quantised(const Block<double>& m) {
  json j;
  const Index n = m.rows(), c = m.cols();
  std::vector<double> lo(size_t(c), 0.0), hi(size_t(c), 0.0);
  for (Index k = 0; k < c && n > 0; ++k) {
    lo[size_t(k)] = m.col(k).minCoeff();
    hi[size_t(k)] = m.col(k).maxCoeff();
    JSA_CHECK(std::isfinite(lo[size_t(k)]) && std::isfinite(hi[size_t(k)]),
              "non-finite values in a view array");
  }
  std::vector<std::uint8_t> bytes;
  bytes.reserve(size_t(n * c * 2));
  for (Index i = 0; i < n; ++i)
    for (Index k = 0; k < c; ++k) {
      const double range = hi[size_t(k)] - lo[size_t(k)];
      const double t = range > 0 ? (m(i, k) - lo[size_t(k)]) / range : 0;
      put_u16(bytes, std::uint32_t(std::lround(std::clamp(t, 0.0, 1.0) * 65535)));
    }
  j["lo"] = lo;
  j["hi"] = hi;
  j["n"] = n;
  j["b64"] = base64(bytes.data(), bytes.size());
  return j;
}

// Indices < `limit` -> {type: "u16" | "u32", b64}.
json indices(const std::vector<int>& v, Index limit) {
  const bool small = limit <= 65536;
  std::vector<std::uint8_t> bytes;
  bytes.reserve(v.size() * (small ? 2 : 4));
  for (const int i : v) {
    JSA_CHECK(i >= 0 && i < limit, "index " << i << " outside 0.." << limit - 1);
    small ? put_u16(bytes, std::uint32_t(i)) : put_u32(bytes, std::uint32_t(i));
  }
  return json{{"type", small ? "u16" : "u32"},
              {"n", v.size()},
              {"b64", base64(bytes.data(), bytes.size())}};
}

json face_indices(const Faces& f, Index vertex_count) {
  return indices(std::vector<int>(f.data(), f.data() + f.size()), vertex_count);
}

json float32(const std::vector<double>& v) {
  std::vector<std::uint8_t> bytes;
  bytes.reserve(v.size() * 4);
  for (const double d : v) {
    const float f = float(d);
    std::uint32_t u;
    std::memcpy(&u, &f, 4);
    put_u32(bytes, u);
  }
  return json{{"n", v.size()}, {"b64", base64(bytes.data(), bytes.size())}};
}

// first: the page's shape 0, whose meshed domain (faces, uv) the others share
// as a rule (one domain, one grid): then theirs is not written twice.
json shape_json(const ViewShape& s, size_t shape_count, const ViewShape& first) {
  const Index V = s.vertices.rows();
  JSA_CHECK(V > 0 && s.vertices.cols() == 3, "shape " << s.name << ": no vertices");
  JSA_CHECK(s.uv.rows() == 0 || s.uv.rows() == V, "shape " << s.name << ": one uv per vertex");
  JSA_CHECK(s.domain_uv.rows() == s.domain_vertices.rows(),
            "shape " << s.name << ": one domain uv per vertex");
  json j;
  j["name"] = s.name;
  j["vertices"] = quantised(s.vertices);
  j["faces"] = face_indices(s.faces, V);
  j["uv"] = s.uv.rows() > 0 ? quantised(s.uv) : json(nullptr);
  j["domain_vertices"] = quantised(s.domain_vertices);
  const bool shared = &s != &first && s.domain_faces.rows() == first.domain_faces.rows() &&
                      s.domain_uv.rows() == first.domain_uv.rows() &&
                      s.domain_faces == first.domain_faces && s.domain_uv == first.domain_uv;
  j["domain_faces"] =
      shared ? json(nullptr) : face_indices(s.domain_faces, s.domain_vertices.rows());
  j["domain_uv"] = shared ? json(nullptr) : quantised(s.domain_uv);
  json corr = json::array();
  for (size_t t = 0; t < shape_count; ++t) {
    const bool has = t < s.correspondence.size() && !s.correspondence[t].empty();
    if (has) JSA_CHECK(Index(s.correspondence[t].size()) == V, "one correspondence per vertex");
    // The target's vertex count bounds the indices; 2^31 is safe when unknown here.
    corr.push_back(has ? indices(s.correspondence[t], Index(1) << 31) : json(nullptr));
  }
  j["correspondence"] = corr;
  j["keypoints"] = s.keypoints;
  j["keypoint_error"] = s.keypoint_error;
  return j;
}

// Replaces each `marker` of the template by its text, in one pass, so that no
// inserted text (three.js, data) is searched for markers.
std::string fill(const std::string& tpl,
                 const std::vector<std::pair<std::string, std::string>>& parts) {
  std::string out;
  size_t at = 0;
  while (true) {
    size_t best = std::string::npos;
    const std::pair<std::string, std::string>* which = nullptr;
    for (const auto& p : parts) {
      const size_t f = tpl.find(p.first, at);
      if (f < best) best = f, which = &p;
    }
    if (!which) break;
    out.append(tpl, at, best - at);
    out += which->second;
    at = best + which->first.size();
  }
  out.append(tpl, at, std::string::npos);
  return out;
}

// Text placed inside <script>: "</script" would end the element early. In JS
// strings, regular expressions and JSON, "<\/" means the same as "</".
std::string script_safe(std::string s) {
  for (size_t i = 0; i + 8 <= s.size(); ++i) {
    if (s[i] != '<' || s[i + 1] != '/') continue;
    std::string word = s.substr(i + 2, 6);
    std::transform(word.begin(), word.end(), word.begin(),
                   [](unsigned char ch) { return char(std::tolower(ch)); });
    if (word == "script") s.insert(i + 1, "\\");
  }
  return s;
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

std::string base64(const std::uint8_t* data, std::size_t size) {
  static const char* const table =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((size + 2) / 3 * 4);
  for (std::size_t i = 0; i < size; i += 3) {
    const std::uint32_t a = data[i], b = i + 1 < size ? data[i + 1] : 0,
                        c = i + 2 < size ? data[i + 2] : 0;
    const std::uint32_t triple = (a << 16) | (b << 8) | c;
    out += table[(triple >> 18) & 63];
    out += table[(triple >> 12) & 63];
    out += i + 1 < size ? table[(triple >> 6) & 63] : '=';
    out += i + 2 < size ? table[triple & 63] : '=';
  }
  return out;
}

ThreeJs read_three_js(const std::string& dir) {
  const fs::path root = dir.empty() ? fs::path("/usr/share/javascript/three") : fs::path(dir);
  // Debian 12's libjs-three keeps the non-module OrbitControls (it adds
  // THREE.OrbitControls to the global THREE) under examples/js/controls/.
  const fs::path three = root / "three.min.js";
  const fs::path orbit = root / "examples/js/controls/OrbitControls.js";
  const std::string hint =
      dir.empty()
          ? " (install the Debian package libjs-three, or give --three-dir)"
          : " (--three-dir must hold three.min.js and examples/js/controls/OrbitControls.js)";
  for (const fs::path& p : {three, orbit})
    if (!fs::is_regular_file(p))
      throw InputError("view: three.js not found: no " + p.string() + hint);
  ThreeJs t;
  t.three = read_text(three);
  t.orbit_controls = read_text(orbit);
  if (t.three.find("WebGLRenderer") == std::string::npos ||
      t.orbit_controls.find("OrbitControls") == std::string::npos)
    throw InputError("view: " + root.string() + " does not hold three.js as libjs-three ships it" +
                     hint);
  return t;
}

std::string view_page_html(const ViewPage& page, const ThreeJs& three) {
  JSA_CHECK(!page.shapes.empty(), "a view page needs at least one shape");
  json d;
  d["title"] = page.title;
  d["shapes"] = json::array();
  for (const ViewShape& s : page.shapes)
    d["shapes"].push_back(shape_json(s, page.shapes.size(), page.shapes[0]));
  d["domain"] = {{"means", quantised(page.domain.means)}, {"sigma", page.domain.sigma}};
  if (page.texture.width > 0) {
    const std::string png = encode_png(page.texture);
    d["texture"] = "data:image/png;base64," +
                   base64(reinterpret_cast<const std::uint8_t*>(png.data()), png.size());
  } else {
    d["texture"] = nullptr;
  }
  // Curves: at most ~2000 rows (every k-th), enough for a plot a few hundred pixels wide.
  const ViewCurves& c = page.curves;
  const size_t rows = c.iterations.size(), stride = std::max<size_t>(1, (rows + 1999) / 2000);
  std::vector<double> it;
  for (size_t r = 0; r < rows; r += stride) it.push_back(c.iterations[r]);
  json curves = {{"names", c.names}, {"iterations", float32(it)}, {"values", json::array()}};
  for (const std::vector<double>& col : c.values) {
    JSA_CHECK(col.size() == rows, "every loss column has one value per row");
    std::vector<double> v;
    for (size_t r = 0; r < rows; r += stride) v.push_back(col[r]);
    curves["values"].push_back(float32(v));
  }
  d["curves"] = curves;
  json table = json::array();
  for (const ViewTableRow& r : page.table) table.push_back({r.group, r.key, r.value});
  d["table"] = table;

  const std::string escaped_title = [&] {
    std::string t;
    for (const char ch : page.title) {
      if (ch == '<')
        t += "&lt;";
      else if (ch == '>')
        t += "&gt;";
      else if (ch == '&')
        t += "&amp;";
      else
        t += ch;
    }
    return t;
  }();
  return fill(view_page_template, {{"@TITLE@", escaped_title},
                                   {"/*@THREE@*/", script_safe(three.three)},
                                   {"/*@ORBIT@*/", script_safe(three.orbit_controls)},
                                   {"/*@DATA@*/", script_safe(d.dump())}});
}

}  // namespace jsa
