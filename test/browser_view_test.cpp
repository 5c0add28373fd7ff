// `jsatlas view` in a real browser: headless Chromium (Debian's `chromium`)
// loads pages written for a tiny single-shape run and a tiny 2-shape
// collection, and we check what a user would see: the WebGL canvas is not
// blank (pixel statistics of a --screenshot PNG, read back with stb_image),
// the page logged no error, and a click on a vertex of shape 0 (scripted by the
// URL hash #test-click=0:V, since headless Chromium has no mouse) marks on
// shape 1 the vertex that `jsatlas correspond --snap` computes.
// Exits 77 (ctest: skipped) when no chromium is installed.
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "io/geometry/builtin_shapes.h"
#include "io/pictures/image.h"
#include "test/cli_test_support.h"

using namespace cli_test;

namespace {

std::string chromium_path() {
  if (const char* env = std::getenv("JSATLAS_CHROMIUM")) return env;
  for (const char* p : {"/usr/bin/chromium", "/usr/bin/chromium-browser"})
    if (std::filesystem::exists(p)) return p;
  return "";
}

// Headless, no network and a fresh profile; WebGL through SwiftShader (no GPU).
Result browser(const std::string& args, const std::string& dir) {
  const std::string profile = dir + "/chromium-profile";
  std::filesystem::remove_all(profile);
  std::filesystem::create_directories(profile);
  const std::string cmd = "timeout 180 " + chromium_path() +
                          " --headless --no-sandbox --disable-gpu --disable-quic --no-first-run "
                          "--disable-background-networking"
                          " --disable-component-update --disable-sync --use-angle=swiftshader "
                          "--enable-unsafe-swiftshader"
                          " --hide-scrollbars --user-data-dir=" +
                          profile + " " + args;
  Result r;
  FILE* p = popen((cmd + " 2>/dev/null").c_str(), "r");
  if (!p) return r;
  std::array<char, 4096> buf;
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) r.output.append(buf.data(), n);
  const int status = pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return r;
}

// The page writes its state (errors, clicks, ...) as JSON into <pre id="jsatlas-state">.
nlohmann::json page_state(const std::string& page, const std::string& hash,
                          const std::string& dir) {
  const Result r =
      browser("--virtual-time-budget=10000 --dump-dom 'file://" + page + hash + "'", dir);
  INFO("chromium exit " << r.code);
  const std::string open = "<pre id=\"jsatlas-state\">";
  const size_t a = r.output.find(open), b = r.output.find("</pre>", a);
  REQUIRE(a != std::string::npos);
  REQUIRE(b != std::string::npos);
  std::string text = r.output.substr(a + open.size(), b - a - open.size());
  // Text nodes are serialised with &, <, > escaped.
  for (const auto& [entity, ch] :
       {std::pair<std::string, std::string>{"&lt;", "<"}, {"&gt;", ">"}, {"&amp;", "&"}})
    for (size_t i = 0; (i = text.find(entity, i)) != std::string::npos;)
      text.replace(i, entity.size(), ch), i += ch.size();
  REQUIRE(!text.empty());
  return nlohmann::json::parse(text);
}

struct Pixels {
  double coloured = 0;  // share of pixels that are not (near) white
  int distinct = 0;     // distinct colours, quantised to 5 bits per channel
};
// Over the left part of the window, where the shape panels are (the side column is at the right).
Pixels pixel_statistics(const jsa::Image& image) {
  Pixels s;
  std::vector<bool> seen(1 << 15, false);
  long total = 0, coloured = 0;
  for (int y = 60; y < image.height; ++y)
    for (int x = 0; x < image.width - 460; ++x) {
      const jsa::Colour c = image.get(x, y);
      ++total;
      if (c.minCoeff() < 0.93) ++coloured;
      const int key = (int(c[0] * 31) << 10) | (int(c[1] * 31) << 5) | int(c[2] * 31);
      if (!seen[size_t(key)]) seen[size_t(key)] = true, ++s.distinct;
    }
  s.coloured = total ? double(coloured) / double(total) : 0;
  return s;
}

