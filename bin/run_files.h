// Glue shared by the subcommands: what a finished fit leaves behind (meshes
// with UVs, UV quality reports, pictures), each also reachable on its own
// through `jsatlas mesh` and `jsatlas chart`.
#pragma once
#include <string>

#include "model/atlas.h"
#include "model/tool/loss_log.h"
#include "model/tool/shape_input.h"

namespace jsa::cli {

std::string json_quote(const std::string& s);

struct MeshOutputOptions {
  int resolution = 256;     // grid cells across the domain
  double threshold = 0.05;  // domain = {P >= threshold * median of P at the means}
  bool quiet = false;
  std::string texture;      // the user's image for the MTLs (empty: the built-in colour chart)
  int texture_size = 1024;  // texels per side of the texture the UVs are laid out for
  double padding = 4;       // texels kept free around charts and along the border
};
// OUT.obj (+ .mtl, texture PNG, _uv.json report, .png three views): the
// thresholded domain mapped through phi, in the input's frame. With the
// shape's surface samples (P x 6 [x, n], unit frame) the report also gives the
// share of the mesh's area that faces away from the surface (phi's flaps).
void write_domain_mesh(Atlas<float>& atlas, const Normalization& normalization,
                       const std::string& obj_path, const MeshOutputOptions& o, int shape = 0,
                       const Block<double>* surface = nullptr);

struct ChartOutputOptions {
  bool psi_only = false;    // write psi's UVs as they are (no cut, repair or packing): the "before"
  bool split_cuts = false;  // with psi_only: give torn triangles their own UV corners
  double torn_ratio = 10;   // a UV edge this many times longer than its 3D edge is torn (report)
  bool pack = true;  // pack the valid charts into [0,1]^2; false keeps psi's shared-domain layout
  int texture_size = 1024;  // texels per side of the texture the UVs are laid out for
  double padding = 4;  // texels between packed charts (and the border inset of the shared layout)
  bool quiet = false;
  std::string texture;  // the user's image for the MTL (empty: the built-in colour chart)
};
// OUT.obj with the user's vertices and faces in their order and valid UVs
// (io/geometry/valid_uv.h: psi's layout cut where it tears or folds, made
// injective, packed), OUT_uv.json (the UV report of the written map, and of
// psi's own UVs under "psi"), OUT.png (three views coloured through the
// chart), OUT_layout.png.
struct ChartWritten {
  Block<double> vt;  // the written texture coordinates
  Faces uv_faces;    // F x 3 into vt
};
ChartWritten write_chart(Atlas<float>& atlas, const Normalization& normalization, const Mesh& mesh,
                         const std::string& obj_path, const ChartOutputOptions& o, int shape = 0);

// Texture coordinates of the shared layout: the TextureFrame inset by `padding`
// texels of a texture_size texture, the same for every shape of a collection.
Block<double> shared_layout(const Block<double>& frame_uv, int texture_size, double padding);

// Everything at the end of `fit`: domain_mesh.*, input_chart.* (for mesh
// inputs), domain.png, losses.png; for a collection the per-shape files go to
// DIR/shape_<i>/ and DIR/collection.png shows every shape coloured by the
// shared domain. With mesh.texture, every MTL uses that image, and
// DIR/texture_transfer.png shows it on every input through its chart: the
// domain is shared, so a texture painted on one shape's UVs fits them all.
void write_run_outputs(Atlas<float>& atlas, const std::vector<RunInput>& inputs, const LossLog& log,
                       const std::string& dir, const MeshOutputOptions& mesh);

}  // namespace jsa::cli
