// Tests for io/pictures/raster: a triangle covers its projected area, the z-buffer keeps
// the nearer of two quads whatever the draw order, colours interpolate, a cube
// fits inside each of three views, points occlude, textures show, grids and UV
// layouts put pixels where they belong.
#include <catch2/catch.hpp>
#include <cmath>

#include "engine/check.h"
#include "io/pictures/raster.h"

namespace {

int count_pixels_not(const jsa::Image& image, const jsa::Colour& background) {
  int count = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) count += (image.get(x, y) - background).norm() > 1e-6;
  return count;
}

// Flat, exact colours: no shading, no anti-aliasing.
jsa::RenderOptions flat_options(int size) {
  jsa::RenderOptions options;
  options.width = options.height = size;
  options.ambient = 1;
  options.supersampling = 1;
  return options;
}

// An axis-aligned square in the plane z = depth, as two triangles.
void add_quad(jsa::Block<double>& vertices, jsa::Faces& faces, jsa::Block<double>& colours,
              double half, double depth, const jsa::Colour& colour) {
  const int base = static_cast<int>(vertices.rows());
  vertices.conservativeResize(base + 4, 3);
  colours.conservativeResize(base + 4, 3);
  const double corners[4][2] = {{-half, -half}, {half, -half}, {half, half}, {-half, half}};
  for (int i = 0; i < 4; ++i) {
    vertices.row(base + i) << corners[i][0], corners[i][1], depth;
    colours.row(base + i) = colour.transpose();
  }
  const int f = static_cast<int>(faces.rows());
  faces.conservativeResize(f + 2, 3);
  faces.row(f) << base, base + 1, base + 2;
  faces.row(f + 1) << base, base + 2, base + 3;
}

jsa::Mesh unit_cube() {
  jsa::Mesh cube;
  cube.vertices.resize(8, 3);
  for (int i = 0; i < 8; ++i) cube.vertices.row(i) << (i & 1), (i >> 1 & 1), (i >> 2 & 1);
  cube.faces.resize(12, 3);
  cube.faces << 0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4, 2, 6, 3, 3, 6, 7, 0, 4, 2, 2,
      4, 6, 1, 3, 5, 3, 7, 5;
  return cube;
}

}  // namespace

TEST_CASE("render_mesh: a front-facing triangle covers its projected area", "[raster]") {
  const double a = 0.5, distance = 3, fov = 40;
  jsa::Block<double> vertices(3, 3);
  vertices << -a, -a, 0, a, -a, 0, -a, a, 0;
  jsa::Faces faces(1, 3);
  faces << 0, 1, 2;
  jsa::Block<double> colours(3, 3);
  colours << 1, 0, 0, 0, 1, 0, 0, 0, 1;
  const jsa::Camera camera{{0, 0, distance}, {0, 0, 0}, {0, 1, 0}, fov};
  const int size = 200;
  const jsa::Image image = jsa::render_mesh(vertices, faces, colours, camera, flat_options(size));

  const double focal = 0.5 * size / std::tan(fov * M_PI / 360);
  const double leg = 2 * a * focal / distance;  // projected leg length in pixels
  CHECK(count_pixels_not(image, jsa::colours::white()) == Approx(0.5 * leg * leg).epsilon(0.03));
  // Near each corner the colour is mostly that corner's colour; y is down on screen.
  const double c = size / 2.0, r = a * focal / distance;
  CHECK(image.get(int(c - r + 3), int(c + r - 3)).x() > 0.9);  // vertex 0 (bottom left): red
  CHECK(image.get(int(c + r - 6), int(c + r - 2)).y() > 0.8);  // vertex 1 (bottom right): green
  CHECK(image.get(int(c - r + 2), int(c - r + 6)).z() > 0.8);  // vertex 2 (top left): blue
  // Shading: with ambient 0.3 the facing triangle is darker but still lit.
  jsa::RenderOptions shaded = flat_options(size);
  shaded.ambient = 0.3;
  const jsa::Image lit = jsa::render_mesh(vertices, faces, jsa::Block<double>(), camera, shaded);
  const double level = lit.get(int(c - r / 2), int(c + r / 2)).x();
  CHECK(level < 0.8);
  CHECK(level > 0.3 * 0.8);
}

