// Scanline-free rasterisation: for each triangle, test every pixel centre in its
// screen bounding box with three edge functions, interpolate with barycentric
// weights divided by depth (perspective-correct), keep the nearest in a z-buffer.
// Rendering happens at `supersampling` times the size, then k x k blocks are averaged.
#include "io/pictures/raster.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "engine/check.h"

namespace jsa {
namespace {

// World -> camera frame (right, up, forward) and a pinhole projection to pixels.
struct Projection {
  Eigen::Vector3d eye, right, up, forward;
  double focal, centre_x, centre_y;  // pixels per unit of x/z, and the image centre

  Projection(const Camera& camera, int width, int height) : eye(camera.eye) {
    JSA_CHECK(camera.fov_degrees > 0 && camera.fov_degrees < 180, "fov " << camera.fov_degrees);
    forward = camera.target - camera.eye;
    JSA_CHECK(forward.norm() > 0, "camera eye and target coincide");
    forward.normalize();
    right = forward.cross(camera.up);
    JSA_CHECK(right.norm() > 1e-12 * camera.up.norm(), "camera up is parallel to the view");
    right.normalize();
    up = right.cross(forward);
    focal = 0.5 * std::min(width, height) / std::tan(camera.fov_degrees * M_PI / 360);
    centre_x = 0.5 * width, centre_y = 0.5 * height;
  }
  // (x right, y down) in pixels, and the depth along the view direction.
  Eigen::Vector3d project(const Eigen::Vector3d& point) const {
    const Eigen::Vector3d d = point - eye;
    const double depth = d.dot(forward);
    return {centre_x + focal * d.dot(right) / depth, centre_y - focal * d.dot(up) / depth, depth};
  }
  // A world direction in camera coordinates (z towards the viewer).
  Eigen::Vector3d to_camera(const Eigen::Vector3d& direction) const {
    return {direction.dot(right), direction.dot(up), -direction.dot(forward)};
  }
};

struct FrameBuffer {
  Image image;
  std::vector<double> depth;
  FrameBuffer(int width, int height, const Colour& background)
      : image(width, height, background),
        depth(static_cast<std::size_t>(width) * height, std::numeric_limits<double>::infinity()) {}
  // Writes the pixel if it is nearer than what is there.
  void write(int x, int y, double z, const Colour& colour) {
    double& nearest = depth[static_cast<std::size_t>(y) * image.width + x];
    if (z >= nearest) return;
    nearest = z;
    image.set(x, y, colour);
  }
};

// Averages k x k blocks.
Image downsample(const Image& large, int k) {
  if (k == 1) return large;
  Image small(large.width / k, large.height / k);
  for (int y = 0; y < small.height; ++y)
    for (int x = 0; x < small.width; ++x) {
      Colour sum = Colour::Zero();
      for (int dy = 0; dy < k; ++dy)
        for (int dx = 0; dx < k; ++dx) sum += large.get(x * k + dx, y * k + dy);
      small.set(x, y, sum / (k * k));
    }
  return small;
}

// Fills one projected triangle (screen x, y, depth per corner). `colour_at(w)`
// gets the perspective-correct barycentric weights w (summing to 1).
template <class ColourAt>
void rasterize_triangle(FrameBuffer& frame, const Eigen::Vector3d (&s)[3], ColourAt colour_at) {
  // Twice the signed area of (p, q, (x, y)). Evaluated with the endpoints in a fixed
  // order so that edge(p, q) == -edge(q, p) exactly: a pixel centre on an edge shared
  // by two triangles then falls in at least one of them, never in a crack.
  auto edge = [](const Eigen::Vector3d& p, const Eigen::Vector3d& q, double x, double y) {
    const bool swap = std::make_pair(q.x(), q.y()) < std::make_pair(p.x(), p.y());
    const Eigen::Vector3d& a = swap ? q : p;
    const Eigen::Vector3d& b = swap ? p : q;
    const double value = (b.x() - a.x()) * (y - a.y()) - (b.y() - a.y()) * (x - a.x());
    return swap ? -value : value;
  };
  const double area = edge(s[0], s[1], s[2].x(), s[2].y());
  if (area == 0 || !std::isfinite(area)) return;
  const PixelSpan xs = pixel_span(std::min({s[0].x(), s[1].x(), s[2].x()}),
                                  std::max({s[0].x(), s[1].x(), s[2].x()}), frame.image.width);
  const PixelSpan ys = pixel_span(std::min({s[0].y(), s[1].y(), s[2].y()}),
                                  std::max({s[0].y(), s[1].y(), s[2].y()}), frame.image.height);
  for (int y = ys.first; y <= ys.last; ++y)
    for (int x = xs.first; x <= xs.last; ++x) {
      const double px = x + 0.5, py = y + 0.5;
      // Screen-space barycentrics; all >= 0 inside, whatever the winding.
      const Eigen::Vector3d b(edge(s[1], s[2], px, py) / area, edge(s[2], s[0], px, py) / area,
                              edge(s[0], s[1], px, py) / area);
      if (b.minCoeff() < 0) continue;
      // Attributes are linear in screen space only after dividing by depth:
      // w_i = (b_i / z_i) / sum_j (b_j / z_j), and the depth is 1 / sum_j (b_j / z_j).
      const Eigen::Vector3d over_depth(b[0] / s[0].z(), b[1] / s[1].z(), b[2] / s[2].z());
      const double inverse_depth = over_depth.sum();
      frame.write(x, y, 1 / inverse_depth, colour_at(Eigen::Vector3d(over_depth / inverse_depth)));
    }
}

// Shared by render_mesh and render_textured_mesh: colour_at(face, w) gives the
// unshaded colour at weights w; this applies the face's two-sided Lambert shade.
template <class ColourAt>
Image render_faces(const Block<double>& vertices, const Faces& faces, const Camera& camera,
                   const RenderOptions& options, ColourAt colour_at) {
  JSA_CHECK(vertices.cols() == 3, "vertices must be V x 3, got " << vertices.cols() << " columns");
  JSA_CHECK(options.width > 0 && options.height > 0 && options.supersampling >= 1,
            "render size " << options.width << " x " << options.height);
  const int k = options.supersampling;
  const Projection projection(camera, options.width * k, options.height * k);
  const Eigen::Vector3d light = options.light_dir.normalized();
  FrameBuffer frame(options.width * k, options.height * k, options.background);
  for (Index f = 0; f < faces.rows(); ++f) {
    Eigen::Vector3d corner[3], screen[3];
    bool visible = true;
    for (int i = 0; i < 3; ++i) {
      const int v = faces(f, i);
      JSA_CHECK(v >= 0 && v < vertices.rows(), "face " << f << " has vertex " << v);
      corner[i] = vertices.row(v).transpose();
      screen[i] = projection.project(corner[i]);
      visible = visible && screen[i].z() > options.near;
    }
    if (!visible) continue;
    const Eigen::Vector3d normal = (corner[1] - corner[0]).cross(corner[2] - corner[0]);
    const double lambert =
        normal.norm() > 0 ? std::abs(projection.to_camera(normal.normalized()).dot(light)) : 1;
    const double shade = options.ambient + (1 - options.ambient) * lambert;
    rasterize_triangle(frame, screen,
                       [&](const Eigen::Vector3d& w) { return Colour(shade * colour_at(f, w)); });
  }
  return downsample(frame.image, k);
}

}  // namespace

Image render_mesh(const Block<double>& vertices, const Faces& faces,
                  const Block<double>& vertex_colours, const Camera& camera,
                  const RenderOptions& options) {
  const bool coloured = vertex_colours.rows() > 0;
  JSA_CHECK(!coloured || (vertex_colours.rows() == vertices.rows() && vertex_colours.cols() == 3),
            "vertex_colours must be V x 3 or empty");
  return render_faces(vertices, faces, camera, options, [&](Index f, const Eigen::Vector3d& w) {
    if (!coloured) return colours::grey(0.8);
    Colour colour = Colour::Zero();
    for (int i = 0; i < 3; ++i) colour += w[i] * vertex_colours.row(faces(f, i)).transpose();
    return colour;
  });
}

Image render_textured_mesh(const Block<double>& vertices, const Faces& faces,
                           const Block<double>& uv, const Image& texture, const Camera& camera,
                           const RenderOptions& options) {
  JSA_CHECK(uv.rows() == vertices.rows() && uv.cols() == 2, "uv must be V x 2");
  return render_faces(vertices, faces, camera, options, [&](Index f, const Eigen::Vector3d& w) {
    Eigen::Vector2d at = Eigen::Vector2d::Zero();
    for (int i = 0; i < 3; ++i) at += w[i] * uv.row(faces(f, i)).transpose();
    return sample_texture(texture, at.x(), at.y());
  });
}

Image render_points(const Block<double>& points, const Block<double>& colours, const Camera& camera,
                    const RenderOptions& options) {
  JSA_CHECK(points.cols() == 3, "points must be N x 3");
  JSA_CHECK(colours.rows() == 0 || (colours.rows() == points.rows() && colours.cols() == 3),
            "colours must be N x 3 or empty");
  const int k = options.supersampling;
  JSA_CHECK(options.width > 0 && options.height > 0 && k >= 1, "render size");
  const Projection projection(camera, options.width * k, options.height * k);
  FrameBuffer frame(options.width * k, options.height * k, options.background);
  const double radius = std::max(options.point_radius * k, 0.5);
  for (Index n = 0; n < points.rows(); ++n) {
    const Eigen::Vector3d s = projection.project(points.row(n).transpose());
    if (!(s.z() > options.near) || !s.allFinite()) continue;
    const Colour colour =
        colours.rows() > 0 ? Colour(colours.row(n).transpose()) : colours::grey(0.25);
    const PixelSpan xs = pixel_span(s.x() - radius, s.x() + radius, frame.image.width);
    const PixelSpan ys = pixel_span(s.y() - radius, s.y() + radius, frame.image.height);
    for (int y = ys.first; y <= ys.last; ++y)
      for (int x = xs.first; x <= xs.last; ++x)
        if (std::hypot(x + 0.5 - s.x(), y + 0.5 - s.y()) <= radius)
          frame.write(x, y, s.z(), colour);
  }
  return downsample(frame.image, k);
}

std::vector<Camera> three_views(const Block<double>& vertices, double fov_degrees) {
  JSA_CHECK(vertices.rows() > 0 && vertices.cols() == 3, "three_views needs V x 3 vertices, V > 0");
  const Eigen::Vector3d low = vertices.colwise().minCoeff().transpose();
  const Eigen::Vector3d high = vertices.colwise().maxCoeff().transpose();
  const Eigen::Vector3d centre = 0.5 * (low + high);
  const double half_width = 0.9 * std::tan(fov_degrees * M_PI / 360);  // fill 90% of the frame
  const Eigen::Vector3d directions[3] = {
      {0, 0, 1}, {1, 0, 0}, Eigen::Vector3d(1, 1, 1).normalized()};  // front, side, 3/4 top
  const Eigen::Vector3d up(0, 1, 0);
  std::vector<Camera> cameras;
  for (const Eigen::Vector3d& towards_eye : directions) {
    const Eigen::Vector3d right = up.cross(towards_eye).normalized();
    const Eigen::Vector3d screen_up = towards_eye.cross(right);
    // A box corner at sideways offset s and depth offset d (towards the eye) is in
    // frame when s / (distance - d) <= half_width. Since projection keeps lines
    // straight, the whole box is in frame when its eight corners are.
    double distance = 0;
    for (int k = 0; k < 8; ++k) {
      const Eigen::Vector3d corner((k & 1 ? high : low).x(), (k & 2 ? high : low).y(),
                                   (k & 4 ? high : low).z());
      const Eigen::Vector3d offset = corner - centre;
      const double sideways =
          std::max(std::abs(offset.dot(right)), std::abs(offset.dot(screen_up)));
      distance = std::max(distance, offset.dot(towards_eye) + sideways / half_width);
    }
    if (!(distance > 0)) distance = 1;  // a single point: any distance will do
    cameras.push_back({centre + distance * towards_eye, centre, up, fov_degrees});
  }
  return cameras;
}

Image compose_grid(const std::vector<Image>& images, const GridOptions& options) {
  JSA_CHECK(!images.empty(), "compose_grid needs at least one image");
  const int count = static_cast<int>(images.size());
  const int columns = options.columns > 0 ? std::min(options.columns, count) : count;
  const int rows = (count + columns - 1) / columns;
  int cell_width = 0, cell_height = 0;
  for (const Image& image : images)
    cell_width = std::max(cell_width, image.width),
    cell_height = std::max(cell_height, image.height);
  const int gap = std::max(options.gap, 0);
  const int caption_height =
      options.captions.empty() ? 0 : text_height(options.caption_scale) + gap;
  const int row_height = cell_height + caption_height + gap;
  Image grid(gap + columns * (cell_width + gap), gap + rows * row_height, options.background);
  for (int i = 0; i < count; ++i) {
    const int x = gap + (i % columns) * (cell_width + gap), y = gap + (i / columns) * row_height;
    grid.paste(images[i], x + (cell_width - images[i].width) / 2, y);
    if (i < static_cast<int>(options.captions.size())) {
      const std::string& caption = options.captions[i];
      const int width = text_width(caption, options.caption_scale);
      draw_text(grid, x + std::max(0, (cell_width - width) / 2), y + cell_height + gap, caption,
                colours::black(), options.caption_scale);
    }
  }
  return grid;
}

Image side_by_side(const std::vector<Image>& images, int gap) {
  GridOptions options;
  options.gap = gap;
  return compose_grid(images, options);
}

Image draw_uv_layout(const Block<double>& uv, const Faces& faces,
                     const std::vector<Eigen::Vector3d>& face_colours,
                     const std::vector<bool>& highlight, int size) {
  JSA_CHECK(uv.cols() == 2, "uv must be V x 2");
  JSA_CHECK(static_cast<Index>(face_colours.size()) == faces.rows(), "one colour per face");
  JSA_CHECK(highlight.empty() || static_cast<Index>(highlight.size()) == faces.rows(),
            "highlight must be empty or one flag per face");
  JSA_CHECK(size > 0, "uv layout of " << size << " px");
  Image image(size, size, colours::white());
  auto corner = [&](Index f, int i) {
    const int v = faces(f, i);
    JSA_CHECK(v >= 0 && v < uv.rows(), "face " << f << " has vertex " << v);
    return Eigen::Vector2d(uv(v, 0) * size, (1 - uv(v, 1)) * size);
  };
  for (Index f = 0; f < faces.rows(); ++f)
    fill_triangle(image, corner(f, 0), corner(f, 1), corner(f, 2), face_colours[f]);
  draw_rectangle_outline(image, 0, 0, size, size, colours::grey(0.7));  // the unit square
  for (Index f = 0; f < static_cast<Index>(highlight.size()); ++f)
    if (highlight[f])
      for (int i = 0; i < 3; ++i)
        draw_line(image, corner(f, i), corner(f, (i + 1) % 3), colours::red(), 1.5);
  return image;
}

}  // namespace jsa
