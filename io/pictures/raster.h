// A small software rasteriser for looking at results without a GPU: triangle
// meshes with per-vertex colours or a UV texture, and point clouds as discs, both
// with a z-buffer, perspective projection and Lambert + ambient shading. Also
// cameras that frame a shape from three views, a grid composer with captions, and
// the 2D UV layout of a mesh with flipped / torn triangles outlined in red.
#pragma once
#include <string>
#include <vector>

#include "engine/block.h"
#include "io/geometry/mesh.h"
#include "io/pictures/image.h"

namespace jsa {

struct Camera {
  Eigen::Vector3d eye{0, 0, 3};     // where the camera is
  Eigen::Vector3d target{0, 0, 0};  // the point at the image centre
  Eigen::Vector3d up{0, 1, 0};      // world direction that appears upwards
  double fov_degrees = 40;          // vertical (and, for a square image, horizontal) field of view
};

struct RenderOptions {
  int width = 512, height = 512;
  // Direction towards the light in camera coordinates (x right, y up, z towards
  // the viewer), so every view is lit the same way: from the upper left, in front.
  Eigen::Vector3d light_dir{-0.4, 0.6, 1.0};
  double ambient = 0.3;  // shade = ambient + (1 - ambient) * |n . l|, two-sided
  Colour background = colours::white();
  int supersampling = 2;      // render k times larger and average k x k blocks (anti-aliasing)
  double point_radius = 2.0;  // render_points: disc radius in output pixels
  double near = 1e-3;         // triangles with a vertex closer than this are skipped
};

// Shaded render of a triangle mesh. vertices: V x 3; faces: F x 3 indices into
// vertices; vertex_colours: V x 3 in [0, 1] interpolated across each face
// (perspective-correct), or 0 rows for a uniform light grey.
Image render_mesh(const Block<double>& vertices, const Faces& faces,
                  const Block<double>& vertex_colours, const Camera& camera,
                  const RenderOptions& options = {});
// As render_mesh, but each pixel takes its colour from `texture` at the
// interpolated uv (V x 2, [0, 1]^2, v up): a checkerboard shows distortion.
Image render_textured_mesh(const Block<double>& vertices, const Faces& faces,
                           const Block<double>& uv, const Image& texture, const Camera& camera,
                           const RenderOptions& options = {});
// Points (N x 3) as unshaded discs of options.point_radius pixels, nearest in
// front. colours: N x 3 in [0, 1], or 0 rows for dark grey.
Image render_points(const Block<double>& points, const Block<double>& colours, const Camera& camera,
                    const RenderOptions& options = {});

// Front (looking down -z), side (down -x) and three-quarter top views of the
// bounding box, each as close as it can be with the whole box inside the central
// 90% of a square frame. Up is +y in all three.
std::vector<Camera> three_views(const Block<double>& vertices, double fov_degrees = 40);

struct GridOptions {
  int columns = 0;                    // images per row; 0 puts them all in one row
  int gap = 8;                        // pixels between cells and around the border
  std::vector<std::string> captions;  // one per image (missing ones left blank)
  int caption_scale = 2;              // font scale of the captions, drawn under each image
  Colour background = colours::white();
};

// Images in a grid, row by row; cells are as large as the largest image.
Image compose_grid(const std::vector<Image>& images, const GridOptions& options = {});
Image side_by_side(const std::vector<Image>& images, int gap = 8);

// The UV layout: uv (V x 2, in [0, 1]^2, v up) of each face filled with its
// face colour on a white `size` x `size` square, then the faces with
// highlight[f] (flipped or torn) outlined in red on top. highlight may be empty.
Image draw_uv_layout(const Block<double>& uv, const Faces& faces,
                     const std::vector<Eigen::Vector3d>& face_colours,
                     const std::vector<bool>& highlight, int size = 512);

}  // namespace jsa
