#include "model/tool/geodesic_refinement.h"

#include <cmath>
#include <limits>
#include <map>
#include <memory>

#include "engine/check.h"
#include "engine/parallel.h"
#include "io/geometry/geodesic.h"
#include "io/geometry/nearest.h"

namespace jsa {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct Shape {
  Block<double> unit, normals;   // vertices and unit normals in the unit frame
  EdgeGraph graph;               // edges in the unit frame
  double radius = 1;             // r = sqrt(A / 4 pi), in the unit frame
  std::vector<int> landmarks;    // l_k, vertices
  Block<double> from_landmarks;  // V x K: d(v, l_k) / r
};

struct Pair {
  std::vector<int> kept;  // the landmarks of I in the pair
  Block<double> to;       // V_J x kept: d_J(q, T(l_k)) / r_J
};

// Distances of every node from each source, divided by r, as columns.
Block<double> distance_columns(const EdgeGraph& g, const std::vector<int>& sources, double r) {
  Block<double> out(g.size(), Index(sources.size()));
  parallel_rows(
      Index(sources.size()),
      [&](Index begin, Index end) {
        std::vector<double> d;
        for (Index k = begin; k < end; ++k) {
          distances_from(g, sources[size_t(k)], d);
          // Out of reach (another component): as far as the farthest reached node.
          double far = 0;
          for (double x : d)
            if (x < kInf) far = std::max(far, x);
          for (Index v = 0; v < g.size(); ++v)
            out(v, k) = (d[size_t(v)] < kInf ? d[size_t(v)] : far) / r;
        }
      },
      1);
  return out;
}

struct Refinement {
  CorrespondenceMap base;
  GeodesicRefinementOptions options;
  std::vector<Shape> shapes;
  std::map<std::pair<int, int>, Pair> pairs;

  Shape& shape(int s) {
    Shape& out = shapes[size_t(s)];
    if (out.landmarks.empty()) {
      std::vector<std::vector<double>> unused;
      out.landmarks = farthest_nodes(out.graph, options.landmarks, unused);
      out.from_landmarks = distance_columns(out.graph, out.landmarks, out.radius);
    }
    return out;
  }

  const Pair& pair(int from, int to) {
    auto it = pairs.find({from, to});
    if (it != pairs.end()) return it->second;
    const Shape& i = shape(from);
    const Shape& j = shapes[size_t(to)];
    const Index k = Index(i.landmarks.size());
    Block<double> points(k, 3), normals(k, 3);
    for (Index m = 0; m < k; ++m) {
      points.row(m) = i.unit.row(i.landmarks[size_t(m)]);
      normals.row(m) = i.normals.row(i.landmarks[size_t(m)]);
    }
    const Block<double> images = base(from, to, points, normals);
    std::vector<int> at;
    nearest(images, j.unit, at);
    Pair p;
    std::vector<int> sources;
    Block<double> back;
    if (options.cycle_tolerance > 0) {
      Block<double> image_normals(k, 3);
      for (Index m = 0; m < k; ++m) image_normals.row(m) = j.normals.row(at[size_t(m)]);
      Block<double> on_j(k, 3);
      for (Index m = 0; m < k; ++m) on_j.row(m) = j.unit.row(at[size_t(m)]);
      back = base(to, from, on_j, image_normals);
    }
    for (Index m = 0; m < k; ++m) {
      if (options.cycle_tolerance > 0 &&
          (back.row(m) - points.row(m)).norm() > options.cycle_tolerance)
        continue;
      p.kept.push_back(int(m));
      sources.push_back(at[size_t(m)]);
    }
    if (p.kept.empty())  // no landmark survives: keep them all rather than none
      for (Index m = 0; m < k; ++m) {
        p.kept.push_back(int(m));
        sources.push_back(at[size_t(m)]);
      }
    p.to = distance_columns(j.graph, sources, j.radius);
    return pairs.emplace(std::make_pair(from, to), std::move(p)).first->second;
  }
};

}  // namespace

CorrespondenceMap geodesic_refinement(CorrespondenceMap base, const std::vector<Mesh>& meshes,
                                      const std::vector<Normalization>& frames,
                                      const GeodesicRefinementOptions& o) {
  JSA_CHECK(frames.size() == meshes.size(), "geodesic_refinement: one frame per mesh");
  JSA_CHECK(o.landmarks >= 1 && o.tau >= 0 && o.cycle_tolerance >= 0,
            "geodesic_refinement: landmarks >= 1, tau and cycle_tolerance >= 0");
  auto r = std::make_shared<Refinement>();
  r->base = std::move(base);
  r->options = o;
  for (size_t s = 0; s < meshes.size(); ++s) {
    if (meshes[s].is_point_cloud())
      throw InputError("the geodesic refinement needs triangle meshes (shape " + std::to_string(s) +
                       " is a point cloud)");
    Shape shape;
    shape.unit = frames[s].to_unit(meshes[s].vertices);
    shape.normals = frames[s].normals_to_unit(vertex_normals_of(meshes[s]));
    shape.graph = edge_graph(shape.unit, face_edges(meshes[s]));
    shape.radius = std::sqrt(surface_area(meshes[s]) / (4 * M_PI)) / frames[s].scale;
    if (!(shape.radius > 0))
      throw InputError("the geodesic refinement: shape " + std::to_string(s) + " has no area");
    r->shapes.push_back(std::move(shape));
  }
  return [r](int from, int to, const Block<double>& p, const Block<double>&) {
    const Pair& pair = r->pair(from, to);
    const Shape& i = r->shapes[size_t(from)];
    const Shape& j = r->shapes[size_t(to)];
    const double tau = r->options.tau;
    std::vector<int> at;
    nearest(p, i.unit, at);
    Block<double> q(p.rows(), 3);
    parallel_rows(
        p.rows(),
        [&](Index begin, Index end) {
          const Index kept = Index(pair.kept.size());
          Eigen::RowVectorXd s(kept), w(kept);
          for (Index m = begin; m < end; ++m) {
            for (Index k = 0; k < kept; ++k) {
              s(k) = i.from_landmarks(at[size_t(m)], pair.kept[size_t(k)]);
              w(k) = tau > 0 ? std::exp(-s(k) / tau) : 1.0;
            }
            Index best = 0;
            double least = kInf;
            for (Index v = 0; v < j.unit.rows(); ++v) {
              const double cost = (w.array() * (pair.to.row(v) - s).array().square()).sum();
              if (cost < least) {
                least = cost;
                best = v;
              }
            }
            q.row(m) = j.unit.row(best);
          }
        },
        1);
    return q;
  };
}

}  // namespace jsa
