#include "model/tool/spectral_refinement.h"

#include <limits>
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
  if (o.consensus && meshes.size() < 3)
    throw InputError("the spectral consensus needs three or more shapes (--spectral-consensus; " +
                     std::to_string(meshes.size()) + " given)");
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
  const bool consensus = o.consensus;
  return [r, both, consensus](int from, int to, const Block<double>& p, const Block<double>& n) {
    const Block<double>& unit_j = r->shapes[size_t(to)].unit;
    std::vector<int> at;
    nearest(p, r->shapes[size_t(from)].unit, at);
    // T_IJ(x) through the vertex map, for x at the vertices `at` of I.
    auto carried = [&](const std::vector<int>& map) {
      Block<double> q(p.rows(), 3);
      for (Index m = 0; m < p.rows(); ++m) q.row(m) = unit_j.row(map[size_t(at[size_t(m)])]);
      return q;
    };
    Block<double> q = carried(r->vertex_map(from, to));
    if (!both && !consensus) return q;
    // The other direction's map, inverted by nearest images: the vertex y of
    // J whose T_JI(y) is nearest p.
    const std::vector<int>& back = r->vertex_map(to, from);
    const Block<double>& unit_i = r->shapes[size_t(from)].unit;
    Block<double> images(Index(back.size()), 3);
    for (size_t y = 0; y < back.size(); ++y) images.row(Index(y)) = unit_i.row(back[y]);
    std::vector<int> inverse;
    nearest(p, images, inverse);
    const Block<double> own = r->base(from, to, p, n);
    if (!consensus) {
      for (Index m = 0; m < p.rows(); ++m) {
        const auto other = unit_j.row(inverse[size_t(m)]);
        if ((other - own.row(m)).norm() < (q.row(m) - own.row(m)).norm()) q.row(m) = other;
      }
      return q;
    }
    std::vector<Block<double>> estimates{own, q, Block<double>(p.rows(), 3)};
    for (Index m = 0; m < p.rows(); ++m) estimates[2].row(m) = unit_j.row(inverse[size_t(m)]);
    for (int k = 0; k < int(r->shapes.size()); ++k) {
      if (k == from || k == to) continue;
      const std::vector<int>& ik = r->vertex_map(from, k);
      const std::vector<int>& kj = r->vertex_map(k, to);
      Block<double> through(p.rows(), 3);
      for (Index m = 0; m < p.rows(); ++m)
        through.row(m) = unit_j.row(kj[size_t(ik[size_t(at[size_t(m)])])]);
      estimates.push_back(std::move(through));
    }
    for (Index m = 0; m < p.rows(); ++m) {
      double best = std::numeric_limits<double>::infinity();
      for (const Block<double>& e : estimates) {
        double sum = 0;  // the estimate's summed distance to the others
        for (const Block<double>& f : estimates) sum += (e.row(m) - f.row(m)).norm();
        if (sum < best) {
          best = sum;
          q.row(m) = e.row(m);
        }
      }
    }
    return q;
  };
}

}  // namespace jsa
