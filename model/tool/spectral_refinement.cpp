#include "model/tool/spectral_refinement.h"

#include <map>
#include <memory>

#include "engine/check.h"
#include "io/geometry/functional_map.h"
#include "io/geometry/nearest.h"

namespace jsa {

namespace {

struct Shape {
  Block<double> unit, normals;  // vertices and unit normals in the unit frame
  LaplaceBasis basis;           // empty until a pair needs it
};

struct Refinement {
  CorrespondenceMap base;
  std::vector<Mesh> meshes;
  std::vector<Shape> shapes;
  ZoomOutOptions zoomout;
  int functions = 0;
  std::map<std::pair<int, int>, std::vector<int>> maps;  // (I, J) -> vertex of J per vertex of I

  const Shape& shape(int s) {
    Shape& out = shapes[size_t(s)];
    if (out.basis.functions.size() == 0)
      out.basis = laplace_basis(meshes[size_t(s)], functions, zoomout.seed);
    return out;
  }

  const std::vector<int>& vertex_map(int from, int to) {
    auto it = maps.find({from, to});
    if (it != maps.end()) return it->second;
    const Shape& i = shape(from);
    const Shape& j = shape(to);
    std::vector<int> map;
    const Block<double> images = base(from, to, i.unit, i.normals);
    nearest(images, j.unit, map);  // the start: the atlas's map
    ZoomOutOptions o = zoomout;
    if (o.prior_weight > 0) {
      o.prior_on_target = images;
      o.prior_on_source = j.unit;
    }
    // ZoomOut's target is the shape the map is defined on: I.
    map = jsa::zoomout(j.basis, i.basis, map, o);
    return maps.emplace(std::make_pair(from, to), std::move(map)).first->second;
  }
};

}  // namespace

CorrespondenceMap spectral_refinement(CorrespondenceMap base, const std::vector<Mesh>& meshes,
                                      const std::vector<Normalization>& frames,
                                      const SpectralRefinementOptions& o) {
  JSA_CHECK(frames.size() == meshes.size(), "spectral_refinement: one frame per mesh");
  auto r = std::make_shared<Refinement>();
  r->base = std::move(base);
  r->zoomout.k_start = o.k_start;
  r->zoomout.k_end = o.functions;
  r->zoomout.k_step = o.k_step;
  r->zoomout.samples = o.samples;
  r->zoomout.seed = o.seed;
  r->zoomout.orthogonal = true;
  r->zoomout.prior_weight = o.prior_weight;
  r->zoomout.prior_until = o.prior_until;
  for (size_t s = 0; s < meshes.size(); ++s) {
    if (meshes[s].is_point_cloud())
      throw InputError("the spectral refinement needs triangle meshes (shape " + std::to_string(s) +
                       " is a point cloud)");
    if (meshes[s].vertices.rows() < Index(o.functions))
      throw InputError("the spectral refinement: shape " + std::to_string(s) + " has " +
                       std::to_string(meshes[s].vertices.rows()) + " vertices, fewer than " +
                       std::to_string(o.functions) + " eigenfunctions (--spectral-functions)");
    Shape shape;
    shape.unit = frames[s].to_unit(meshes[s].vertices);
    shape.normals = frames[s].normals_to_unit(vertex_normals_of(meshes[s]));
    r->shapes.push_back(std::move(shape));
  }
  r->meshes = meshes;
  r->functions = o.functions;
  const bool both = o.both_directions;
  return [r, both](int from, int to, const Block<double>& p, const Block<double>& n) {
    const std::vector<int>& map = r->vertex_map(from, to);
    std::vector<int> at;
    nearest(p, r->shapes[size_t(from)].unit, at);
    Block<double> q(p.rows(), 3);
    for (Index m = 0; m < p.rows(); ++m)
      q.row(m) = r->shapes[size_t(to)].unit.row(map[size_t(at[size_t(m)])]);
    if (both) {
      // The other direction's map, inverted by nearest images: T_JI(y) for
      // every vertex y of J, searched for the points p.
      const std::vector<int>& back = r->vertex_map(to, from);
      const Block<double>& unit_i = r->shapes[size_t(from)].unit;
      Block<double> images(Index(back.size()), 3);
      for (size_t y = 0; y < back.size(); ++y) images.row(Index(y)) = unit_i.row(back[y]);
      std::vector<int> inverse;
      nearest(p, images, inverse);
      const Block<double> own = r->base(from, to, p, n);
      for (Index m = 0; m < p.rows(); ++m) {
        const auto other = r->shapes[size_t(to)].unit.row(inverse[size_t(m)]);
        if ((other - own.row(m)).norm() < (q.row(m) - own.row(m)).norm()) q.row(m) = other;
      }
    }
    return q;
  };
}

}  // namespace jsa
