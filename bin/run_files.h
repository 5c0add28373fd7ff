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
  std::string texture;  // the user's image for the MTLs (empty: the built-in colour chart)
};
// OUT.obj (+ .mtl, texture PNG, _uv.json report, .png three views): the
// thresholded domain mapped through phi, in the input's frame.
void write_domain_mesh(Atlas<float>& atlas, const Normalization& normalization,
                       const std::string& obj_path, const MeshOutputOptions& o, int shape = 0);

struct ChartOutputOptions {
  bool split_cuts = false;  // give torn triangles their own UV corners (no smeared triangles)
  double torn_ratio = 10;   // a UV edge this many times longer than its 3D edge is torn
  bool quiet = false;
  std::string texture;  // the user's image for the MTL (empty: the built-in colour chart)
};
// OUT.obj with the user's vertices and faces in their order and vt from psi,
// OUT_uv.json, OUT.png (three views coloured through the chart), OUT_layout.png.
void write_chart(Atlas<float>& atlas, const Normalization& normalization, const Mesh& mesh,
                 const std::string& obj_path, const ChartOutputOptions& o, int shape = 0);

// Everything at the end of `fit`: domain_mesh.*, input_chart.* (for mesh
// inputs), domain.png, losses.png; for a collection the per-shape files go to
// DIR/shape_<i>/ and DIR/collection.png shows every shape coloured by the
// shared domain. With mesh.texture, every MTL uses that image, and
// DIR/texture_transfer.png shows it on every input through its chart: the
// domain is shared, so a texture painted on one shape's UVs fits them all.
void write_run_outputs(Atlas<float>& atlas, const std::vector<RunInput>& inputs, const LossLog& log,
                       const std::string& dir, const MeshOutputOptions& mesh);

}  // namespace jsa::cli
