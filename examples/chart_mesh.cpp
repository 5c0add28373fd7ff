// Example: chart a mesh and write it with UVs. A short fit of builtin:sphere,
// then psi maps every vertex of the mesh to the 2D domain (model/tool/chart_mesh.h),
// triangles torn across the cut get their own UV corners, and the mesh is
// written as an OBJ with texture coordinates (io/mesh_io.h).
// Usage: example_chart_mesh [out.obj]. Exits non-zero if the chart is unusable.
#include "model/tool/chart_mesh.h"

#include <cstdio>
#include <exception>
#include <string>

#include "engine/parallel.h"
#include "io/mesh_io.h"
#include "losses/metrics/uv_quality.h"
#include "model/tool/domain_mesh.h"
#include "model/tool/shape_input.h"
#include "model/tool/trainer.h"

using namespace jsa;

int main(int argc, char** argv) try {
  const std::string out_path = argc > 1 ? argv[1] : "chart_sphere.obj";
  // The mesh, its normalisation to the unit ball, and 20000 surface samples.
  const RunInput in = load_run_input("builtin:sphere", 20000, /*seed=*/1);

  FitOptions o;
  o.atlas.gaussians = 256;
  o.atlas.width = 32;
  o.atlas.hidden_layers = 3;
  o.points = 256;
  o.iterations = 1500;
  // Blocks this small are not worth splitting, and on a busy machine an OpenMP
  // team waiting at barriers costs more than the work. The library reads the
  // thread count from OpenMP; applying FitOptions::threads is the caller's job.
  o.threads = 1;
  set_threads(o.threads);
  Trainer trainer(o, in.pool);
  while (!trainer.finished()) trainer.step();
  std::printf("fit: %lld iterations, L_6D %.4f, L_2D %.4f\n",
              static_cast<long long>(trainer.iteration()), trainer.last().surface,
              trainer.last().chart);

  // psi([x, alpha n]) at every vertex, then domain -> [0, 1]^2 texture space.
  Atlas<float>& atlas = trainer.atlas();
  const Block<double> uv = chart_vertices(atlas, in.mesh, in.normalization);
  const UvQuality q = measure_uv_quality(in.mesh.vertices, in.mesh.faces, uv, in.mesh.faces);
  std::printf("%lld faces: %lld torn across the cut, %lld flipped, L2 stretch %.2f\n",
              static_cast<long long>(q.triangles), static_cast<long long>(q.torn),
              static_cast<long long>(q.flipped), q.stretch_l2);
  const SplitUv split = split_torn(atlas, in.mesh, in.normalization, uv, q.torn_faces);
  const Block<double> vt = texture_frame(atlas).to_texture(split.uv);
  write_obj(out_path, in.mesh, &vt, "", "", &split.uv_faces);

  const Mesh back = read_shape(out_path);  // the written file reads back as the same mesh
  std::printf("wrote %s: %lld vertices, %lld texture coordinates, %lld faces\n", out_path.c_str(),
              static_cast<long long>(back.vertices.rows()), static_cast<long long>(vt.rows()),
              static_cast<long long>(back.faces.rows()));
  const bool ok = vt.allFinite() && back.vertices.rows() == in.mesh.vertices.rows() &&
                  back.faces.rows() == in.mesh.faces.rows() && q.torn_area_fraction < 0.2 &&
                  q.flipped_area_fraction < 0.2;
  std::printf("%s\n", ok ? "ok" : "FAILED");
  return ok ? 0 : 1;
} catch (const std::exception& e) {  // JSA_CHECK and InputError throw
  std::fprintf(stderr, "example_chart_mesh: %s\n", e.what());
  return 1;
}
