// Tests for io/pictures/image: PNG bytes (signature, IHDR size, and a decode round trip
// through stb_image), pixel access, coverage-drawn shapes, the bitmap font
// (every claimed glyph draws ink, glyphs are distinct), colour maps and textures.
#include <stb/stb_image.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>

#include "engine/check.h"
#include "io/pictures/image.h"

namespace {

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

std::uint32_t big_endian_u32(const std::string& bytes, std::size_t at) {
  std::uint32_t value = 0;
  for (std::size_t i = 0; i < 4; ++i)
    value = (value << 8) | static_cast<std::uint8_t>(bytes[at + i]);
  return value;
}

int count_pixels_not(const jsa::Image& image, const jsa::Colour& background) {
  int count = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) count += (image.get(x, y) - background).norm() > 1e-6;
  return count;
}

}  // namespace

TEST_CASE("write_png writes a PNG that decodes to the same pixels", "[image]") {
  const std::string path = std::filesystem::temp_directory_path() /
                           ("jsatlas_image_test_" + std::to_string(::getpid()) + ".png");
  jsa::Image image(37, 21, jsa::colours::black());
  image.set(0, 0, {1, 0, 0});
  image.set(36, 20, {0, 0, 1});
  image.set(10, 5, {0.2, 0.4, 0.6});
  jsa::write_png(path, image);

  const std::string bytes = slurp(path);
  std::filesystem::remove(path);
  REQUIRE(bytes.size() > 33);
  CHECK(bytes.substr(0, 8) == std::string("\x89PNG\r\n\x1a\n", 8));
  CHECK(bytes.substr(12, 4) == "IHDR");
  CHECK(big_endian_u32(bytes, 16) == 37);
  CHECK(big_endian_u32(bytes, 20) == 21);
  CHECK(static_cast<int>(bytes[24]) == 8);  // bit depth
  CHECK(static_cast<int>(bytes[25]) == 2);  // colour type: RGB

  int width = 0, height = 0, channels = 0;
  unsigned char* decoded =
      stbi_load_from_memory(reinterpret_cast<const unsigned char*>(bytes.data()),
                            static_cast<int>(bytes.size()), &width, &height, &channels, 3);
  REQUIRE(decoded != nullptr);
  CHECK(width == 37);
  CHECK(height == 21);
  CHECK(std::equal(image.rgb.begin(), image.rgb.end(), decoded));
  stbi_image_free(decoded);
}

TEST_CASE("write_png reports a missing directory as bad input", "[image]") {
  CHECK_THROWS_AS(jsa::write_png("/nonexistent_jsatlas_dir/a.png", jsa::Image(2, 2)),
                  jsa::InputError);
  CHECK_THROWS_AS(jsa::write_png("/tmp/empty.png", jsa::Image()), jsa::InternalError);
}

TEST_CASE("read_image decodes what write_png wrote, and rejects what is not an image", "[image]") {
  const std::string base =
      std::filesystem::temp_directory_path() / ("jsatlas_read_image_" + std::to_string(::getpid()));
  jsa::Image image(13, 7, jsa::colours::white());
  image.set(3, 2, {0.2, 0.4, 0.6});
  image.set(12, 6, {1, 0, 0});
  jsa::write_png(base + ".png", image);
  const jsa::Image back = jsa::read_image(base + ".png");
  CHECK(back.width == 13);
  CHECK(back.height == 7);
  CHECK(back.rgb == image.rgb);
  std::ofstream(base + ".txt") << "not an image at all\n";
  CHECK_THROWS_AS(jsa::read_image(base + ".txt"), jsa::InputError);
  CHECK_THROWS_AS(jsa::read_image(base + "_missing.png"), jsa::InputError);
  std::ofstream(base + "_empty.png").flush();
  CHECK_THROWS_AS(jsa::read_image(base + "_empty.png"), jsa::InputError);
  // A PNG header claiming 20000 x 1 pixels is refused from the header, before decoding.
  std::string bytes = slurp(base + ".png");
  const unsigned char wide[8] = {0, 0, 0x4E, 0x20, 0, 0, 0, 1};
  for (int k = 0; k < 8; ++k) bytes[16 + k] = char(wide[k]);
  std::ofstream(base + "_huge.png", std::ios::binary) << bytes;
  try {
    jsa::read_image(base + "_huge.png");
    FAIL("a 20000 x 1 header was accepted");
  } catch (const jsa::InputError& e) {
    CHECK(std::string(e.what()).find("20000 x 1 pixels") != std::string::npos);
  }
  for (const char* ext : {".png", ".txt", "_empty.png", "_huge.png"})
    std::filesystem::remove(base + ext);
}

