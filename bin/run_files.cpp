#include "bin/run_files.h"

#include <iostream>

#include <nlohmann/json.hpp>

#include "io/mesh_io.h"
#include "model/domain_mesh.h"

namespace jsa::cli {

std::string json_quote(const std::string& s) { return nlohmann::json(s).dump(); }

void write_run_outputs(Atlas<float>& atlas, const RunInput& input, const std::string& dir,
                       int mesh_resolution, double mesh_threshold, bool quiet) {
  DomainMesh dm = mesh_domain(atlas, DomainMeshOptions{mesh_resolution, mesh_threshold});
  Mesh out;
  Block<double> points, normals;
  evaluate_surface(atlas, dm.uv, points, normals);
  out.vertices = input.normalization.from_unit(points);
  out.normals = normals;
  out.faces = dm.faces;
  Block<double> vt(dm.uv.rows(), 2);
  const Eigen::RowVector2d extent = dm.hi - dm.lo;
  const double side = std::max(extent(0), extent(1));
  for (Index i = 0; i < dm.uv.rows(); ++i) vt.row(i) = (dm.uv.row(i) - dm.lo) / side;
  write_obj(dir + "/domain_mesh.obj", out, &vt);
  if (!quiet)
    std::cerr << "mesh: " << dir << "/domain_mesh.obj  (" << out.vertices.rows() << " vertices, "
              << out.faces.rows() << " triangles; the domain holds " << int(100 * dm.mass_fraction + 0.5)
              << "% of P's mass)\n";
}

}  // namespace jsa::cli
