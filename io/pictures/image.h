// An RGB picture in memory, the few things we draw on it, and PNG output.
// Everything visual in jsatlas (renders, UV layouts, plots) ends up as an Image:
// anti-aliased lines and dots, filled rectangles and triangles, a built-in 5x7
// bitmap font for labels, two colour maps (a viridis-like ramp, and
// `domain_colour` that gives each point of the 2D domain its own colour, as in the
// paper's figures), and checkerboard / colour-chart textures for meshes with UVs.
#pragma once
#include <Eigen/Dense>
#include <cstdint>
#include <string>
#include <vector>

namespace jsa {

// r, g, b in [0, 1]; values outside are clamped when written to an Image.
using Colour = Eigen::Vector3d;

namespace colours {
inline Colour white() { return {1, 1, 1}; }
inline Colour black() { return {0, 0, 0}; }
inline Colour grey(double level) { return {level, level, level}; }
inline Colour red() { return {0.85, 0.1, 0.1}; }
}  // namespace colours

struct Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;  // row-major, top row first, 3 bytes per pixel

  Image() = default;
  Image(int width, int height, const Colour& background = colours::white());

  bool contains(int x, int y) const { return x >= 0 && y >= 0 && x < width && y < height; }
  // Pixels outside the image are ignored by `set` and `blend`; `get` requires inside.
  void set(int x, int y, const Colour& colour);
  Colour get(int x, int y) const;
  // colour * alpha + old * (1 - alpha), alpha in [0, 1] (the coverage of a pixel).
  void blend(int x, int y, const Colour& colour, double alpha);
  void fill(const Colour& colour);
  // Copies `source` with its top-left corner at (x, y), clipped to this image.
  void paste(const Image& source, int x, int y);
};

// Decodes an image file (PNG, JPEG, BMP, TGA: whatever stb_image reads) to RGB.
// Throws InputError with the reason if it is missing, unreadable, not an image,
// or larger than 16384 x 16384 (checked from the header, before decoding).
Image read_image(const std::string& path);

// Encodes a PNG with stb_image_write and writes it through write_file_atomically.
// Throws InputError if the directory is missing or not writable.
void write_png(const std::string& path, const Image& image);
// The PNG file's bytes, in memory (for pages that inline their pictures).
std::string encode_png(const Image& image);

// ---- drawing (all clipped to the image; coordinates in pixels, y down) ----

// The pixel indices floor(low) .. ceil(high) along an axis of `size` pixels,
// clipped to the image; first > last when nothing is left. Safe for huge,
// infinite and NaN bounds (no out-of-range float -> int conversion).
struct PixelSpan {
  int first, last;
};
PixelSpan pixel_span(double low, double high, int size);

// Pixels with x0 <= x < x1 and y0 <= y < y1.
void fill_rectangle(Image& image, int x0, int y0, int x1, int y1, const Colour& colour);
void draw_rectangle_outline(Image& image, int x0, int y0, int x1, int y1, const Colour& colour);
// An anti-aliased segment `width` pixels wide between two points (pixel centres
// are at integer + 0.5). Coverage is 1 - distance past the half width, so ends are round.
void draw_line(Image& image, const Eigen::Vector2d& from, const Eigen::Vector2d& to,
               const Colour& colour, double width = 1.0);
// An anti-aliased filled disc.
void fill_circle(Image& image, const Eigen::Vector2d& centre, double radius, const Colour& colour);
// Every pixel whose centre lies inside the triangle (either winding).
void fill_triangle(Image& image, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                   const Eigen::Vector2d& c, const Colour& colour);

// ---- text: a 5x7 bitmap font advancing 6 pixels a glyph, all times `scale` ----

// True for the characters the font has a glyph for: ' ' to '~' (all printable ASCII).
bool font_has_glyph(char c);
// Draws `text` with its top-left corner at (x, y). Characters without a glyph
// draw as a hollow box. g, p, q and y hang 2 rows (times scale) below the 7-row
// text height. Returns the x just past the last character.
int draw_text(Image& image, int x, int y, const std::string& text, const Colour& colour,
              int scale = 1);
int text_width(const std::string& text, int scale = 1);
int text_height(int scale = 1);

// ---- colour maps ----

// Perceptual dark-blue -> green -> yellow ramp for t in [0, 1] (clamped):
// piecewise-linear through a few control points in the spirit of matplotlib's viridis.
Colour viridis(double t);
// Hue h in [0, 1) around the colour wheel, saturation and value in [0, 1].
Colour hsv_colour(double h, double s, double v);
// A distinct colour for each point (u, v) of [0, 1]^2: the hue turns with the
// angle around the centre and the saturation grows with the distance from it,
// so neighbouring points get similar colours and distant points do not.
Colour domain_colour(double u, double v);

// ---- textures (square, `size` x `size` pixels; v = 0 is the bottom row) ----

Image checkerboard(int size, int squares);
// domain_colour at every pixel, with thin dark grid lines every 1/8.
Image colour_chart(int size);
// Nearest-pixel lookup of (u, v) in [0, 1]^2 (clamped); v = 0 is the bottom row.
Colour sample_texture(const Image& texture, double u, double v);

}  // namespace jsa
