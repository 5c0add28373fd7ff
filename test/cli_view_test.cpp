// `jsatlas view` without a browser: the page stands alone (no external
// resource), carries the correspondences `jsatlas correspond` computes, the
// keypoint errors when .vts files are given, and a missing three.js is one
// clear line. The page in a real browser: test/browser_view_test.cpp.
#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "io/geometry/builtin_shapes.h"
#include "test/cli_test_support.h"

using namespace cli_test;

namespace {

const std::string kSmall =
    " -K 200 -M 200 --width 16 --depth 2 --threads 1 --pool 5000 --mesh-resolution 32 -q";

std::vector<std::uint8_t> unbase64(const std::string& s) {
  std::vector<std::uint8_t> out;
  // Only the last 14 bits are ever read, so keep no more (an int would overflow).
  int bits = 0;
  std::uint32_t value = 0;
  for (const char ch : s) {
    const char* const table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    const char* at = std::strchr(table, ch);
    if (ch == '=' || !at || !*at) continue;
    value = ((value << 6) | std::uint32_t(at - table)) & 0x3fffu;
    bits += 6;
    if (bits >= 8) out.push_back(std::uint8_t((value >> (bits - 8)) & 0xff)), bits -= 8;
  }
  return out;
}

// The page's data block (<script type="application/json" id="jsatlas-data">).
nlohmann::json page_data(const std::string& html) {
  const std::string open = "<script type=\"application/json\" id=\"jsatlas-data\">";
  const size_t a = html.find(open), b = html.find("</script>", a);
  REQUIRE(a != std::string::npos);
  REQUIRE(b != std::string::npos);
  return nlohmann::json::parse(html.substr(a + open.size(), b - a - open.size()));
}

long index_at(const nlohmann::json& packed, long k) {
  const std::vector<std::uint8_t> b = unbase64(packed["b64"].get<std::string>());
  if (packed["type"] == "u16") return long(b[size_t(2 * k)]) | long(b[size_t(2 * k + 1)]) << 8;
  return long(b[size_t(4 * k)]) | long(b[size_t(4 * k + 1)]) << 8 |
         long(b[size_t(4 * k + 2)]) << 16 | long(b[size_t(4 * k + 3)]) << 24;
}

}  // namespace

TEST_CASE("view: the page stands alone and carries the correspondences and keypoint errors") {
  const std::string dir = fresh_dir("cli_view");
  REQUIRE(run("fit builtin:sphere builtin:torus -o " + dir + " --iters 6 --code-size 8 --no-align" +
              kSmall)
              .code == 0);
  // Keypoints as SHREC gives them: <input stem>.vts, one vertex index per line.
  const long nv[2] = {long(jsa::builtin_shape("sphere").vertices.rows()),
                      long(jsa::builtin_shape("torus").vertices.rows())};
  write_text(dir + "/builtin:sphere.vts", "3\n17\n" + std::to_string(nv[0] - 1) + "\n");
  write_text(dir + "/builtin:torus.vts", "8\n0\n" + std::to_string(nv[1] - 1) + "\n");
  const Result v = run("view " + dir + " --keypoints " + dir + " --mesh-resolution 32 --threads 1");
  INFO(v.output);
  REQUIRE(v.code == 0);
  const std::string html = read_text(dir + "/view.html");
  // Nothing fetched: no external script, style, image or link.
  for (const std::string bad : {"<script src", "<link", "src=\"http", "href=\"http", "@import"})
    CHECK(html.find(bad) == std::string::npos);
  CHECK(html.find("OrbitControls") != std::string::npos);
  CHECK(html.find("WebGLRenderer") != std::string::npos);

  const nlohmann::json d = page_data(html);
  REQUIRE(d["shapes"].size() == 2);
  CHECK(d["shapes"][0]["vertices"]["n"] == nv[0]);
  CHECK(d["shapes"][0]["correspondence"][0].is_null());
  const nlohmann::json& to1 = d["shapes"][0]["correspondence"][1];
  REQUIRE(to1["n"] == nv[0]);
  for (const long vertex : {0L, 40L, nv[0] - 1}) {
    const Result c = run("correspond " + dir + " --from 0 --to 1 --vertices " +
                         std::to_string(vertex) + " --snap");
    REQUIRE(c.code == 0);
    std::istringstream last(c.output.substr(c.output.rfind('\n', c.output.size() - 2) + 1));
    double x, y, z;
    long expected = -1;
    REQUIRE(static_cast<bool>(last >> x >> y >> z >> expected));
    CHECK(index_at(to1, vertex) == expected);
  }
  // One error per keypoint per other shape, and the summary in the table.
  CHECK(d["shapes"][0]["keypoints"] == std::vector<long>{3, 17, nv[0] - 1});
  REQUIRE(d["shapes"][1]["keypoint_error"][0].size() == 3);
  for (const auto& e : d["shapes"][1]["keypoint_error"][0]) CHECK(e.get<double>() >= 0);
  bool summary = false;
  for (const auto& row : d["table"]) summary = summary || row[1] == "mean L2 x1e-2, unit frame";
  CHECK(summary);
}

TEST_CASE("view: bad input is one clear line and no page") {
  const std::string dir = fresh_dir("cli_view_bad");
  REQUIRE(run("fit builtin:torus -o " + dir + " --iters 2" + kSmall).code == 0);
  Result v = run("view " + dir + " --three-dir " + dir + "/nowhere");
  CHECK(v.code == 1);
  CHECK(count_lines(v.output) == 1);
  CHECK(v.output.find("three.min.js") != std::string::npos);
  v = run("view " + dir + " --keypoints " + dir);
  CHECK(v.code == 1);
  CHECK(count_lines(v.output) == 1);
  CHECK(v.output.find("collection") != std::string::npos);
  v = run("view " + dir + "/nothing-here");
  CHECK(v.code == 1);
  CHECK(count_lines(v.output) == 1);
  CHECK(!std::filesystem::exists(dir + "/view.html"));
}
