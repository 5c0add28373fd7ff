// Pixels, shapes, the bitmap font, colour maps and textures. Shapes are drawn by
// coverage: each pixel centre's distance to the shape gives its blend weight,
// which anti-aliases edges without any special cases.
#include "io/pictures/image.h"

#include <stb/stb_image.h>
#include <stb/stb_image_write.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <ostream>
#include <utility>

#include "engine/check.h"
#include "io/atomic_write.h"

namespace jsa {
namespace {

std::uint8_t to_byte(double channel) {
  return static_cast<std::uint8_t>(std::lround(std::clamp(channel, 0.0, 1.0) * 255.0));
}

Eigen::Vector2d pixel_centre(int x, int y) { return {x + 0.5, y + 0.5}; }

double distance_to_segment(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                           const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double length_squared = ab.squaredNorm();
  const double t = length_squared > 0 ? std::clamp((p - a).dot(ab) / length_squared, 0.0, 1.0) : 0;
  return (a + t * ab - p).norm();
}

}  // namespace

Image::Image(int width_, int height_, const Colour& background) : width(width_), height(height_) {
  JSA_CHECK(width >= 0 && height >= 0, "image size " << width << " x " << height);
  rgb.resize(static_cast<std::size_t>(width) * height * 3);
  fill(background);
}

void Image::set(int x, int y, const Colour& colour) {
  if (!contains(x, y)) return;
  std::uint8_t* pixel = &rgb[(static_cast<std::size_t>(y) * width + x) * 3];
  for (int k = 0; k < 3; ++k) pixel[k] = to_byte(colour[k]);
}

Colour Image::get(int x, int y) const {
  JSA_CHECK(contains(x, y),
            "pixel (" << x << ", " << y << ") outside " << width << " x " << height);
  const std::uint8_t* pixel = &rgb[(static_cast<std::size_t>(y) * width + x) * 3];
  return Colour(pixel[0], pixel[1], pixel[2]) / 255.0;
}

void Image::blend(int x, int y, const Colour& colour, double alpha) {
  if (!contains(x, y) || alpha <= 0) return;
  alpha = std::min(alpha, 1.0);
  set(x, y, alpha * colour + (1 - alpha) * get(x, y));
}

void Image::fill(const Colour& colour) {
  for (std::size_t i = 0; i < rgb.size(); i += 3)
    for (int k = 0; k < 3; ++k) rgb[i + k] = to_byte(colour[k]);
}

void Image::paste(const Image& source, int x, int y) {
  for (int sy = 0; sy < source.height; ++sy)
    for (int sx = 0; sx < source.width; ++sx)
      if (contains(x + sx, y + sy)) {
        const std::size_t from = (static_cast<std::size_t>(sy) * source.width + sx) * 3;
        const std::size_t to = (static_cast<std::size_t>(y + sy) * width + (x + sx)) * 3;
        std::copy(&source.rgb[from], &source.rgb[from] + 3, &rgb[to]);
      }
}

Image read_image(const std::string& path) {
  int width = 0, height = 0, channels = 0;
  if (!stbi_info(path.c_str(), &width, &height, &channels)) {
    const char* why = stbi_failure_reason();
    throw InputError(path + ": not a readable image (" + (why ? why : "unknown reason") + ")");
  }
  constexpr int kMaxSide = 16384;
  if (width <= 0 || height <= 0 || width > kMaxSide || height > kMaxSide)
    throw InputError(path + ": image of " + std::to_string(width) + " x " + std::to_string(height) +
                     " pixels (at most " + std::to_string(kMaxSide) + " a side)");
  unsigned char* data = stbi_load(path.c_str(), &width, &height, &channels, 3);
  if (!data) {
    const char* why = stbi_failure_reason();
    throw InputError(path + ": cannot decode the image (" + (why ? why : "unknown reason") + ")");
  }
  Image image;
  image.width = width;
  image.height = height;
  image.rgb.assign(data, data + static_cast<std::size_t>(width) * height * 3);
  stbi_image_free(data);
  return image;
}

std::string encode_png(const Image& image) {
  JSA_CHECK(image.width > 0 && image.height > 0, "cannot encode an empty image");
  std::string bytes;
  // stb calls back with chunks of the encoded file; we append them.
  auto append = [](void* out, void* data, int size) {
    static_cast<std::string*>(out)->append(static_cast<const char*>(data), std::size_t(size));
  };
  const int ok = stbi_write_png_to_func(append, &bytes, image.width, image.height, 3,
                                        image.rgb.data(), image.width * 3);
  JSA_CHECK(ok != 0, "stb could not encode a " << image.width << " x " << image.height << " PNG");
  return bytes;
}

void write_png(const std::string& path, const Image& image) {
  JSA_CHECK(image.width > 0 && image.height > 0, "cannot write an empty image to " << path);
  const std::string bytes = encode_png(image);
  write_file_atomically(
      path, [&](std::ostream& out) { out.write(bytes.data(), std::streamsize(bytes.size())); });
}

// ---- drawing ----

PixelSpan pixel_span(double low, double high, int size) {
  if (!(low <= high)) return {0, -1};  // also NaN
  const double first = std::max(std::floor(low), 0.0);
  const double last = std::min(std::ceil(high), size - 1.0);
  if (first > last) return {0, -1};
  return {static_cast<int>(first), static_cast<int>(last)};
}

void fill_rectangle(Image& image, int x0, int y0, int x1, int y1, const Colour& colour) {
  x0 = std::max(x0, 0), y0 = std::max(y0, 0);
  x1 = std::min(x1, image.width), y1 = std::min(y1, image.height);
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) image.set(x, y, colour);
}