TEST_CASE("render_mesh: the z-buffer keeps the nearer quad in either draw order", "[raster]") {
  const jsa::Camera camera{{0, 0, 3}, {0, 0, 0}, {0, 1, 0}, 40};
  for (bool near_first : {true, false}) {
    jsa::Block<double> vertices(0, 3), colours(0, 3);
    jsa::Faces faces(0, 3);
    if (near_first) add_quad(vertices, faces, colours, 0.3, 0.5, {1, 0, 0});
    add_quad(vertices, faces, colours, 0.6, 0.0, {0, 0, 1});
    if (!near_first) add_quad(vertices, faces, colours, 0.3, 0.5, {1, 0, 0});
    const jsa::Image image = jsa::render_mesh(vertices, faces, colours, camera, flat_options(101));
    INFO("near quad drawn first: " << near_first);
    CHECK((image.get(50, 50) - jsa::Colour(1, 0, 0)).norm() < 1e-6);
    CHECK((image.get(50, 50 + 25) - jsa::Colour(0, 0, 1)).norm() < 1e-6);  // far quad around it
  }
}

TEST_CASE("three_views frames a cube: visible, inside the border, all different", "[raster]") {
  const jsa::Mesh cube = unit_cube();
  const auto cameras = jsa::three_views(cube.vertices);
  REQUIRE(cameras.size() == 3);
  jsa::RenderOptions options;
  options.width = options.height = 96;
  std::vector<jsa::Image> views;
  for (const jsa::Camera& camera : cameras) {
    views.push_back(
        jsa::render_mesh(cube.vertices, cube.faces, jsa::Block<double>(), camera, options));
    const jsa::Image& view = views.back();
    CHECK(count_pixels_not(view, jsa::colours::white()) > 0.15 * 96 * 96);
    int on_border = 0;
    for (int i = 0; i < 96; ++i)
      on_border += ((view.get(i, 0) - jsa::colours::white()).norm() > 1e-6) +
                   ((view.get(i, 95) - jsa::colours::white()).norm() > 1e-6) +
                   ((view.get(0, i) - jsa::colours::white()).norm() > 1e-6) +
                   ((view.get(95, i) - jsa::colours::white()).norm() > 1e-6);
    CHECK(on_border == 0);
  }
  CHECK(views[0].rgb != views[2].rgb);
  // Tight framing: seen head-on, the near face fills about 90% of the width.
  CHECK(count_pixels_not(views[0], jsa::colours::white()) > 0.7 * 96 * 96);
}

TEST_CASE("render_mesh survives vertices just in front of the near plane", "[raster]") {
  // One vertex barely in front of the eye projects tens of thousands of pixels away.
  jsa::Block<double> vertices(3, 3);
  vertices << -0.5, -0.5, 0, 0.5, -0.5, 0, 1, 1,
      3 - 0.0011;  // depth 0.0011, just past options.near
  jsa::Faces faces(1, 3);
  faces << 0, 1, 2;
  const jsa::Image image =
      jsa::render_mesh(vertices, faces, jsa::Block<double>(), {{0, 0, 3}, {0, 0, 0}, {0, 1, 0}, 40},
                       flat_options(64));
  CHECK(image.width == 64);
}

TEST_CASE("render_points: discs of the right size, nearer points in front", "[raster]") {
  jsa::Block<double> points(2, 3), colours(2, 3);
  points << 0, 0, 0, 0, 0, 1;  // the second is nearer the eye at z = 3
  colours << 0, 0, 1, 1, 0, 0;
  jsa::RenderOptions options = flat_options(64);
  options.point_radius = 4;
  const jsa::Camera camera{{0, 0, 3}, {0, 0, 0}, {0, 1, 0}, 40};
  const jsa::Image image = jsa::render_points(points, colours, camera, options);
  CHECK((image.get(32, 32) - jsa::Colour(1, 0, 0)).norm() < 1e-6);
  CHECK(count_pixels_not(image, jsa::colours::white()) == Approx(M_PI * 16).epsilon(0.25));
  // A point behind the camera is skipped, not mirrored.
  points << 0, 0, 5, 0, 0, 6;
  CHECK(count_pixels_not(jsa::render_points(points, colours, camera, options),
                         jsa::colours::white()) == 0);
}

TEST_CASE("render_textured_mesh shows the checkerboard", "[raster]") {
  jsa::Block<double> vertices(0, 3), unused(0, 3);
  jsa::Faces faces(0, 3);
  add_quad(vertices, faces, unused, 0.5, 0, {0, 0, 0});
  jsa::Block<double> uv(4, 2);
  uv << 0, 0, 1, 0, 1, 1, 0, 1;
  const jsa::Image board = jsa::checkerboard(64, 2);
  const jsa::Image image = jsa::render_textured_mesh(
      vertices, faces, uv, board, {{0, 0, 3}, {0, 0, 0}, {0, 1, 0}, 40}, flat_options(100));
  // Bottom-left quarter of the quad is the texture's bottom-left square, and so on.
  CHECK((image.get(42, 58) - board.get(0, 63)).norm() < 1e-6);
  CHECK((image.get(58, 58) - board.get(63, 63)).norm() < 1e-6);
  CHECK((image.get(42, 58) - image.get(58, 58)).norm() > 0.5);
}