const std::string kSmall =
    " -K 200 -M 200 --width 16 --depth 2 --threads 1 --pool 5000 --mesh-resolution 32 -q";

}  // namespace

TEST_CASE("view: a single-shape run's page draws the shape and logs no error") {
  const std::string dir = fresh_dir("view_single");
  REQUIRE(run("fit builtin:torus -o " + dir + " --iters 20" + kSmall).code == 0);
  const Result v = run("view " + dir + " --mesh-resolution 32 --threads 1");
  INFO(v.output);
  REQUIRE(v.code == 0);
  REQUIRE(v.output.find("written: " + dir + "/view.html") != std::string::npos);
  const std::string page = dir + "/view.html";

  const std::string shot = dir + "/shot.png";
  browser("--window-size=1280,800 --virtual-time-budget=10000 --screenshot=" + shot + " 'file://" +
              page + "'",
          dir);
  REQUIRE(std::filesystem::exists(shot));
  const jsa::Image image = jsa::read_image(shot);
  REQUIRE(image.width == 1280);
  const Pixels s = pixel_statistics(image);
  INFO("coloured " << s.coloured << ", distinct colours " << s.distinct);
  CHECK(s.coloured > 0.05);  // the torus fills a good part of its panel
  CHECK(s.distinct > 100);   // shaded and checkered, not a flat fill

  for (const std::string colour : {"checker", "position", "texture", "normals"}) {
    const nlohmann::json st = page_state(page, "#colour=" + colour, dir);
    INFO(colour << ": " << st.dump());
    CHECK(st["ready"] == true);
    CHECK(st["errors"].empty());
    CHECK(st["nonblank"].get<double>() > 0.05);
  }
  const nlohmann::json domain = page_state(page, "#surface=domain", dir);
  INFO(domain.dump());
  CHECK(domain["errors"].empty());
  // After 20 steps phi still maps the domain to a small patch: drawn, but small.
  CHECK(domain["nonblank"].get<double>() > 0);
}

TEST_CASE("view: a click on shape 0 marks on shape 1 the vertex jsatlas correspond gives") {
  const std::string dir = fresh_dir("view_collection");
  REQUIRE(run("fit builtin:sphere builtin:torus -o " + dir +
              " --iters 10 --code-size 8 --no-align" + kSmall)
              .code == 0);
  const Result v =
      run("view " + dir + " -o " + dir + "/page.html --mesh-resolution 32 --threads 1");
  INFO(v.output);
  REQUIRE(v.code == 0);
  const std::string page = dir + "/page.html";
  const long sphere_vertices = long(jsa::builtin_shape("sphere").vertices.rows());
  for (const long vertex : {123L, sphere_vertices - 1}) {
    const Result c = run("correspond " + dir + " --from 0 --to 1 --vertices " +
                         std::to_string(vertex) + " --snap --threads 1");
    INFO(c.output);
    REQUIRE(c.code == 0);
    // Last line: "x y z index"
    std::istringstream last(c.output.substr(c.output.rfind('\n', c.output.size() - 2) + 1));
    double x, y, z;
    long expected = -1;
    REQUIRE(static_cast<bool>(last >> x >> y >> z >> expected));

    const nlohmann::json st = page_state(page, "#test-click=0:" + std::to_string(vertex), dir);
    INFO(st.dump());
    CHECK(st["errors"].empty());
    REQUIRE(st["clicked"]["shape"] == 0);
    REQUIRE(st["clicked"]["vertex"] == vertex);
    REQUIRE(st["clicked"]["marks"].size() == 1);
    CHECK(st["clicked"]["marks"][0]["shape"] == 1);
    CHECK(st["clicked"]["marks"][0]["vertex"] == expected);
  }
}

int main(int argc, char** argv) {
  if (chromium_path().empty()) {
    std::printf(
        "SKIPPED: no chromium (Debian: apt-get install chromium) to load the page of jsatlas "
        "view\n");
    return 77;
  }
  return Catch::Session().run(argc, argv);
}