void draw_rectangle_outline(Image& image, int x0, int y0, int x1, int y1, const Colour& colour) {
  fill_rectangle(image, x0, y0, x1, y0 + 1, colour);
  fill_rectangle(image, x0, y1 - 1, x1, y1, colour);
  fill_rectangle(image, x0, y0, x0 + 1, y1, colour);
  fill_rectangle(image, x1 - 1, y0, x1, y1, colour);
}

void draw_line(Image& image, const Eigen::Vector2d& from, const Eigen::Vector2d& to,
               const Colour& colour, double width) {
  const double reach = width / 2 + 1;
  const PixelSpan xs = pixel_span(std::min(from.x(), to.x()) - reach,
                                  std::max(from.x(), to.x()) + reach, image.width);
  const PixelSpan ys = pixel_span(std::min(from.y(), to.y()) - reach,
                                  std::max(from.y(), to.y()) + reach, image.height);
  for (int y = ys.first; y <= ys.last; ++y)
    for (int x = xs.first; x <= xs.last; ++x) {
      const double distance = distance_to_segment(pixel_centre(x, y), from, to);
      image.blend(x, y, colour, width / 2 + 0.5 - distance);
    }
}

void fill_circle(Image& image, const Eigen::Vector2d& centre, double radius, const Colour& colour) {
  draw_line(image, centre, centre, colour, 2 * radius);  // a segment of length 0 is a disc
}

void fill_triangle(Image& image, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                   const Eigen::Vector2d& c, const Colour& colour) {
  // Signed area of (p, q, r), positive when r is left of p->q; endpoints taken in
  // a fixed order so edge(p, q, r) == -edge(q, p, r) exactly and shared edges leave no cracks.
  auto edge = [](const Eigen::Vector2d& p, const Eigen::Vector2d& q, const Eigen::Vector2d& r) {
    const bool swap = std::make_pair(q.x(), q.y()) < std::make_pair(p.x(), p.y());
    const Eigen::Vector2d& s = swap ? q : p;
    const Eigen::Vector2d& t = swap ? p : q;
    const double value = (t.x() - s.x()) * (r.y() - s.y()) - (t.y() - s.y()) * (r.x() - s.x());
    return swap ? -value : value;
  };
  const double area = edge(a, b, c);
  if (area == 0 || !std::isfinite(area)) return;
  const double sign = area > 0 ? 1 : -1;
  const PixelSpan xs =
      pixel_span(std::min({a.x(), b.x(), c.x()}), std::max({a.x(), b.x(), c.x()}), image.width);
  const PixelSpan ys =
      pixel_span(std::min({a.y(), b.y(), c.y()}), std::max({a.y(), b.y(), c.y()}), image.height);
  for (int y = ys.first; y <= ys.last; ++y)
    for (int x = xs.first; x <= xs.last; ++x) {
      const Eigen::Vector2d p = pixel_centre(x, y);
      if (sign * edge(a, b, p) >= 0 && sign * edge(b, c, p) >= 0 && sign * edge(c, a, p) >= 0)
        image.set(x, y, colour);
    }
}

