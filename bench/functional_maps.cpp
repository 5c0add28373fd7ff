// How well do maps between the Laplace-Beltrami eigenfunctions of two shapes
// carry a collection's keypoints, without any atlas? (issue 19,
// docs/collections.md, "Intrinsic maps as the layouts' start".) For every
// ordered pair of shapes (I, J), every vertex of I is sent to a vertex of J by
//
//   nearest  - the nearest vertex of J in space (both shapes in the unit frames
//              the pose step of `jsatlas fit` gives them);
//   zoomout  - ZoomOut (io/geometry/functional_map.h) started from `nearest`;
//
// and the keypoints are scored as `jsatlas eval-corr` scores an atlas (mean L2
// in the target's unit frame, over the ordered pairs). Usage:
//
//   bench_functional_maps --keypoints ../shared/data/shrec
//       ../shared/data/shrec/ant_{1,2,3,4}.obj  [--k-end 60 --k-start 6 --k-step 2]
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "bench/timing.h"
#include "io/geometry/functional_map.h"
#include "io/geometry/nearest.h"
#include "io/keypoints.h"
#include "model/tool/correspondence.h"
#include "model/tool/shape_input.h"
#include "model/tool/spectral_start.h"

using namespace jsa;
namespace fs = std::filesystem;

int main(int argc, char** argv) {
  CLI::App app{"keypoint error of spatial and spectral (ZoomOut) vertex maps"};
  std::vector<std::string> inputs;
  std::string keypoint_dir;
  ZoomOutOptions zo;
  int basis = 0;
  uint64_t seed = 1;
  app.add_option("inputs", inputs, "meshes of one category (.vts keypoints beside)")
      ->required()
      ->expected(2, -1);
  app.add_option("--keypoints", keypoint_dir, "folder of NAME.vts")->required();
  app.add_option("--k-start", zo.k_start, "ZoomOut's first size");
  app.add_option("--k-end", zo.k_end, "ZoomOut's last size");
  app.add_option("--k-step", zo.k_step, "ZoomOut's step");
  app.add_flag("--orthogonal", zo.orthogonal, "C projected onto the orthogonal matrices");
  app.add_option("--samples", zo.samples,
                 "ZoomOut's vertices per shape before the last size (0: all)");
  app.add_option("--basis", basis, "eigenfunctions computed (default: k-end)");
  app.add_option("--seed", seed, "pool seed (the unit frames), as jsatlas fit --seed");
  CLI11_PARSE(app, argc, argv);
  if (basis <= 0) basis = zo.k_end;
  const size_t n = inputs.size();

  // The shapes as `jsatlas fit` poses them.
  std::vector<RunInput> shapes;
  for (size_t i = 0; i < n; ++i)
    shapes.push_back(load_run_input(inputs[i], 20000, seed + 1000 * i));
  align_to_first(shapes);
  std::vector<Mesh> meshes;
  std::vector<Normalization> frames;
  std::vector<std::vector<int>> keypoints;
  std::vector<Block<double>> unit_vertices;
  for (size_t i = 0; i < n; ++i) {
    meshes.push_back(shapes[i].mesh);
    frames.push_back(shapes[i].normalization);
    unit_vertices.push_back(frames[i].to_unit(meshes[i].vertices));
    const std::string stem = fs::path(inputs[i]).stem().string();
    keypoints.push_back(read_keypoints((fs::path(keypoint_dir) / (stem + ".vts")).string(),
                                       long(meshes[i].vertices.rows())));
  }

  const auto t0 = bench::Clock::now();
  std::vector<LaplaceBasis> bases;
  for (size_t i = 0; i < n; ++i) bases.push_back(laplace_basis(meshes[i], basis, 1));
  const double basis_seconds = bench::seconds_since(t0);
  std::fprintf(stderr,
               "bases (%d functions, %zu shapes): %.1f s; lambda_1..3 of shape 0: %.2f %.2f %.2f\n",
               basis, n, basis_seconds, bases[0].eigenvalues(1), bases[0].eigenvalues(2),
               bases[0].eigenvalues(3));

  // maps[rule][I][J]: every vertex of I -> a vertex of J.
  std::vector<std::vector<std::vector<std::vector<int>>>> maps(
      2, std::vector<std::vector<std::vector<int>>>(n, std::vector<std::vector<int>>(n)));
  double zoom_seconds = 0;
  for (size_t I = 0; I < n; ++I)
    for (size_t J = 0; J < n; ++J) {
      if (I == J) {  // the self-map (eval-corr's diagonal): the identity
        for (int rule = 0; rule < 2; ++rule) {
          maps[size_t(rule)][I][J].resize(size_t(unit_vertices[I].rows()));
          for (size_t v = 0; v < maps[size_t(rule)][I][J].size(); ++v)
            maps[size_t(rule)][I][J][v] = int(v);
        }
        continue;
      }
      nearest(unit_vertices[I], unit_vertices[J], maps[0][I][J]);
      const auto z0 = bench::Clock::now();
      // ZoomOut's target is I (the map is defined on I's vertices), its source J.
      maps[1][I][J] = zoomout(bases[J], bases[I], maps[0][I][J], zo);
      zoom_seconds += bench::seconds_since(z0);
    }
  std::fprintf(stderr, "ZoomOut %d..%d step %d: %.1f s for %zu pairs\n", zo.k_start, zo.k_end,
               zo.k_step, zoom_seconds, n * (n - 1));

  const char* names[] = {"nearest in space", "ZoomOut"};
  for (int rule = 0; rule < 2; ++rule) {
    const CorrespondenceMap map = [&](int from, int to, const Block<double>& p,
                                      const Block<double>&) {
      std::vector<int> at;
      nearest(p, unit_vertices[size_t(from)], at);
      Block<double> q(p.rows(), 3);
      for (Index r = 0; r < p.rows(); ++r)
        q.row(r) = unit_vertices[size_t(to)].row(
            maps[size_t(rule)][size_t(from)][size_t(to)][size_t(at[size_t(r)])]);
      return q;
    };
    const KeypointError e = keypoint_error(map, meshes, frames, keypoints);
    std::printf("%-18s mean %.2f x 1e-2, within 0.02 %.1f%%, within 0.05 %.1f%%; per keypoint:",
                names[rule], 100 * e.mean, 100 * e.within[1], 100 * e.within[2]);
    for (double v : e.keypoint_mean) std::printf(" %.1f", 100 * v);
    std::printf("\n  pairs (row: from):");
    for (size_t I = 0; I < n; ++I) {
      std::printf("\n   ");
      for (size_t J = 0; J < n; ++J) std::printf(" %6.2f", 100 * e.pair_mean[I][J]);
    }
    std::printf("\n");
  }
  // What a map shows of itself without keypoints (issue 19: a start chosen per
  // collection must be judged before any label is seen). Per rule, over the
  // ordered pairs: the round trip T_JI(T_IJ(v)) against v, the triangle
  // T_JK(T_IJ(v)) against T_IK(v), and I's edges torn (stretched more than 4x
  // their length, or more than 0.1 of the unit radius) or collapsed (onto one
  // vertex of J), every distance in the target's unit frame.
  for (int rule = 0; rule < 2; ++rule) {
    const auto& m = maps[size_t(rule)];
    double trip = 0, triangle = 0, torn = 0, collapsed = 0;
    int pairs = 0, triangles = 0;
    for (size_t I = 0; I < n; ++I)
      for (size_t J = 0; J < n; ++J) {
        if (I == J) continue;
        const Block<double>& xi = unit_vertices[I];
        const Block<double>& xj = unit_vertices[J];
        double s = 0;
        for (Index v = 0; v < xi.rows(); ++v)
          s += (xi.row(m[J][I][size_t(m[I][J][size_t(v)])]) - xi.row(v)).norm();
        trip += s / double(xi.rows());
        Index edges = 0, tears = 0, folds = 0;
        for (Index f = 0; f < meshes[I].faces.rows(); ++f)
          for (int c = 0; c < 3; ++c) {
            const int a = meshes[I].faces(f, c), b = meshes[I].faces(f, (c + 1) % 3);
            const double before = (xi.row(a) - xi.row(b)).norm();
            const double after = (xj.row(m[I][J][size_t(a)]) - xj.row(m[I][J][size_t(b)])).norm();
            ++edges;
            if (after > std::max(4 * before, 0.1)) ++tears;
            if (after == 0) ++folds;
          }
        torn += double(tears) / double(edges);
        collapsed += double(folds) / double(edges);
        ++pairs;
        for (size_t K = 0; K < n; ++K) {
          if (K == I || K == J) continue;
          double t = 0;
          for (Index v = 0; v < xi.rows(); ++v)
            t += (unit_vertices[K].row(m[J][K][size_t(m[I][J][size_t(v)])]) -
                  unit_vertices[K].row(m[I][K][size_t(v)]))
                     .norm();
          triangle += t / double(xi.rows());
          ++triangles;
        }
      }
    std::printf(
        "%-18s label-free: round trip %.2f x 1e-2, triangle %.2f x 1e-2, edges torn %.2f%%, "
        "collapsed %.1f%%\n",
        names[rule], 100 * trip / pairs, triangles ? 100 * triangle / triangles : 0.0,
        100 * torn / pairs, 100 * collapsed / pairs);
  }
  // The same through spectral_start (what `jsatlas fit --spectral-map` uses),
  // from each template t: t's keypoints carried to every other shape.
  for (int t = 0; t < int(n); ++t) {
    const SpectralStart st = spectral_start(meshes, frames, t);
    std::printf("spectral_start from shape %d:", t);
    for (size_t J = 0; J < n; ++J) {
      if (int(J) == t) continue;
      double sum = 0;
      for (size_t m = 0; m < keypoints[size_t(t)].size(); ++m)
        sum += (st.images[J].row(keypoints[size_t(t)][m]) - unit_vertices[J].row(keypoints[J][m]))
                   .norm();
      std::printf(" to %zu: %.2f;", J, 100 * sum / double(keypoints[size_t(t)].size()));
    }
    std::printf("\n");
  }
  return 0;
}
