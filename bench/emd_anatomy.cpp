// Where a fit's EMD gap comes from (issue 21). The EMD of `jsatlas eval`
// (samples through P and phi against samples of the shape, an exact
// assignment) exceeds its floor for three reasons this program tells apart:
//   - density: phi spreads P's samples unevenly over a surface it fits well
//     (what L_even, losses/evenness.h, measures: Var log q, q = p / |J_u x J_v|);
//   - layers: two parts of the domain map onto one part of the surface, which
//     q cannot see (it is local); phi's area counted with its layers,
//     E_{x~P}[|J| / p] = integral of |J| dx, then exceeds the surface's;
//   - misfit: somewhere the reconstruction is not on the surface, so the
//     samples there belong to other cells.
// The surface is cut into S cells (the Voronoi cells of S samples of it); N
// samples through P and phi and N fresh samples of the shape are counted per
// cell. A cell holding less than half its share is under-covered; how far the
// reconstruction is from its centre (against 20 N samples through phi) says
// whether it is a misfit or only sparse.
//   bench_emd_anatomy RUN [--samples N] [--cells S] [--seed S]
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "engine/parallel.h"
#include "io/geometry/nearest.h"
#include "io/geometry/surface_sampling.h"
#include "model/tool/checkpoint.h"
#include "model/tool/shape_input.h"