// ---- text ----

namespace {

constexpr int kGlyphWidth = 5, kGlyphHeight = 7, kAdvance = 6;

struct GlyphRows {
  char c;
  const char* rows[kGlyphHeight];  // '#' is ink, '.' is paper
};

// clang-format off
const GlyphRows kGlyphs[] = {
  {' ', {".....", ".....", ".....", ".....", ".....", ".....", "....."}},
  {'!', {"..#..", "..#..", "..#..", "..#..", "..#..", ".....", "..#.."}},
  {'"', {".#.#.", ".#.#.", ".....", ".....", ".....", ".....", "....."}},
  {'#', {".#.#.", ".#.#.", "#####", ".#.#.", "#####", ".#.#.", ".#.#."}},
  {'$', {"..#..", ".####", "#.#..", ".###.", "..#.#", "####.", "..#.."}},
  {'%', {"##...", "##..#", "...#.", "..#..", ".#...", "#..##", "...##"}},
  {'&', {".##..", "#..#.", "#.#..", ".#...", "#.#.#", "#..#.", ".##.#"}},
  {'\'', {"..#..", "..#..", ".#...", ".....", ".....", ".....", "....."}},
  {'(', {"...#.", "..#..", ".#...", ".#...", ".#...", "..#..", "...#."}},
  {')', {".#...", "..#..", "...#.", "...#.", "...#.", "..#..", ".#..."}},
  {'*', {".....", "..#..", "#.#.#", ".###.", "#.#.#", "..#..", "....."}},
  {'+', {".....", "..#..", "..#..", "#####", "..#..", "..#..", "....."}},
  {',', {".....", ".....", ".....", ".....", ".##..", "..#..", ".#..."}},
  {'-', {".....", ".....", ".....", "#####", ".....", ".....", "....."}},
  {'.', {".....", ".....", ".....", ".....", ".....", ".##..", ".##.."}},
  {'/', {".....", "....#", "...#.", "..#..", ".#...", "#....", "....."}},
  {'0', {".###.", "#...#", "#..##", "#.#.#", "##..#", "#...#", ".###."}},
  {'1', {"..#..", ".##..", "..#..", "..#..", "..#..", "..#..", ".###."}},
  {'2', {".###.", "#...#", "....#", "...#.", "..#..", ".#...", "#####"}},
  {'3', {"#####", "...#.", "..#..", "...#.", "....#", "#...#", ".###."}},
  {'4', {"...#.", "..##.", ".#.#.", "#..#.", "#####", "...#.", "...#."}},
  {'5', {"#####", "#....", "####.", "....#", "....#", "#...#", ".###."}},
  {'6', {"..##.", ".#...", "#....", "####.", "#...#", "#...#", ".###."}},
  {'7', {"#####", "....#", "...#.", "..#..", ".#...", ".#...", ".#..."}},
  {'8', {".###.", "#...#", "#...#", ".###.", "#...#", "#...#", ".###."}},
  {'9', {".###.", "#...#", "#...#", ".####", "....#", "...#.", ".##.."}},
  {':', {".....", ".##..", ".##..", ".....", ".##..", ".##..", "....."}},
  {';', {".....", ".##..", ".##..", ".....", ".##..", "..#..", ".#..."}},
  {'<', {"...#.", "..#..", ".#...", "#....", ".#...", "..#..", "...#."}},
  {'=', {".....", ".....", "#####", ".....", "#####", ".....", "....."}},
  {'>', {".#...", "..#..", "...#.", "....#", "...#.", "..#..", ".#..."}},
  {'?', {".###.", "#...#", "....#", "...#.", "..#..", ".....", "..#.."}},
  {'@', {".###.", "#...#", "....#", ".##.#", "#.#.#", "#.#.#", ".###."}},
  {'A', {".###.", "#...#", "#...#", "#####", "#...#", "#...#", "#...#"}},
  {'B', {"####.", "#...#", "#...#", "####.", "#...#", "#...#", "####."}},
  {'C', {".###.", "#...#", "#....", "#....", "#....", "#...#", ".###."}},
  {'D', {"###..", "#..#.", "#...#", "#...#", "#...#", "#..#.", "###.."}},
  {'E', {"#####", "#....", "#....", "####.", "#....", "#....", "#####"}},
  {'F', {"#####", "#....", "#....", "####.", "#....", "#....", "#...."}},
  {'G', {".###.", "#...#", "#....", "#.###", "#...#", "#...#", ".####"}},
  {'H', {"#...#", "#...#", "#...#", "#####", "#...#", "#...#", "#...#"}},
  {'I', {".###.", "..#..", "..#..", "..#..", "..#..", "..#..", ".###."}},
  {'J', {"..###", "...#.", "...#.", "...#.", "...#.", "#..#.", ".##.."}},
  {'K', {"#...#", "#..#.", "#.#..", "##...", "#.#..", "#..#.", "#...#"}},
  {'L', {"#....", "#....", "#....", "#....", "#....", "#....", "#####"}},
  {'M', {"#...#", "##.##", "#.#.#", "#.#.#", "#...#", "#...#", "#...#"}},
  {'N', {"#...#", "#...#", "##..#", "#.#.#", "#..##", "#...#", "#...#"}},
  {'O', {".###.", "#...#", "#...#", "#...#", "#...#", "#...#", ".###."}},
  {'P', {"####.", "#...#", "#...#", "####.", "#....", "#....", "#...."}},
  {'Q', {".###.", "#...#", "#...#", "#...#", "#.#.#", "#..#.", ".##.#"}},
  {'R', {"####.", "#...#", "#...#", "####.", "#.#..", "#..#.", "#...#"}},
  {'S', {".####", "#....", "#....", ".###.", "....#", "....#", "####."}},
  {'T', {"#####", "..#..", "..#..", "..#..", "..#..", "..#..", "..#.."}},
  {'U', {"#...#", "#...#", "#...#", "#...#", "#...#", "#...#", ".###."}},
  {'V', {"#...#", "#...#", "#...#", "#...#", "#...#", ".#.#.", "..#.."}},
  {'W', {"#...#", "#...#", "#...#", "#.#.#", "#.#.#", "#.#.#", ".#.#."}},
  {'X', {"#...#", "#...#", ".#.#.", "..#..", ".#.#.", "#...#", "#...#"}},
  {'Y', {"#...#", "#...#", ".#.#.", "..#..", "..#..", "..#..", "..#.."}},
  {'Z', {"#####", "....#", "...#.", "..#..", ".#...", "#....", "#####"}},
  {'[', {".###.", ".#...", ".#...", ".#...", ".#...", ".#...", ".###."}},
  {'\\', {".....", "#....", ".#...", "..#..", "...#.", "....#", "....."}},
  {']', {".###.", "...#.", "...#.", "...#.", "...#.", "...#.", ".###."}},
  {'^', {"..#..", ".#.#.", "#...#", ".....", ".....", ".....", "....."}},
  {'_', {".....", ".....", ".....", ".....", ".....", ".....", "#####"}},
  {'`', {".#...", "..#..", "...#.", ".....", ".....", ".....", "....."}},
  {'a', {".....", ".....", ".###.", "....#", ".####", "#...#", ".####"}},
  {'b', {"#....", "#....", "#.##.", "##..#", "#...#", "#...#", "####."}},
  {'c', {".....", ".....", ".###.", "#....", "#....", "#...#", ".###."}},
  {'d', {"....#", "....#", ".##.#", "#..##", "#...#", "#...#", ".####"}},
  {'e', {".....", ".....", ".###.", "#...#", "#####", "#....", ".###."}},
  {'f', {"..##.", ".#..#", ".#...", "###..", ".#...", ".#...", ".#..."}},
  {'g', {".####", "#...#", "#...#", "#...#", ".####", "....#", ".###."}},
  {'h', {"#....", "#....", "#.##.", "##..#", "#...#", "#...#", "#...#"}},
  {'i', {"..#..", ".....", ".##..", "..#..", "..#..", "..#..", ".###."}},
  {'j', {"...#.", ".....", "..##.", "...#.", "...#.", "#..#.", ".##.."}},
  {'k', {"#....", "#....", "#..#.", "#.#..", "##...", "#.#..", "#..#."}},
  {'l', {".##..", "..#..", "..#..", "..#..", "..#..", "..#..", ".###."}},
  {'m', {".....", ".....", "##.#.", "#.#.#", "#.#.#", "#...#", "#...#"}},
  {'n', {".....", ".....", "#.##.", "##..#", "#...#", "#...#", "#...#"}},
  {'o', {".....", ".....", ".###.", "#...#", "#...#", "#...#", ".###."}},
  {'p', {"####.", "#...#", "#...#", "#...#", "####.", "#....", "#...."}},
  {'q', {".####", "#...#", "#...#", "#...#", ".####", "....#", "....#"}},
  {'r', {".....", ".....", "#.##.", "##..#", "#....", "#....", "#...."}},
  {'s', {".....", ".....", ".###.", "#....", ".###.", "....#", "####."}},
  {'t', {".#...", ".#...", "###..", ".#...", ".#...", ".#..#", "..##."}},
  {'u', {".....", ".....", "#...#", "#...#", "#...#", "#..##", ".##.#"}},
  {'v', {".....", ".....", "#...#", "#...#", "#...#", ".#.#.", "..#.."}},
  {'w', {".....", ".....", "#...#", "#...#", "#.#.#", "#.#.#", ".#.#."}},
  {'x', {".....", ".....", "#...#", ".#.#.", "..#..", ".#.#.", "#...#"}},
  {'y', {"#...#", "#...#", "#...#", "#...#", ".####", "....#", ".###."}},
  {'z', {".....", ".....", "#####", "...#.", "..#..", ".#...", "#####"}},
  {'{', {"...#.", "..#..", "..#..", ".#...", "..#..", "..#..", "...#."}},
  {'|', {"..#..", "..#..", "..#..", "..#..", "..#..", "..#..", "..#.."}},
  {'}', {".#...", "..#..", "..#..", "...#.", "..#..", "..#..", ".#..."}},
  {'~', {".....", ".....", ".#...", "#.#.#", "...#.", ".....", "....."}},
};
// clang-format on

// Letters with a tail below the line: their rows start at the x-height (row 2),
// so they are drawn two rows lower and reach two rows below the 7-row box.
int glyph_drop(char c) { return c == 'g' || c == 'p' || c == 'q' || c == 'y' ? 2 : 0; }

const GlyphRows* find_glyph(char c) {
  for (const GlyphRows& glyph : kGlyphs)
    if (glyph.c == c) return &glyph;
  return nullptr;
}

}  // namespace

