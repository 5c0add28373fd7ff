// Pictures of an atlas, drawn with io/pictures/image, io/pictures/raster and io/pictures/plot:
//  - the domain: P as a heat map over the texture frame, the Gaussian means as
//    dots, the thresholded boundary as a red contour;
//  - loss curves of a run (log scale);
//  - three views of a mesh coloured by 2D domain position (the paper's figures
//    colour shapes this way, so correspondences show as matching colours);
//  - a chart's UV layout, triangles coloured by their 3D normal, flipped and
//    torn ones outlined in red.
#pragma once
#include <vector>

#include "io/geometry/mesh.h"
#include "io/pictures/image.h"
#include "model/tool/domain_mesh.h"
#include "model/tool/loss_log.h"

namespace jsa {

Image domain_picture(const Atlas<float>& atlas, double level, int size = 512);
Image loss_curves(const LossLog& log);
// texture_uv: V x 2 in [0,1]^2 (TextureFrame coordinates) giving each vertex its colour.
Image domain_coloured_views(const Block<double>& vertices, const Faces& faces,
                            const Block<double>& texture_uv, int size = 384);
// The same three views with each pixel coloured from `texture` at its
// interpolated uv (V x 2, TextureFrame coordinates): texture transfer made visible.
Image textured_views(const Block<double>& vertices, const Faces& faces,
                     const Block<double>& texture_uv, const Image& texture, int size = 384);
// flipped faces are outlined in red; torn faces (which span the cut, across the
// whole layout) are left unfilled and marked by red dots at their corners.
Image uv_layout_picture(const Block<double>& vertices, const Faces& faces,
                        const Block<double>& texture_uv, const Faces& uv_faces,
                        const std::vector<int>& flipped, const std::vector<int>& torn,
                        int size = 768);

}  // namespace jsa
