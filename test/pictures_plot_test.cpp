// Tests for io/pictures/plot: a rising series draws its colour rising left to right, log
// axes reject values <= 0 with a message naming the series, labels draw ink, the
// heat map colours cells by value, and overlays land on their grid coordinates.
#include <catch2/catch.hpp>
#include <cmath>

#include "engine/check.h"
#include "io/pictures/plot.h"

namespace {

bool near(const jsa::Colour& a, const jsa::Colour& b, double tolerance = 0.02) {
  return (a - b).norm() < tolerance;
}

// Mean pixel row of the pixels of `colour` in each of the left and right thirds.
std::pair<double, double> mean_rows_left_right(const jsa::Image& image, const jsa::Colour& colour,
                                               int& count) {
  double left = 0, right = 0;
  int n_left = 0, n_right = 0;
  count = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      if (near(image.get(x, y), colour)) {
        ++count;
        if (x < image.width / 3) left += y, ++n_left;
        if (x > 2 * image.width / 3) right += y, ++n_right;
      }
  return {n_left ? left / n_left : -1, n_right ? right / n_right : -1};
}

}  // namespace

TEST_CASE("line_plot: a rising series rises, in its own colour", "[plot]") {
  jsa::Series rising{"", {}, {}};
  for (int i = 0; i <= 50; ++i) rising.x.push_back(i), rising.y.push_back(i * i);
  jsa::PlotOptions options;
  options.legend = false;
  const jsa::Image image = jsa::line_plot({rising}, options);
  // Lines stay inside the frame: no series colour in the outer 8 pixel margin.
  int outside = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x : {0, 7, image.width - 8, image.width - 1})
      outside += near(image.get(x, y), jsa::series_colour(0));
  CHECK(outside == 0);
  int count = 0;
  const auto [left, right] = mean_rows_left_right(image, jsa::series_colour(0), count);
  CHECK(count > 300);
  REQUIRE(left > 0);
  REQUIRE(right > 0);
  CHECK(right < left - 100);  // y grows upwards on screen
}

TEST_CASE("line_plot: log axes, two series, and a legend", "[plot]") {
  jsa::Series loss{"loss", {}, {}}, other{"chamfer", {}, {}};
  for (int i = 1; i <= 100; ++i) {
    loss.x.push_back(i), loss.y.push_back(10 * std::pow(0.93, i));
    other.x.push_back(i), other.y.push_back(5e-3 * i);
  }
  jsa::PlotOptions options;
  options.log_y = true;
  options.title = "Training";
  options.x_label = "epoch";
  options.y_label = "value";
  const jsa::Image image = jsa::line_plot({loss, other}, options);
  int count = 0;
  const auto falling = mean_rows_left_right(image, jsa::series_colour(0), count);
  CHECK(falling.second > falling.first + 100);
  const auto rising = mean_rows_left_right(image, jsa::series_colour(1), count);
  CHECK(rising.second < rising.first);
  // The title is drawn in black, centred at the top.
  int title_ink = 0;
  for (int y = 8; y < 8 + jsa::text_height(2); ++y)
    for (int x = 250; x < 390; ++x) title_ink += near(image.get(x, y), jsa::colours::black());
  CHECK(title_ink > 50);
}

TEST_CASE("line_plot: log scale rejects values <= 0, naming the series", "[plot]") {
  jsa::PlotOptions options;
  options.log_y = true;
  const jsa::Series bad{"loss", {0, 1, 2}, {1, 0, 2}};
  CHECK_THROWS_AS(jsa::line_plot({bad}, options), jsa::InputError);
  CHECK_THROWS_WITH(jsa::line_plot({bad}, options),
                    Catch::Contains("'loss'") && Catch::Contains("y[1]"));
  options.log_y = false;
  options.log_x = true;  // x = 0 on a log x axis
  CHECK_THROWS_WITH(jsa::line_plot({bad}, options), Catch::Contains("x[0]"));
  options.log_x = false;
  CHECK_NOTHROW(jsa::line_plot({bad}, options));
  const jsa::Series ragged{"ragged", {0, 1, 2}, {1, 2}};
  CHECK_THROWS_WITH(jsa::line_plot({ragged}, options), Catch::Contains("'ragged'"));
  // Non-finite points are skipped, and degenerate inputs still give a picture.
  const jsa::Series gaps{"gaps", {0, 1, 2, 3}, {1, NAN, 2, INFINITY}};
  CHECK(jsa::line_plot({gaps}, options).width == 640);
  CHECK(jsa::line_plot({}, options).width == 640);
  CHECK(jsa::line_plot({{"one", {3}, {3}}}, options).width == 640);
  // A range far below the rounding of its values still terminates with a few ticks.
  CHECK(jsa::line_plot({{"flat", {0, 1}, {1e6, 1e6 + 1e-10}}}, options).width == 640);
}