bool font_has_glyph(char c) { return find_glyph(c) != nullptr; }

int text_width(const std::string& text, int scale) {
  return text.empty() ? 0 : (static_cast<int>(text.size()) * kAdvance - 1) * scale;
}

int text_height(int scale) { return kGlyphHeight * scale; }

int draw_text(Image& image, int x, int y, const std::string& text, const Colour& colour,
              int scale) {
  for (char c : text) {
    if (const GlyphRows* glyph = find_glyph(c)) {
      for (int row = 0; row < kGlyphHeight; ++row)
        for (int column = 0; column < kGlyphWidth; ++column)
          if (glyph->rows[row][column] == '#')
            fill_rectangle(image, x + column * scale, y + (row + glyph_drop(c)) * scale,
                           x + (column + 1) * scale, y + (row + glyph_drop(c) + 1) * scale, colour);
    } else {
      draw_rectangle_outline(image, x, y, x + kGlyphWidth * scale, y + kGlyphHeight * scale,
                             colour);
    }
    x += kAdvance * scale;
  }
  return x;
}

// ---- colour maps ----

Colour viridis(double t) {
  // Nine samples along matplotlib's viridis, read off by eye and rounded.
  static const std::array<Colour, 9> kStops = {
      Colour(0.267, 0.005, 0.329), Colour(0.283, 0.141, 0.458), Colour(0.230, 0.322, 0.546),
      Colour(0.172, 0.448, 0.558), Colour(0.128, 0.567, 0.551), Colour(0.135, 0.659, 0.518),
      Colour(0.369, 0.789, 0.383), Colour(0.678, 0.864, 0.190), Colour(0.993, 0.906, 0.144)};
  if (!std::isfinite(t)) t = 0;
  const double position = std::clamp(t, 0.0, 1.0) * (kStops.size() - 1);
  const std::size_t below = std::min(static_cast<std::size_t>(position), kStops.size() - 2);
  const double fraction = position - below;
  return (1 - fraction) * kStops[below] + fraction * kStops[below + 1];
}

