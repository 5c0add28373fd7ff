// Line plots and heat maps. An Axis maps data values to [0, 1] (linearly or by
// log10) and chooses ticks: 1-2-5 steps for linear axes; on log axes, powers of
// ten past three decades, else 1, 2 and 5 times them. Contours use marching squares.
#include "io/pictures/plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

#include "engine/check.h"

namespace jsa {
namespace {

std::string format_number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", value);
  std::string formatted = text;
  if (formatted == "-0") return "0";
  // 1e+04 -> 1e4, 2e-05 -> 2e-5
  const std::pair<std::string, std::string> shorter[] = {{"e+0", "e"}, {"e-0", "e-"}, {"e+", "e"}};
  for (const auto& [from, to] : shorter) {
    const auto at = formatted.find(from);
    if (at != std::string::npos) formatted.replace(at, from.size(), to);
  }
  return formatted;
}

// A 1, 2 or 5 times a power of ten, close to `rough`.
double nice_step(double rough) {
  const double decade = std::pow(10, std::floor(std::log10(rough)));
  const double fraction = rough / decade;
  return (fraction < 1.5 ? 1 : fraction < 3.5 ? 2 : fraction < 7.5 ? 5 : 10) * decade;
}

struct Axis {
  double low = 0, high = 1;  // in plotted units: the value, or log10 of it
  bool log = false;

  double plotted(double value) const { return log ? std::log10(value) : value; }
  double to_unit(double value) const { return (plotted(value) - low) / (high - low); }

  // Covers [min_value, max_value] (finite, and positive on a log axis) with a 4% margin.
  Axis(double min_value, double max_value, bool log_scale) : log(log_scale) {
    low = plotted(min_value), high = plotted(max_value);
    if (!(high > low)) {  // a single value: open a range around it
      const double half = log ? 1 : low != 0 ? 0.1 * std::abs(low) : 1;
      low -= half, high += half;
    }
    const double margin = 0.04 * (high - low);
    low -= margin, high += margin;
  }

  std::vector<double> ticks() const {  // data values
    std::vector<double> values;
    if (log && high - low >= 3) {  // powers of ten, at most ~8 of them
      const double stride = std::ceil((high - low) / 8);
      for (double e = std::ceil(low / stride) * stride; e <= high; e += stride)
        values.push_back(std::pow(10, e));
      return values;
    }
    if (log && high - low >= 0.7) {  // 1, 2, 5 times each power of ten
      for (double e = std::floor(low); e <= high; ++e)
        for (double m : {1.0, 2.0, 5.0}) {
          const double value = m * std::pow(10, e);
          if (plotted(value) >= low && plotted(value) <= high) values.push_back(value);
        }
      return values;
    }
    const double from = log ? std::pow(10, low) : low, to = log ? std::pow(10, high) : high;
    const double step = nice_step((to - from) / 5);
    if (!(step > 0) || !std::isfinite(step)) return values;  // a range past double's reach
    // Counted, not accumulated: a step below the rounding of `from` cannot loop forever.
    const double first = std::ceil(from / step) * step;
    const int count =
        std::clamp(static_cast<int>(std::floor((to - first) / step + 1e-9)) + 1, 0, 20);
    for (int i = 0; i < count; ++i) {
      const double v = first + i * step;
      values.push_back(std::abs(v) < 1e-9 * step ? 0 : v);
    }
    return values;
  }
};

// The finite values of one coordinate, checked against a log axis.
void check_values(const Series& s, const std::vector<double>& values, bool log, const char* name,
                  double& min_value, double& max_value, bool& any) {
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
    if (log && values[i] <= 0)
      throw InputError("line_plot: series '" + s.name + "' has " + name + "[" + std::to_string(i) +
                       "] = " + format_number(values[i]) + " but the " + name +
                       " axis is logarithmic; plot it on a linear axis or drop values <= 0");
    min_value = any ? std::min(min_value, values[i]) : values[i];
    max_value = any ? std::max(max_value, values[i]) : values[i];
    any = true;
  }
}

}  // namespace