TEST_CASE("heat_map colours cells by value and overlays land on grid coordinates", "[plot]") {
  jsa::Block<double> values(20, 30);
  for (int r = 0; r < 20; ++r)
    for (int c = 0; c < 30; ++c) values(r, c) = std::hypot(c - 15.0, r - 10.0);
  jsa::HeatMapOptions options;
  options.size = 300;
  options.title = "density";
  jsa::HeatMap map = jsa::heat_map(values, options);
  CHECK(map.cell == Approx(10));
  const double high = values.maxCoeff();
  for (auto [r, c] : {std::pair<int, int>{10, 15}, {0, 0}, {5, 20}}) {
    const Eigen::Vector2d p = map.to_pixel(c, r);
    CHECK(near(map.image.get(int(p.x()), int(p.y())), jsa::viridis(values(r, c) / high)));
  }
  // The colour bar sits right of the grid, bright at its top.
  const int bar_x = static_cast<int>(map.left) + 300 + 12 + 7;
  CHECK(near(map.image.get(bar_x, static_cast<int>(map.top) + 1), jsa::viridis(1), 0.05));

  jsa::draw_grid_dot(map, 3, 4, 3, jsa::colours::red());
  const Eigen::Vector2d dot = map.to_pixel(3, 4);
  CHECK(near(map.image.get(int(dot.x()), int(dot.y())), jsa::colours::red()));

  // The contour at radius 6 passes through (15 + 6, 10) and not through the centre.
  jsa::draw_contour(map, values, 6.0, jsa::colours::white(), 2);
  const Eigen::Vector2d on = map.to_pixel(21, 10), centre = map.to_pixel(15, 10);
  CHECK(near(map.image.get(int(on.x()), int(on.y())), jsa::colours::white(), 0.3));
  CHECK_FALSE(near(map.image.get(int(centre.x()), int(centre.y())), jsa::colours::white(), 0.3));
  int white = 0;  // its length is 2 pi 6 cells of 10 px; 2 px wide, anti-aliased
  for (int y = int(map.top); y < int(map.top) + 200; ++y)
    for (int x = int(map.left); x < int(map.left) + 300; ++x)
      white += near(map.image.get(x, y), jsa::colours::white(), 0.3);
  CHECK(white > 2 * M_PI * 60 * 1);
  CHECK(white < 2 * M_PI * 60 * 3);

  jsa::draw_grid_polyline(map, {{0, 19}, {29, 19}}, jsa::colours::black(), 2, false);
  const Eigen::Vector2d bottom = map.to_pixel(10, 19);
  CHECK(near(map.image.get(int(bottom.x()), int(bottom.y())), jsa::colours::black(), 0.3));
}

TEST_CASE("heat_map: constant and non-finite grids", "[plot]") {
  jsa::Block<double> values = jsa::Block<double>::Constant(4, 4, 2.0);
  values(0, 0) = NAN;
  const jsa::HeatMap map = jsa::heat_map(values);
  const Eigen::Vector2d missing = map.to_pixel(0, 0), other = map.to_pixel(3, 3);
  CHECK(near(map.image.get(int(missing.x()), int(missing.y())), jsa::colours::grey(0.6)));
  CHECK(near(map.image.get(int(other.x()), int(other.y())), jsa::viridis(0.5)));
  CHECK_THROWS_AS(jsa::heat_map(jsa::Block<double>(0, 3)), jsa::InternalError);
  jsa::HeatMap copy = map;
  CHECK_THROWS_AS(jsa::draw_contour(copy, jsa::Block<double>::Zero(3, 4), 0.5, {1, 1, 1}),
                  jsa::InternalError);
  // A grid much larger than the picture still draws (cells below a pixel).
  const jsa::HeatMap tall = jsa::heat_map(jsa::Block<double>::Random(1000, 3));
  CHECK(tall.image.height > 400);
  CHECK(tall.cell == Approx(0.4));
}