Colour hsv_colour(double h, double s, double v) {
  h = (h - std::floor(h)) * 6;  // sector of the colour wheel, in [0, 6)
  const int sector = std::min(static_cast<int>(h), 5);
  const double f = h - sector;
  const double p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
  switch (sector) {
    case 0:
      return {v, t, p};
    case 1:
      return {q, v, p};
    case 2:
      return {p, v, t};
    case 3:
      return {p, q, v};
    case 4:
      return {t, p, v};
    default:
      return {v, p, q};
  }
}

Colour domain_colour(double u, double v) {
  const double du = u - 0.5, dv = v - 0.5;
  const double hue = std::atan2(dv, du) / (2 * M_PI);
  const double radius = std::min(1.0, std::sqrt(du * du + dv * dv) / std::sqrt(0.5));
  return hsv_colour(hue, 0.15 + 0.85 * radius, 0.95);
}

// ---- textures ----

Image checkerboard(int size, int squares) {
  JSA_CHECK(size > 0 && squares > 0, "checkerboard " << size << " px, " << squares << " squares");
  Image image(size, size);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const int i = x * squares / size, j = (size - 1 - y) * squares / size;
      image.set(x, y, (i + j) % 2 == 0 ? colours::grey(0.92) : colours::grey(0.25));
    }
  return image;
}

Image colour_chart(int size) {
  JSA_CHECK(size > 0, "colour chart of " << size << " px");
  Image image(size, size);
  const int cell = std::max(1, size / 8);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const Colour colour = domain_colour((x + 0.5) / size, 1 - (y + 0.5) / size);
      const bool grid_line = size >= 16 && (x % cell == 0 || y % cell == 0);
      image.set(x, y, grid_line ? Colour(0.5 * colour) : colour);
    }
  return image;
}

Colour sample_texture(const Image& texture, double u, double v) {
  JSA_CHECK(texture.width > 0 && texture.height > 0, "empty texture");
  u = std::isfinite(u) ? std::clamp(u, 0.0, 1.0) : 0;  // clamp before converting to int
  v = std::isfinite(v) ? std::clamp(v, 0.0, 1.0) : 0;
  const int x = std::clamp(static_cast<int>(std::floor(u * texture.width)), 0, texture.width - 1);
  const int y =
      std::clamp(static_cast<int>(std::floor((1 - v) * texture.height)), 0, texture.height - 1);
  return texture.get(x, y);
}

}  // namespace jsa
