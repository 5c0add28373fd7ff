#include "model/tool/spectral_start.h"

#include "engine/check.h"
#include "io/geometry/nearest.h"

namespace jsa {

ZoomOutOptions zoomout_options(const SpectralStartOptions& o) {
  ZoomOutOptions zo;
  zo.k_start = o.k_start;
  zo.k_end = o.functions;
  zo.k_step = o.k_step;
  zo.samples = o.samples;
  zo.orthogonal = true;
  return zo;
}

std::vector<LaplaceBasis> laplace_bases(const std::vector<Mesh>& meshes, int functions,
                                        const std::string& option) {
  for (const Mesh& m : meshes)
    if (m.is_point_cloud())
      throw InputError(option + " needs triangle meshes (an input is a point cloud)");
  std::vector<LaplaceBasis> bases;
  for (const Mesh& m : meshes) bases.push_back(laplace_basis(m, functions));
  return bases;
}

SpectralStart spectral_start(const std::vector<Mesh>& meshes,
                             const std::vector<Normalization>& frames, int reference,
                             const SpectralStartOptions& o,
                             const std::vector<LaplaceBasis>* bases) {
  const size_t n = meshes.size();
  JSA_CHECK(frames.size() == n && reference >= 0 && size_t(reference) < n,
            "spectral_start: one frame per mesh, and a reference among them");
  JSA_CHECK(!bases || bases->size() == n, "spectral_start: one basis per mesh");
  std::vector<LaplaceBasis> own;
  if (!bases) {
    own = laplace_bases(meshes, o.functions, "--spectral-map");
    bases = &own;
  }
  SpectralStart out;
  const Mesh& t = meshes[size_t(reference)];
  out.template_vertices = frames[size_t(reference)].to_unit(t.vertices);
  const LaplaceBasis& on_t = (*bases)[size_t(reference)];
  ZoomOutOptions zo = zoomout_options(o);
  out.images.resize(n);
  for (size_t i = 0; i < n; ++i) {
    if (int(i) == reference) continue;
    const Block<double> vertices = frames[i].to_unit(meshes[i].vertices);
    std::vector<int> map;
    nearest(out.template_vertices, vertices, map);  // the start: nearest in space
    if (o.prior_weight > 0) {                       // a template vertex stays near its own place
      zo.prior_weight = o.prior_weight;
      zo.prior_until = o.prior_until;
      zo.prior_on_target = out.template_vertices;
      zo.prior_on_source = vertices;
    }
    // ZoomOut's target is the template (the map is defined on its vertices).
    map = zoomout((*bases)[i], on_t, map, zo);
    out.images[i].resize(Index(map.size()), 3);
    for (size_t v = 0; v < map.size(); ++v) out.images[i].row(Index(v)) = vertices.row(map[v]);
  }
  return out;
}

}  // namespace jsa
