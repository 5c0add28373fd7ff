// Packing charts into the unit square without overlap: each chart is turned
// so its principal axis is horizontal (a rotation, never a mirror), then the
// bounding boxes go on shelves (tallest first, left to right, a new shelf when
// a row is full), all at one common scale, the largest that fits (bisection),
// so every chart keeps the same texel density. Boxes are `padding` texels apart
// and from the border, for a texture of texture_size^2 texels.
#pragma once
#include <string>
#include <vector>

#include "engine/block.h"

namespace jsa {

struct PackOptions {
  int texture_size = 1024;  // texels per side of the texture the UVs are for
  double padding = 4;       // texels between two charts' boxes and between a box and the border
};

struct PackResult {
  double scale = 0;       // common scale applied to every chart
  double efficiency = 0;  // sum of the charts' UV areas after packing / the unit square
  double padding = 0;     // texels actually used (halved from the requested until the charts fit)
  std::vector<std::string> warnings;
};

// charts[i]: the UVs of chart i (n_i x 2), moved in place into [0, 1]^2;
// area[i]: its UV area (sum of triangle areas) before packing.
PackResult pack_charts(std::vector<Block<double>>& charts, const std::vector<double>& area,
                       const PackOptions& options);

}  // namespace jsa