namespace {

double surface_area(const jsa::Mesh& m) {
  double area = 0;
  for (jsa::Index f = 0; f < m.faces.rows(); ++f) {
    const Eigen::RowVector3d a = m.vertices.row(m.faces(f, 0)), b = m.vertices.row(m.faces(f, 1)),
                             c = m.vertices.row(m.faces(f, 2));
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  return area;
}

std::vector<int> cell_counts(const std::vector<int>& cell_of, jsa::Index cells) {
  std::vector<int> count(size_t(cells), 0);
  for (int c : cell_of) ++count[size_t(c)];
  return count;
}

}  // namespace

int main(int argc, char** argv) try {
  CLI::App app{"Where a fit's EMD gap comes from: density, layers or misfit, per surface cell"};
  std::string run;
  jsa::Index samples = 40000, cells = 1000;
  uint64_t seed = 7;
  app.add_option("run", run, "A single-shape run directory (model.ckpt)")->required();
  app.add_option("--samples", samples, "N: samples through P and phi, and of the shape")
      ->check(CLI::Range(1000, 10000000));
  app.add_option("--cells", cells, "S: surface cells")->check(CLI::Range(10, 100000));
  app.add_option("--seed", seed, "Seed of every draw");
  CLI11_PARSE(app, argc, argv);

  const std::string ckpt = (std::filesystem::path(run) / "model.ckpt").string();
  const jsa::CheckpointContents contents = jsa::read_checkpoint(ckpt);
  auto atlas = jsa::load_atlas(contents, ckpt);
  const jsa::Mesh shape = jsa::load_shape(contents.inputs[0]);
  if (shape.is_point_cloud()) throw jsa::InputError("the shape is a point cloud: no area");
  const jsa::Normalization& unit = contents.normalizations[0];
  const double area = surface_area(shape) / (unit.scale * unit.scale);

  // Samples through P and phi, with P's density p and phi's area element |J|.
  jsa::Rng fit_rng(seed, 1);
  jsa::Block<double> uv, fit, fit_normals, du, dv, again, again_normals;
  jsa::sample_reconstruction(*atlas, samples, fit_rng, uv, fit, fit_normals);
  jsa::evaluate_surface(*atlas, uv, again, again_normals, 0, &du, &dv);
  const std::vector<double> p = atlas->domain.density(atlas->params, uv);
  std::vector<double> log_q;
  double layered_area = 0;  // E_{x~P}[|J| / p]
  for (jsa::Index i = 0; i < samples; ++i) {
    const Eigen::RowVector3d ju = du.row(i), jv = dv.row(i);
    const double j = ju.cross(jv).norm();
    if (!(j > 0) || !(p[size_t(i)] > 0)) continue;
    layered_area += j / p[size_t(i)];
    log_q.push_back(std::log(p[size_t(i)] / j));
  }
  layered_area /= double(samples);
  double mean = 0, var = 0;
  for (double l : log_q) mean += l;
  mean /= double(log_q.size());
  for (double l : log_q) var += (l - mean) * (l - mean);
  var /= double(log_q.size());

  // Cells, and what each holds.
  jsa::Rng cell_rng(seed, 2), ref_rng(seed, 3), dense_rng(seed, 4);
  const jsa::SurfaceSamples centres = jsa::sample_surface(shape, cells, cell_rng);
  const jsa::SurfaceSamples reference = jsa::sample_surface(shape, samples, ref_rng);
  const jsa::Block<double> centre = unit.to_unit(centres.points);
  std::vector<int> fit_cell, ref_cell;
  jsa::nearest(fit, centre, fit_cell);
  jsa::nearest(unit.to_unit(reference.points), centre, ref_cell);
  const std::vector<int> fit_count = cell_counts(fit_cell, cells),
                         ref_count = cell_counts(ref_cell, cells);
  // The reconstruction's distance to each centre, against 20 N samples (about
  // a fifth of the spacing of N).
  jsa::Block<double> dense_uv, dense, dense_normals;
  jsa::sample_reconstruction(*atlas, 20 * samples, dense_rng, dense_uv, dense, dense_normals);
  std::vector<int> unused;
  std::vector<double> gap2;
  jsa::nearest(centre, dense, unused, &gap2);
  std::vector<double> gap(gap2.size());
  for (size_t s = 0; s < gap.size(); ++s) gap[s] = std::sqrt(gap2[s]);
  std::vector<double> sorted_gap = gap;
  std::sort(sorted_gap.begin(), sorted_gap.end());
  const double median_gap = sorted_gap[sorted_gap.size() / 2];

  // A cell's thickness: the distance from its centre to the nearest sample of
  // the shape whose normal faces the other way (n . n' < -1/2): small on legs
  // and antennae.
  const jsa::Block<double> reference_points = unit.to_unit(reference.points),
                           reference_normals = unit.normals_to_unit(reference.normals),
                           centre_normals = unit.normals_to_unit(centres.normals);
  std::vector<double> thickness(size_t(cells), 1e30);
#pragma omp parallel for schedule(static)
  for (jsa::Index s = 0; s < cells; ++s)
    for (jsa::Index i = 0; i < samples; ++i)
      if (reference_normals.row(i).dot(centre_normals.row(s)) < -0.5)
        thickness[size_t(s)] =
            std::min(thickness[size_t(s)], (reference_points.row(i) - centre.row(s)).norm());
  std::vector<double> sorted_thickness = thickness;
  std::sort(sorted_thickness.begin(), sorted_thickness.end());
  const double thin = sorted_thickness[sorted_thickness.size() / 4];

  double tv = 0, under_mass = 0, over_mass = 0, under_gap = 0, under_radius = 0, radius = 0;
  int under = 0, under_misfit = 0, under_thin = 0;
  for (jsa::Index s = 0; s < cells; ++s) {
    const double f = fit_count[size_t(s)], r = ref_count[size_t(s)];
    tv += std::abs(f - r);
    radius += centre.row(s).norm();
    if (r > 0 && f < 0.5 * r) {
      under_radius += centre.row(s).norm();
      if (thickness[size_t(s)] < thin) ++under_thin;
      under_mass += r;
      under_gap += gap[size_t(s)];
      ++under;
      if (gap[size_t(s)] > 3 * median_gap) ++under_misfit;
    }
    if (f > 2 * r) over_mass += f;
  }
  std::printf("surface area (unit frame)           %.4f\n", area);
  std::printf("phi's area with its layers          %.4f  (%.3fx the surface's)\n", layered_area,
              layered_area / area);
  std::printf("Var log q (L_even's quantity)       %.4f\n", var);
  std::printf("total variation per cell            %.3f\n", 0.5 * tv / double(samples));
  std::printf(
      "surface in under-covered cells      %.3f  (%d cells of %lld, below half their share)\n",
      under_mass / double(samples), under, (long long)cells);
  std::printf("samples in over-covered cells       %.3f  (above twice their share)\n",
              over_mass / double(samples));
  std::printf("reconstruction's gap to a centre    median %.4f, under-covered cells %.4f\n",
              median_gap, under ? under_gap / under : 0.0);
  std::printf("under-covered cells that are misfit %d of %d  (gap > 3x the median)\n", under_misfit,
              under);
  std::printf("under-covered cells' mean radius    %.3f  (every cell's %.3f)\n",
              under ? under_radius / under : 0.0, radius / double(cells));
  std::printf("under-covered cells among the thinnest quarter  %d of %d\n", under_thin, under);
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "bench_emd_anatomy: %s\n", e.what());
  return 1;
}