TEST_CASE("pixels: set, get, blend, clipping", "[image]") {
  jsa::Image image(4, 3, jsa::colours::white());
  image.set(1, 2, {0, 0.5, 1});
  CHECK((image.get(1, 2) - jsa::Colour(0, 128 / 255.0, 1)).norm() < 1e-9);
  image.set(-1, 0, {0, 0, 0});  // ignored, not a crash
  image.set(4, 0, {0, 0, 0});
  CHECK(count_pixels_not(image, jsa::colours::white()) == 1);
  image.blend(0, 0, jsa::colours::black(), 0.5);
  CHECK(image.get(0, 0).x() == Approx(128 / 255.0));
  CHECK_THROWS_AS(image.get(4, 0), jsa::InternalError);
}

TEST_CASE("shapes cover the expected area", "[image]") {
  const jsa::Colour white = jsa::colours::white();
  jsa::Image image(100, 100, white);
  jsa::fill_rectangle(image, 10, 20, 30, 25, jsa::colours::black());
  CHECK(count_pixels_not(image, white) == 20 * 5);

  image.fill(white);
  jsa::fill_triangle(image, {0, 0}, {100, 0}, {0, 100}, jsa::colours::black());
  CHECK(count_pixels_not(image, white) == Approx(5000).epsilon(0.02));
  image.fill(white);
  jsa::fill_triangle(image, {0, 0}, {0, 100}, {100, 0}, jsa::colours::black());  // other winding
  CHECK(count_pixels_not(image, white) == Approx(5000).epsilon(0.02));

  // Two triangles sharing a diagonal through pixel centres leave no crack.
  image.fill(white);
  jsa::fill_triangle(image, {0, 0}, {100, 0}, {100, 100}, jsa::colours::black());
  jsa::fill_triangle(image, {0, 0}, {100, 100}, {0, 100}, jsa::colours::black());
  CHECK(count_pixels_not(image, white) == 100 * 100);

  // Coverage-weighted disc: the summed darkness is its area.
  image.fill(white);
  jsa::fill_circle(image, {50, 50}, 20, jsa::colours::black());
  double ink = 0;
  for (int y = 0; y < 100; ++y)
    for (int x = 0; x < 100; ++x) ink += 1 - image.get(x, y).x();
  CHECK(ink == Approx(M_PI * 400).epsilon(0.02));

  // A horizontal 3 px line along a row: ink = length * width.
  image.fill(white);
  jsa::draw_line(image, {20, 50}, {80, 50}, jsa::colours::black(), 3);
  ink = 0;
  for (int y = 0; y < 100; ++y)
    for (int x = 0; x < 100; ++x) ink += 1 - image.get(x, y).x();
  CHECK(ink == Approx(60 * 3 + M_PI * 1.5 * 1.5).epsilon(0.05));
}

TEST_CASE("pixel_span clips huge, infinite and NaN bounds", "[image]") {
  CHECK(jsa::pixel_span(-1e300, 1e300, 10).first == 0);
  CHECK(jsa::pixel_span(-1e300, 1e300, 10).last == 9);
  CHECK(jsa::pixel_span(2.5, 3.5, 10).first == 2);
  CHECK(jsa::pixel_span(2.5, 3.5, 10).last == 4);
  const jsa::PixelSpan outside = jsa::pixel_span(20, 30, 10), nan = jsa::pixel_span(NAN, 3, 10);
  CHECK(outside.first > outside.last);
  CHECK(nan.first > nan.last);
  // Shapes with such coordinates draw what is on screen and nothing else.
  jsa::Image image(20, 20);
  jsa::fill_triangle(image, {-1e18, -1e18}, {1e18, -1e18}, {0, 1e18}, jsa::colours::black());
  CHECK(image.get(10, 10) == jsa::colours::black());
  jsa::draw_line(image, {NAN, 0}, {5, 5}, jsa::colours::red());
  jsa::fill_circle(image, {INFINITY, 3}, 2, jsa::colours::red());
  CHECK(jsa::sample_texture(jsa::checkerboard(8, 2), 1e300, -1e300) ==
        jsa::checkerboard(8, 2).get(7, 7));
}

