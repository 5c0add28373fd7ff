#include "io/pictures/run_pictures.h"

#include <cmath>

#include "io/geometry/vertex_normals.h"
#include "io/pictures/plot.h"
#include "io/pictures/raster.h"

namespace jsa {

Image domain_picture(const Atlas<float>& atlas, double level, int size) {
  const TextureFrame frame = texture_frame(atlas);
  const int n = 256;  // grid cells per side; row 0 is the top (v = 1)
  Block<double> nodes(Index(n) * n, 2);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c)
      nodes.row(Index(r) * n + c) << frame.lo(0) + (c + 0.5) / n * frame.side,
          frame.lo(1) + (n - r - 0.5) / n * frame.side;
  const std::vector<double> p = atlas.domain.density(atlas.params, nodes);
  Block<double> grid(n, n);
  for (Index i = 0; i < grid.size(); ++i) grid.data()[i] = p[size_t(i)];
  HeatMapOptions o;
  o.size = size;
  o.title = "domain P (Eq. 4): density, means, boundary";
  HeatMap map = heat_map(grid, o);
  const auto mu = atlas.params.value(atlas.domain.means());
  const Index step = std::max<Index>(1, mu.rows() / 4000);  // at most ~4000 dots
  for (Index k = 0; k < mu.rows(); k += step) {
    const double c = (mu(k, 0) - frame.lo(0)) / frame.side * n - 0.5;
    const double r = n - (mu(k, 1) - frame.lo(1)) / frame.side * n - 0.5;
    draw_grid_dot(map, c, r, 1.0, colours::white());
  }
  draw_contour(map, grid, level, colours::red(), 2.0);
  return map.image;
}

Image loss_curves(const LossLog& log) {
  const char* names[] = {"total", "L_6D", "L_2D", "L_cycle 2D", "L_cycle 6D", "L_iso", "L_rep"};
  std::vector<Series> series(7);
  for (int k = 0; k < 7; ++k) series[size_t(k)].name = names[k];
  for (const auto& r : log.rows) {
    const double v[7] = {r.terms.total,    r.terms.surface,  r.terms.chart,    r.terms.cycle_2d,
                         r.terms.cycle_6d, r.terms.isometry, r.terms.repulsion};
    for (int k = 0; k < 7; ++k) {
      series[size_t(k)].x.push_back(double(r.iteration));
      // log axis: zero terms (switched off) are left out as NaN
      series[size_t(k)].y.push_back(v[k] > 0 ? v[k] : std::nan(""));
    }
  }
  std::vector<Series> kept;
  for (auto& s : series) {
    bool any = false;
    for (double y : s.y) any = any || std::isfinite(y);
    if (any) kept.push_back(std::move(s));
  }
  PlotOptions o;
  o.width = 800;
  o.height = 500;
  o.log_y = true;
  o.title = "loss terms (unweighted)";
  o.x_label = "iteration";
  return line_plot(kept, o);
}

Image domain_coloured_views(const Block<double>& vertices, const Faces& faces,
                            const Block<double>& texture_uv, int size) {
  Block<double> colour(vertices.rows(), 3);
  for (Index i = 0; i < vertices.rows(); ++i)
    colour.row(i) = domain_colour(texture_uv(i, 0), texture_uv(i, 1)).transpose();
  RenderOptions ro;
  ro.width = ro.height = size;
  std::vector<Image> views;
  for (const Camera& c : three_views(vertices))
    views.push_back(render_mesh(vertices, faces, colour, c, ro));
  return side_by_side(views);
}

Image textured_views(const Block<double>& vertices, const Faces& faces,
                     const Block<double>& texture_uv, const Image& texture, int size) {
  RenderOptions ro;
  ro.width = ro.height = size;
  std::vector<Image> views;
  for (const Camera& c : three_views(vertices))
    views.push_back(render_textured_mesh(vertices, faces, texture_uv, texture, c, ro));
  return side_by_side(views);
}

Image uv_layout_picture(const Block<double>& vertices, const Faces& faces,
                        const Block<double>& texture_uv, const Faces& uv_faces,
                        const std::vector<int>& flipped, const std::vector<int>& torn, int size) {
  std::vector<bool> is_torn(size_t(faces.rows()), false);
  for (int f : torn) is_torn[size_t(f)] = true;
  const Block<double> fn = face_normals(vertices, faces);
  Faces kept(faces.rows() - Index(torn.size()), 3);
  std::vector<Eigen::Vector3d> colour;
  std::vector<bool> highlight;
  std::vector<bool> is_flipped(size_t(faces.rows()), false);
  for (int f : flipped) is_flipped[size_t(f)] = true;
  for (Index f = 0, k = 0; f < faces.rows(); ++f) {
    if (is_torn[size_t(f)]) continue;
    kept.row(k++) = uv_faces.row(f);
    colour.push_back((0.5 * (fn.row(f).transpose().array() + 1)).matrix());
    highlight.push_back(is_flipped[size_t(f)]);
  }
  Image image = draw_uv_layout(texture_uv, kept, colour, highlight, size);
  for (int f : torn)
    for (int c = 0; c < 3; ++c) {
      const Index v = uv_faces(f, c);
      fill_circle(image, {texture_uv(v, 0) * size, (1 - texture_uv(v, 1)) * size}, 1.5,
                  colours::red());
    }
  return image;
}

}  // namespace jsa
