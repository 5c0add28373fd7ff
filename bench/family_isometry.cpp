// How far from isometric is a family of shapes, and what could distances
// measured along the surface tell about where a keypoint goes? (issue 19,
// docs/collections.md, twenty-fifth round.) L_metric, ZoomOut and the
// geodesic landmarks of `eval-corr --geodesic` all lean on the family being
// near-isometric; this measures how near, from the ground truth alone:
//
//   distortion - for every pair of shapes, the keypoints' distances along the
//                surface (shortest paths on the edges, divided by
//                r = sqrt(A / 4 pi) as the refinement divides them) compared
//                pair by pair: the median of |d_I - d_J| / d_I;
//   oracle     - each keypoint k of I located on J from the *true* images of
//                the other keypoints: the vertex q of J minimising
//                sum_{l != k} w_l (d_J(q, l) - d_I(k, l))^2, w_l = exp(-d_I(k, l) / tau),
//                scored as `jsatlas eval-corr` scores an atlas (L2 in the
//                target's unit frame, mean over keypoints and ordered pairs).
//
// The oracle is a bound for maps built on distances alone: it is given
// landmarks no method has. Usage:
//
//   bench_family_isometry --keypoints ../shared/data/shrec ../shared/data/shrec/ant_{1,2,3,4}.obj
//       [--tau 0.2 --tau 0.5 --tau 0]        (tau 0: every landmark weighs 1)
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "io/geometry/geodesic.h"
#include "io/keypoints.h"
#include "model/tool/shape_input.h"

using namespace jsa;
namespace fs = std::filesystem;

namespace {

struct Shape {
  Block<double> unit_vertices;            // the mesh in its unit frame
  std::vector<int> keypoints;             // vertex indices
  std::vector<std::vector<double>> from;  // from[k][v]: distance keypoint k -> v, over r
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"how isometric a family is, and an oracle locator from distances along the surface"};
  std::vector<std::string> inputs;
  std::string keypoint_dir;
  std::vector<double> taus{0.2, 0.5, 0};
  bool two_ring = false;
  app.add_option("inputs", inputs, "meshes of one category (.vts keypoints beside)")
      ->required()
      ->expected(2, -1);
  app.add_option("--keypoints", keypoint_dir, "folder of NAME.vts")->required();
  app.add_option("--tau", taus, "landmark weight scales of the oracle (0: weight 1)");
  app.add_flag("--two-ring", two_ring,
               "also join the two far corners of every pair of faces sharing an edge "
               "(shorter paths, less of the edges' zigzag)");
  CLI11_PARSE(app, argc, argv);
  const size_t n = inputs.size();

  std::vector<Shape> shapes(n);
  for (size_t i = 0; i < n; ++i) {
    const RunInput in = load_run_input(inputs[i], 2000, 1);
    Shape& s = shapes[i];
    s.unit_vertices = in.normalization.to_unit(in.mesh.vertices);
    const std::string stem = fs::path(inputs[i]).stem().string();
    s.keypoints = read_keypoints((fs::path(keypoint_dir) / (stem + ".vts")).string(),
                                 long(in.mesh.vertices.rows()));
    std::vector<std::pair<int, int>> edges = face_edges(in.mesh);
    if (two_ring) {
      // Paths along edges zigzag: on a regular grid they overestimate by up to
      // 8%, and by a different amount on every triangulation. A straight segment
      // across two faces is a closer stand-in for the geodesic between their far
      // corners.
      std::vector<std::pair<std::pair<int, int>, int>> corner;  // (edge, opposite corner)
      for (Index f = 0; f < in.mesh.faces.rows(); ++f)
        for (int c = 0; c < 3; ++c) {
          const int a = in.mesh.faces(f, c), b = in.mesh.faces(f, (c + 1) % 3);
          corner.push_back({{std::min(a, b), std::max(a, b)}, in.mesh.faces(f, (c + 2) % 3)});
        }
      std::sort(corner.begin(), corner.end());
      for (size_t c = 0; c + 1 < corner.size(); ++c)
        if (corner[c].first == corner[c + 1].first)
          edges.push_back({corner[c].second, corner[c + 1].second});
    }
    const EdgeGraph g = edge_graph(in.mesh.vertices, edges);
    const double r = std::sqrt(surface_area(in.mesh) / (4 * M_PI));
    s.from.resize(s.keypoints.size());
    for (size_t k = 0; k < s.keypoints.size(); ++k) {
      distances_from(g, s.keypoints[k], s.from[k]);
      for (double& d : s.from[k]) d /= r;
    }
    if (s.keypoints.size() != shapes[0].keypoints.size()) {
      std::fprintf(stderr, "%s: %zu keypoints, shape 0 has %zu\n", inputs[i].c_str(),
                   s.keypoints.size(), shapes[0].keypoints.size());
      return 1;
    }
  }
  const size_t K = shapes[0].keypoints.size();