Colour series_colour(int index) {
  static const Colour kPalette[10] = {{0.12, 0.47, 0.71}, {1.00, 0.50, 0.05}, {0.17, 0.63, 0.17},
                                      {0.84, 0.15, 0.16}, {0.58, 0.40, 0.74}, {0.55, 0.34, 0.29},
                                      {0.89, 0.47, 0.76}, {0.50, 0.50, 0.50}, {0.74, 0.74, 0.13},
                                      {0.09, 0.75, 0.81}};
  return kPalette[((index % 10) + 10) % 10];
}

namespace {

// The data rectangle inside the picture, and the axes that map into it.
struct Frame {
  int left, top, right, bottom;
  Axis x_axis, y_axis;
  double x_pixel(double x) const { return left + x_axis.to_unit(x) * (right - left); }
  double y_pixel(double y) const { return bottom - y_axis.to_unit(y) * (bottom - top); }
};

constexpr int kPad = 8;
const int kLine = text_height() + kPad;  // one line of size-1 text and its spacing

// Grid lines, tick marks and labels, the frame, title and axis labels.
void draw_axes(Image& image, const Frame& frame, const PlotOptions& options) {
  for (double t : frame.x_axis.ticks()) {
    const int px = static_cast<int>(std::lround(frame.x_pixel(t)));
    fill_rectangle(image, px, frame.top, px + 1, frame.bottom, colours::grey(0.9));
    fill_rectangle(image, px, frame.bottom, px + 1, frame.bottom + 4, colours::black());
    const std::string label = format_number(t);
    draw_text(image, px - text_width(label) / 2, frame.bottom + 6, label, colours::black());
  }
  for (double t : frame.y_axis.ticks()) {
    const int py = static_cast<int>(std::lround(frame.y_pixel(t)));
    fill_rectangle(image, frame.left, py, frame.right, py + 1, colours::grey(0.9));
    fill_rectangle(image, frame.left - 4, py, frame.left, py + 1, colours::black());
    const std::string label = format_number(t);
    draw_text(image, frame.left - 6 - text_width(label), py - text_height() / 2, label,
              colours::black());
  }
  draw_rectangle_outline(image, frame.left, frame.top, frame.right + 1, frame.bottom + 1,
                         colours::black());
  if (!options.title.empty())
    draw_text(image, (options.width - text_width(options.title, 2)) / 2, kPad, options.title,
              colours::black(), 2);
  if (!options.y_label.empty())
    draw_text(image, kPad, frame.top - 4 - kLine, options.y_label, colours::black());
  if (!options.x_label.empty())
    draw_text(image, (frame.left + frame.right - text_width(options.x_label)) / 2,
              frame.bottom + 6 + kLine, options.x_label, colours::black());
}

// A boxed list of line samples and names in the upper-right corner of the frame.
void draw_legend(Image& image, const Frame& frame, const std::vector<Series>& series,
                 double line_width) {
  int named = 0, longest = 0;
  for (const Series& s : series)
    if (!s.name.empty()) ++named, longest = std::max(longest, text_width(s.name));
  if (named == 0) return;
  const int box_width = longest + 36, box_height = named * kLine + kPad;
  const int x0 = frame.right - kPad - box_width, y0 = frame.top + kPad;
  fill_rectangle(image, x0, y0, x0 + box_width, y0 + box_height, colours::white());
  draw_rectangle_outline(image, x0, y0, x0 + box_width, y0 + box_height, colours::grey(0.6));
  int y = y0 + kPad;
  for (std::size_t k = 0; k < series.size(); ++k) {
    if (series[k].name.empty()) continue;
    const double middle = y + text_height() / 2.0;
    draw_line(image, {x0 + 6.0, middle}, {x0 + 24.0, middle}, series_colour(static_cast<int>(k)),
              line_width);
    draw_text(image, x0 + 30, y, series[k].name, colours::black());
    y += kLine;
  }
}

}  // namespace

