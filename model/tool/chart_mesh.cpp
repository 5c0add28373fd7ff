#include "model/tool/chart_mesh.h"

#include "io/geometry/vertex_normals.h"

namespace jsa {
namespace {

// Rows [x, alpha n] of the chart's input, in the unit frame.
Block<double> chart_input(const Atlas<float>& atlas, const Mesh& mesh,
                          const Normalization& normalization) {
  Block<double> normals =
      mesh.has_normals() ? mesh.normals : area_weighted_vertex_normals(mesh.vertices, mesh.faces);
  Block<double> in(mesh.vertices.rows(), 6);
  in.leftCols(3) = normalization.to_unit(mesh.vertices);
  in.rightCols(3) =
      atlas.options().alpha * normalization.normals_to_unit(normals).rowwise().normalized();
  return in;
}

}  // namespace

Block<double> chart_points(Atlas<float>& atlas, const Block<double>& x, int shape) {
  Block<double> uv(x.rows(), 2);
  Tape<float> t;
  const Index batch = 16384;
  for (Index b = 0; b < x.rows(); b += batch) {
    const Index n = std::min(batch, x.rows() - b);
    t.clear();
    Var out = atlas.psi.evaluate(t, atlas.params, t.constant(x.middleRows(b, n).cast<float>()),
                                 atlas.psi_code(t, shape));
    uv.middleRows(b, n) = t.value(out).cast<double>();
  }
  return uv;
}

Block<double> chart_vertices(Atlas<float>& atlas, const Mesh& mesh,
                             const Normalization& normalization, int shape) {
  if (mesh.vertices.rows() == 0) throw InputError("chart: the mesh has no vertices");
  return chart_points(atlas, chart_input(atlas, mesh, normalization), shape);
}

SplitUv split_torn(Atlas<float>& atlas, const Mesh& mesh, const Normalization& normalization,
                   const Block<double>& vertex_uv, const std::vector<int>& torn_faces, int shape) {
  const Block<double> in = chart_input(atlas, mesh, normalization);
  SplitUv out;
  out.uv_faces = mesh.faces;
  const Index V = vertex_uv.rows(), n = Index(torn_faces.size());
  // Directional finite differences of psi from corner a towards corners b, c:
  // psi(a + eps (b - a)) - psi(a) ~ eps J_psi(a) (b - a). psi is piecewise
  // linear (ReLU), so a small eps measures the slope of a's own linear piece.
  const double eps = 1e-3;
  Block<double> probes(3 * n, 6);
  for (Index k = 0; k < n; ++k) {
    const auto f = mesh.faces.row(torn_faces[k]);
    const auto a = in.row(f(0));
    probes.row(3 * k) = a;
    probes.row(3 * k + 1) = a + eps * (in.row(f(1)) - a);
    probes.row(3 * k + 2) = a + eps * (in.row(f(2)) - a);
  }
  const Block<double> p = chart_points(atlas, probes, shape);
  out.uv.resize(V + 3 * n, 2);
  out.uv.topRows(V) = vertex_uv;
  for (Index k = 0; k < n; ++k) {
    const Index base = V + 3 * k;
    out.uv.row(base) = vertex_uv.row(mesh.faces(torn_faces[k], 0));
    out.uv.row(base + 1) = out.uv.row(base) + (p.row(3 * k + 1) - p.row(3 * k)) / eps;
    out.uv.row(base + 2) = out.uv.row(base) + (p.row(3 * k + 2) - p.row(3 * k)) / eps;
    out.uv_faces.row(torn_faces[k]) << int(base), int(base + 1), int(base + 2);
  }
  return out;
}

}  // namespace jsa