TEST_CASE("font: every printable character has a glyph that draws ink", "[image]") {
  std::set<std::vector<std::uint8_t>> distinct;
  for (char c = ' '; c <= '~'; ++c) {
    INFO("character '" << c << "'");
    REQUIRE(jsa::font_has_glyph(c));
    jsa::Image cell(jsa::text_width(std::string(1, c)), jsa::text_height() + 2);  // + descender
    jsa::draw_text(cell, 0, 0, std::string(1, c), jsa::colours::black());
    if (c == ' ')
      CHECK(count_pixels_not(cell, jsa::colours::white()) == 0);
    else
      CHECK(count_pixels_not(cell, jsa::colours::white()) > 0);
    distinct.insert(cell.rgb);
  }
  CHECK(distinct.size() == 95);  // no two glyphs alike (catches copy-paste rows)
  CHECK_FALSE(jsa::font_has_glyph('\n'));

  jsa::Image line(200, 30);
  const int end = jsa::draw_text(line, 5, 5, "Loss 1e-3", jsa::colours::black(), 2);
  CHECK(end == 5 + 9 * 6 * 2);
  CHECK(jsa::text_width("Loss 1e-3", 2) == 9 * 6 * 2 - 2);
  jsa::Image box(10, 10);
  jsa::draw_text(box, 0, 0, "\x01", jsa::colours::black());  // no glyph: hollow box
  CHECK(count_pixels_not(box, jsa::colours::white()) > 0);
}

TEST_CASE("colour maps: viridis brightens, domain colours differ", "[image]") {
  auto luminance = [](const jsa::Colour& c) {
    return 0.2126 * c.x() + 0.7152 * c.y() + 0.0722 * c.z();
  };
  for (int i = 0; i < 20; ++i)
    CHECK(luminance(jsa::viridis((i + 1) / 20.0)) > luminance(jsa::viridis(i / 20.0)));
  CHECK(jsa::viridis(-1) == jsa::viridis(0));
  CHECK(jsa::viridis(2) == jsa::viridis(1));

  const jsa::Colour corners[4] = {jsa::domain_colour(0, 0), jsa::domain_colour(1, 0),
                                  jsa::domain_colour(0, 1), jsa::domain_colour(1, 1)};
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) CHECK((corners[i] - corners[j]).norm() > 0.3);
  CHECK((jsa::domain_colour(0.3, 0.3) - jsa::domain_colour(0.31, 0.3)).norm() < 0.05);
  CHECK((jsa::hsv_colour(0, 1, 1) - jsa::Colour(1, 0, 0)).norm() < 1e-12);
  CHECK((jsa::hsv_colour(1.0 / 3, 1, 1) - jsa::Colour(0, 1, 0)).norm() < 1e-12);
}

TEST_CASE("textures: checkerboard alternates, chart and lookup agree", "[image]") {
  const jsa::Image board = jsa::checkerboard(64, 4);
  CHECK(board.width == 64);
  CHECK(board.get(0, 63) != board.get(16, 63));                       // neighbouring squares differ
  CHECK(board.get(0, 63) == board.get(16, 47));                       // diagonal squares agree
  CHECK(jsa::sample_texture(board, 0.01, 0.01) == board.get(0, 63));  // v = 0 is the bottom

  const jsa::Image chart = jsa::colour_chart(64);
  CHECK((jsa::sample_texture(chart, 0.3, 0.7) - jsa::domain_colour(0.3, 0.7)).norm() < 0.05);
  CHECK(jsa::sample_texture(chart, 5, -5) == chart.get(63, 63));  // clamped
}