Image line_plot(const std::vector<Series>& series, const PlotOptions& options) {
  JSA_CHECK(options.width > 0 && options.height > 0, "plot size");
  double x_min = 0, x_max = 1, y_min = 0, y_max = 1;
  bool any_x = false, any_y = false;
  for (const Series& s : series) {
    if (s.x.size() != s.y.size())
      throw InputError("line_plot: series '" + s.name + "' has " + std::to_string(s.x.size()) +
                       " x values but " + std::to_string(s.y.size()) + " y values");
    check_values(s, s.x, options.log_x, "x", x_min, x_max, any_x);
    check_values(s, s.y, options.log_y, "y", y_min, y_max, any_y);
  }
  if (!any_x && options.log_x) x_min = 1, x_max = 10;  // empty plot: some valid range
  if (!any_y && options.log_y) y_min = 1, y_max = 10;
  const Axis x_axis(x_min, x_max, options.log_x), y_axis(y_min, y_max, options.log_y);

  // Layout: title and y label above the frame, tick labels left of and below it,
  // the x label under those.
  int widest_y_label = 0;
  for (double t : y_axis.ticks())
    widest_y_label = std::max(widest_y_label, text_width(format_number(t)));
  const Frame frame{kPad + widest_y_label + 6,
                    kPad + (options.title.empty() ? 0 : text_height(2) + kPad) +
                        (options.y_label.empty() ? 0 : kLine) + 4,
                    options.width - 3 * kPad,
                    options.height - kPad - kLine - (options.x_label.empty() ? 0 : kLine),
                    x_axis,
                    y_axis};
  Image image(options.width, options.height, colours::white());
  draw_axes(image, frame, options);

  for (std::size_t k = 0; k < series.size(); ++k) {
    const Series& s = series[k];
    const Colour colour = series_colour(static_cast<int>(k));
    bool have_previous = false;  // false at the start and after a skipped point
    Eigen::Vector2d previous;
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) {
        have_previous = false;
        continue;
      }
      const Eigen::Vector2d p(frame.x_pixel(s.x[i]), frame.y_pixel(s.y[i]));
      if (have_previous) draw_line(image, previous, p, colour, options.line_width);
      if (options.markers || s.x.size() == 1)
        fill_circle(image, p, options.line_width + 1.5, colour);
      previous = p, have_previous = true;
    }
  }
  if (options.legend) draw_legend(image, frame, series, options.line_width);
  return image;
}

HeatMap heat_map(const Block<double>& values, const HeatMapOptions& options) {
  JSA_CHECK(values.rows() > 0 && values.cols() > 0, "heat_map needs a non-empty grid");
  JSA_CHECK(options.size > 0, "heat map size " << options.size);
  double low = options.low, high = options.high;
  double data_min = 0, data_max = 1;
  bool any = false;
  for (Index r = 0; r < values.rows(); ++r)
    for (Index c = 0; c < values.cols(); ++c)
      if (std::isfinite(values(r, c))) {
        data_min = any ? std::min(data_min, values(r, c)) : values(r, c);
        data_max = any ? std::max(data_max, values(r, c)) : values(r, c);
        any = true;
      }
  if (std::isnan(low)) low = data_min;
  if (std::isnan(high)) high = data_max;
  auto unit = [&](double v) { return high > low ? (v - low) / (high - low) : 0.5; };

  HeatMap map;
  const int pad = 10;
  map.cell = static_cast<double>(options.size) / std::max(values.rows(), values.cols());
  map.left = pad;
  map.top = pad + (options.title.empty() ? 0 : text_height(2) + pad);
  map.rows = values.rows(), map.cols = values.cols();
  const int grid_width = std::max(1, static_cast<int>(std::lround(values.cols() * map.cell)));
  const int grid_height = std::max(1, static_cast<int>(std::lround(values.rows() * map.cell)));
  const std::string labels[3] = {format_number(high), format_number(0.5 * (low + high)),
                                 format_number(low)};
  const int bar_x = pad + grid_width + 12, bar_width = 14;
  int label_width = 0;
  for (const std::string& label : labels) label_width = std::max(label_width, text_width(label));
  const int width = options.colour_bar ? bar_x + bar_width + 6 + label_width + pad : bar_x;
  map.image = Image(std::max(width, text_width(options.title, 2) + 2 * pad),
                    static_cast<int>(map.top) + grid_height + pad + text_height() / 2);
  Image& image = map.image;

  for (int y = 0; y < grid_height; ++y)
    for (int x = 0; x < grid_width; ++x) {
      const Index r = std::min<Index>(values.rows() - 1, static_cast<Index>((y + 0.5) / map.cell));
      const Index c = std::min<Index>(values.cols() - 1, static_cast<Index>((x + 0.5) / map.cell));
      const double v = values(r, c);
      image.set(pad + x, static_cast<int>(map.top) + y,
                std::isfinite(v) ? viridis(unit(v)) : colours::grey(0.6));
    }
  if (!options.title.empty()) draw_text(image, pad, pad, options.title, colours::black(), 2);
  if (options.colour_bar) {
    const int top = static_cast<int>(map.top);
    for (int y = 0; y < grid_height; ++y)
      fill_rectangle(image, bar_x, top + y, bar_x + bar_width, top + y + 1,
                     viridis(1 - (y + 0.5) / grid_height));
    draw_rectangle_outline(image, bar_x, top, bar_x + bar_width, top + grid_height,
                           colours::black());
    for (int i = 0; i < 3; ++i)
      draw_text(image, bar_x + bar_width + 6, top + i * (grid_height - 1) / 2 - text_height() / 2,
                labels[i], colours::black());
  }
  return map;
}