  std::printf("keypoints' distances along the surface, median |d_I - d_J| / d_I (row: I):");
  for (size_t I = 0; I < n; ++I) {
    std::printf("\n  ");
    for (size_t J = 0; J < n; ++J) {
      std::vector<double> rel;
      for (size_t a = 0; a < K; ++a)
        for (size_t b = 0; b < K; ++b) {
          const double dI = shapes[I].from[a][size_t(shapes[I].keypoints[b])];
          const double dJ = shapes[J].from[a][size_t(shapes[J].keypoints[b])];
          if (a != b && dI > 0) rel.push_back(std::abs(dI - dJ) / dI);
        }
      std::nth_element(rel.begin(), rel.begin() + long(rel.size() / 2), rel.end());
      std::printf(" %6.3f", rel.empty() ? 0.0 : rel[rel.size() / 2]);
    }
  }
  std::printf("\n");

  for (double tau : taus) {
    double sum = 0;
    size_t count = 0, within2 = 0, within5 = 0;
    std::vector<double> per_keypoint(K, 0);
    for (size_t I = 0; I < n; ++I)
      for (size_t J = 0; J < n; ++J) {
        if (I == J) continue;
        const Shape& a = shapes[I];
        const Shape& b = shapes[J];
        const Index vertices = b.unit_vertices.rows();
        for (size_t k = 0; k < K; ++k) {
          std::vector<double> target, weight;
          std::vector<const std::vector<double>*> rows;
          for (size_t l = 0; l < K; ++l) {
            if (l == k) continue;
            const double d = a.from[l][size_t(a.keypoints[k])];
            target.push_back(d);
            weight.push_back(tau > 0 ? std::exp(-d / tau) : 1.0);
            rows.push_back(&b.from[l]);
          }
          double best = std::numeric_limits<double>::infinity();
          Index q = 0;
          for (Index v = 0; v < vertices; ++v) {
            double cost = 0;
            for (size_t t = 0; t < rows.size(); ++t) {
              const double e = (*rows[t])[size_t(v)] - target[t];
              cost += weight[t] * e * e;
            }
            if (cost < best) best = cost, q = v;
          }
          const double e = (b.unit_vertices.row(q) - b.unit_vertices.row(b.keypoints[k])).norm();
          sum += e, ++count, per_keypoint[k] += e;
          within2 += e <= 0.02, within5 += e <= 0.05;
        }
      }
    std::printf(
        "oracle, tau %.2f%s: mean %.2f x 1e-2, within 0.02 %.1f%%, within 0.05 %.1f%%;"
        " per keypoint:",
        tau, tau > 0 ? "" : " (weight 1)", 100 * sum / double(count),
        100.0 * double(within2) / double(count), 100.0 * double(within5) / double(count));
    for (double v : per_keypoint) std::printf(" %.1f", 100 * v / double(n * (n - 1)));
    std::printf("\n");
  }
  return 0;
}