TEST_CASE("compose_grid places images and captions", "[raster]") {
  const jsa::Image red(10, 20, {1, 0, 0}), blue(30, 10, {0, 0, 1});
  const jsa::Image row = jsa::side_by_side({red, blue}, 4);
  CHECK(row.width == 4 + 2 * (30 + 4));
  CHECK(row.height == 4 + 20 + 4);
  CHECK(row.get(4 + 10, 5) == jsa::Colour(1, 0, 0));  // red centred in a 30 px cell
  CHECK(row.get(4 + 34, 5) == jsa::Colour(0, 0, 1));

  jsa::GridOptions options;
  options.columns = 1;
  options.captions = {"front", "side"};
  const jsa::Image column = jsa::compose_grid({red, blue}, options);
  CHECK(column.width == 8 + 30 + 8);
  CHECK(column.height == 8 + 2 * (20 + jsa::text_height(2) + 8 + 8));
  int ink = 0;  // the caption under the first image
  for (int y = 8 + 20 + 8; y < 8 + 20 + 8 + jsa::text_height(2); ++y)
    for (int x = 0; x < column.width; ++x) ink += column.get(x, y).norm() < 0.1;
  CHECK(ink > 20);
  CHECK_THROWS_AS(jsa::compose_grid({}), jsa::InternalError);
}

TEST_CASE("draw_uv_layout fills faces with their colour and outlines highlighted ones",
          "[raster]") {
  jsa::Block<double> uv(4, 2);
  uv << 0.1, 0.1, 0.5, 0.1, 0.1, 0.5, 0.9, 0.9;
  jsa::Faces faces(2, 3);
  faces << 0, 1, 2, 1, 3, 2;
  const std::vector<Eigen::Vector3d> colours = {{0, 0.6, 0}, {0, 0, 0.6}};
  const jsa::Image layout = jsa::draw_uv_layout(uv, faces, colours, {false, true}, 100);
  CHECK((layout.get(20, 80) - colours[0]).norm() < 0.01);  // inside face 0 (v up)
  CHECK((layout.get(55, 45) - colours[1]).norm() < 0.01);  // inside face 1
  CHECK(layout.get(5, 50) == jsa::colours::white());       // outside both
  int red_near_face0 = 0;  // along the bottom edge of face 0 (v = 0.1)
  for (int x = 15; x < 45; ++x)
    red_near_face0 += layout.get(x, 90).x() > 0.5 && layout.get(x, 90).y() < 0.4;
  CHECK(red_near_face0 == 0);  // face 0 is not highlighted
  int red_pixels = 0;
  for (int y = 0; y < 100; ++y)
    for (int x = 0; x < 100; ++x) {
      const jsa::Colour c = layout.get(x, y);
      red_pixels += c.x() > 0.6 && c.y() < 0.3 && c.z() < 0.3;
    }
  CHECK(red_pixels > 100);  // three outlined edges of face 1
  CHECK_THROWS_AS(jsa::draw_uv_layout(uv, faces, {colours[0]}, {}, 100), jsa::InternalError);
}

TEST_CASE("render_mesh interpolates colours perspective-correctly", "[raster]") {
  // A quad receding in depth, black at the near edge and white at the far edge.
  // The 3D midpoint projects above the screen midpoint; its colour must be mid-grey
  // (screen-space interpolation would give a lighter grey there).
  jsa::Block<double> vertices(4, 3), colours(4, 3);
  vertices << -1, -1, 1, 1, -1, 1, 1, 1, -3, -1, 1, -3;
  colours << 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1;
  jsa::Faces faces(2, 3);
  faces << 0, 1, 2, 0, 2, 3;
  const jsa::Camera camera{{0, 0, 4}, {0, 0, 0}, {0, 1, 0}, 60};
  const jsa::Image image = jsa::render_mesh(vertices, faces, colours, camera, flat_options(201));
  // The midpoint (0, 0, -1) is on the optical axis: the centre pixel.
  CHECK(image.get(100, 100).x() == Approx(0.5).margin(0.03));
  // Screen-space weights would put mid-grey at the screen midpoint of the quad's
  // near (y = 1 / 3 * focal) and far (y = -1 / 7 * focal) edges instead.
  const double focal = 100.5 / std::tan(30 * M_PI / 180);
  const int screen_midpoint = static_cast<int>(100.5 + 0.5 * (focal / 3 - focal / 7));
  CHECK(image.get(100, screen_midpoint).x() < 0.4);
}