void draw_grid_dot(HeatMap& map, double column, double row, double radius, const Colour& colour) {
  fill_circle(map.image, map.to_pixel(column, row), radius, colour);
}

void draw_grid_polyline(HeatMap& map, const std::vector<Eigen::Vector2d>& points,
                        const Colour& colour, double width, bool closed) {
  const std::size_t n = points.size();
  for (std::size_t i = 0; i + 1 < n + (closed && n > 2 ? 1 : 0); ++i)
    draw_line(map.image, map.to_pixel(points[i].x(), points[i].y()),
              map.to_pixel(points[(i + 1) % n].x(), points[(i + 1) % n].y()), colour, width);
}

void draw_contour(HeatMap& map, const Block<double>& values, double level, const Colour& colour,
                  double width) {
  // Each square joins four cell centres, corners in order a=(r,c), b=(r,c+1),
  // c=(r+1,c+1), d=(r+1,c); edge k runs from corner k to corner k+1 (top, right,
  // bottom, left). The iso-line crosses an edge where its ends lie on either side.
  JSA_CHECK(values.rows() == map.rows && values.cols() == map.cols,
            "contour of a " << values.rows() << " x " << values.cols() << " grid drawn on a "
                            << map.rows << " x " << map.cols << " heat map");
  const int corner_row[4] = {0, 0, 1, 1}, corner_column[4] = {0, 1, 1, 0};
  for (Index r = 0; r + 1 < values.rows(); ++r)
    for (Index c = 0; c + 1 < values.cols(); ++c) {
      double v[4];
      bool above[4], finite = true;
      for (int k = 0; k < 4; ++k) {
        v[k] = values(r + corner_row[k], c + corner_column[k]);
        finite = finite && std::isfinite(v[k]);
        above[k] = v[k] >= level;
      }
      if (!finite) continue;
      Eigen::Vector2d crossing[4];  // (column, row) where the line crosses edge k
      bool crosses[4];
      for (int k = 0; k < 4; ++k) {
        const int j = (k + 1) % 4;
        crosses[k] = above[k] != above[j];
        if (!crosses[k]) continue;
        const double t = (level - v[k]) / (v[j] - v[k]);
        crossing[k] = {c + corner_column[k] + t * (corner_column[j] - corner_column[k]),
                       r + corner_row[k] + t * (corner_row[j] - corner_row[k])};
      }
      auto segment = [&](int e, int f) {
        draw_line(map.image, map.to_pixel(crossing[e].x(), crossing[e].y()),
                  map.to_pixel(crossing[f].x(), crossing[f].y()), colour, width);
      };
      const int count = crosses[0] + crosses[1] + crosses[2] + crosses[3];
      if (count == 2) {
        int e = -1, f = -1;
        for (int k = 0; k < 4; ++k)
          if (crosses[k]) (e < 0 ? e : f) = k;
        segment(e, f);
      } else if (count == 4) {
        // Saddle: if the centre sides with corners a and c, the line cuts off b and d.
        const bool centre_above = (v[0] + v[1] + v[2] + v[3]) / 4 >= level;
        if (centre_above == above[0])
          segment(0, 1), segment(2, 3);
        else
          segment(3, 0), segment(1, 2);
      }
    }
}

}  // namespace jsa
