// Charts drawn straight into an Image, so runs and benchmarks can report
// pictures without Python: line plots (loss curves, log-log scaling plots) with
// ticks, title and legend, and heat maps of a grid of values (the domain density
// of Eq. (3)) with a colour bar, plus overlays in grid coordinates for the
// Gaussian means and a contour (the boundary of the learnt domain).
#pragma once
#include <limits>
#include <string>
#include <vector>

#include "engine/block.h"
#include "io/pictures/image.h"

namespace jsa {

struct Series {
  std::string name;  // shown in the legend; an empty name is left out of it
  std::vector<double> x, y;
};

struct PlotOptions {
  int width = 640, height = 420;
  std::string title, x_label, y_label;
  bool log_x = false;     // benchmark scaling plots: log-log
  bool log_y = false;     // loss curves: every y must then be > 0
  double line_width = 2;  // pixels
  bool markers = false;   // a dot on every data point
  bool legend = true;     // upper-right box naming the series
};

// The colour of the i-th series (a ten-colour cycle of distinct hues).
Colour series_colour(int index);

// Points with a non-finite x or y are skipped (the line breaks there). Throws
// InputError naming the series if x and y differ in length, or if a log axis
// meets a value <= 0.
Image line_plot(const std::vector<Series>& series, const PlotOptions& options = {});

struct HeatMapOptions {
  int size = 400;  // pixels along the longer side of the grid
  std::string title;
  // Values mapped to the two ends of the colour map; NaN takes the finite data min / max.
  double low = std::numeric_limits<double>::quiet_NaN();
  double high = std::numeric_limits<double>::quiet_NaN();
  bool colour_bar = true;  // a viridis bar with the low, middle and high values, on the right
};

// A heat map and where its grid sits, so overlays can be drawn in grid
// coordinates: (column, row), continuous, with cell centres at integers and
// row 0 at the top (as the values block is printed).
struct HeatMap {
  Image image;
  double left = 0, top = 0;  // pixel position of the grid's top-left corner
  double cell = 1;           // pixels per cell (may be below 1 for big grids)
  Index rows = 0, cols = 0;  // the grid's size
  Eigen::Vector2d to_pixel(double column, double row) const {
    return {left + (column + 0.5) * cell, top + (row + 0.5) * cell};
  }
};

// values: rows x cols; non-finite cells are drawn grey.
HeatMap heat_map(const Block<double>& values, const HeatMapOptions& options = {});

// A dot of `radius` pixels at grid coordinates (column, row), e.g. a Gaussian mean.
void draw_grid_dot(HeatMap& map, double column, double row, double radius, const Colour& colour);
// A polyline through grid coordinates (column, row); `closed` joins the last to the first.
void draw_grid_polyline(HeatMap& map, const std::vector<Eigen::Vector2d>& points,
                        const Colour& colour, double width = 1.5, bool closed = false);
// The iso-line values == level by marching squares over the cell centres
// (linear interpolation along cell edges; saddles split by the centre average).
// values must be the grid the map was made from (same rows and cols).
void draw_contour(HeatMap& map, const Block<double>& values, double level, const Colour& colour,
                  double width = 1.5);

}  // namespace jsa
