#include "bin/run_files.h"

#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>

#include "io/atomic_write.h"
#include "io/mesh_io.h"
#include "io/raster.h"
#include "losses/uv_quality.h"
#include "model/chart_mesh.h"
#include "model/domain_mesh.h"
#include "model/pictures.h"

namespace jsa::cli {
namespace {

namespace fs = std::filesystem;

std::string stem_of(const std::string& obj_path) {
  const fs::path p(obj_path);
  return (p.parent_path() / p.stem()).string();
}

// OUT.mtl and its texture next to OUT.obj: the built-in colour chart, or the
// user's image (`user_texture`) re-encoded as PNG, so the directory is
// self-contained. Returns the MTL's file name.
std::string write_material(const std::string& obj_path, const std::string& user_texture) {
  const fs::path p(obj_path);
  const fs::path dir = p.parent_path().empty() ? fs::path(".") : p.parent_path();
  std::string texture = "jsatlas_texture.png";
  if (user_texture.empty()) {
    write_png((dir / texture).string(), colour_chart(1024));
  } else {
    texture = fs::path(user_texture).stem().string() + "_texture.png";
    write_png((dir / texture).string(), read_image(user_texture));
  }
  const std::string mtl = p.stem().string() + ".mtl";
  write_mtl((dir / mtl).string(), "atlas", texture);
  return mtl;
}

void write_report(const std::string& path, const UvQuality& q, const nlohmann::json& extra) {
  nlohmann::json j = nlohmann::json::parse(to_json(q));
  for (auto it = extra.begin(); it != extra.end(); ++it) j[it.key()] = it.value();
  write_file_atomically(path, [&](std::ostream& out) { out << j.dump(2) << "\n"; });
}

}  // namespace

std::string json_quote(const std::string& s) { return nlohmann::json(s).dump(); }

void write_domain_mesh(Atlas<float>& atlas, const Normalization& normalization,
                       const std::string& obj_path, const MeshOutputOptions& o, int shape) {
  const DomainMesh dm = mesh_domain(atlas, DomainMeshOptions{o.resolution, o.threshold});
  if (dm.faces.rows() == 0)
    throw InputError("mesh: no domain above the threshold " + std::to_string(o.threshold) +
                     " (lower --threshold)");
  Mesh out;
  Block<double> points, normals;
  evaluate_surface(atlas, dm.uv, points, normals, shape);
  out.vertices = normalization.from_unit(points);
  out.normals = normalization.normals_from_unit(normals);
  out.faces = dm.faces;
  const Block<double> vt = texture_frame(atlas).to_texture(dm.uv);
  write_obj(obj_path, out, &vt, write_material(obj_path, o.texture), "atlas");
  const std::string stem = stem_of(obj_path);
  const UvQuality q = measure_uv_quality(out.vertices, out.faces, vt, out.faces);
  write_report(stem + "_uv.json", q,
               {{"domain_mass_fraction", dm.mass_fraction},
                {"threshold", o.threshold},
                {"level", dm.level},
                {"map", "domain uv -> phi (3D)"}});
  write_png(stem + ".png", domain_coloured_views(out.vertices, out.faces, vt));
  if (!o.quiet) {
    std::cerr << "mesh: " << obj_path << "  (" << out.vertices.rows() << " vertices, "
              << out.faces.rows() << " triangles; the domain holds "
              << int(100 * dm.mass_fraction + 0.5) << "% of P's mass)\n";
    std::cerr << to_text(q);
  }
}

void write_chart(Atlas<float>& atlas, const Normalization& normalization, const Mesh& mesh,
                 const std::string& obj_path, const ChartOutputOptions& o, int shape) {
  if (mesh.faces.rows() == 0)
    throw InputError("chart: the input has no faces (a point cloud has no UV map to write)");
  const Block<double> uv = chart_vertices(atlas, mesh, normalization, shape);
  const TextureFrame frame = texture_frame(atlas);
  Block<double> vt = frame.to_texture(uv);
  UvQualityOptions qo;
  qo.torn_ratio = o.torn_ratio;
  UvQuality q = measure_uv_quality(mesh.vertices, mesh.faces, vt, mesh.faces, qo);
  Faces uv_faces = mesh.faces;
  const Index torn_before = q.torn;
  if (o.split_cuts && q.torn > 0) {
    SplitUv split = split_torn(atlas, mesh, normalization, uv, q.torn_faces, shape);
    vt = frame.to_texture(split.uv);
    uv_faces = split.uv_faces;
    q = measure_uv_quality(mesh.vertices, mesh.faces, vt, uv_faces, qo);
  }
  write_obj(obj_path, mesh, &vt, write_material(obj_path, o.texture), "atlas",
            o.split_cuts ? &uv_faces : nullptr);
  const std::string stem = stem_of(obj_path);
  write_report(stem + "_uv.json", q,
               {{"map", "input mesh -> psi (2D); measured as uv -> 3D"},
                {"split_cuts", o.split_cuts},
                {"torn_before_split", torn_before}});
  const Block<double> vertex_vt = frame.to_texture(uv);
  write_png(stem + ".png", domain_coloured_views(mesh.vertices, mesh.faces, vertex_vt));
  write_png(stem + "_layout.png", uv_layout_picture(mesh.vertices, mesh.faces, vt, uv_faces,
                                                    q.flipped_faces, q.torn_faces));
  if (!o.quiet) {
    std::cerr << "chart: " << obj_path << "  (" << mesh.vertices.rows() << " vertices, "
              << mesh.faces.rows() << " faces in the input's order; " << torn_before
              << " torn across the cut" << (o.split_cuts ? ", split" : "") << ")\n";
    std::cerr << to_text(q);
  }
}

void write_run_outputs(Atlas<float>& atlas, const std::vector<RunInput>& inputs, const LossLog& log,
                       const std::string& dir, const MeshOutputOptions& mesh) {
  const bool collection = inputs.size() > 1;
  // Read once up front: a bad texture fails before anything is written.
  const Image texture = mesh.texture.empty() ? Image() : read_image(mesh.texture);
  std::vector<Image> coloured, textured;
  std::vector<std::string> captions;
  for (size_t i = 0; i < inputs.size(); ++i) {
    const std::string sub = collection ? dir + "/shape_" + std::to_string(i) : dir;
    if (collection) {
      fs::create_directories(sub);
      if (!mesh.quiet) std::cerr << "shape " << i << ":\n";
    }
    write_domain_mesh(atlas, inputs[i].normalization, sub + "/domain_mesh.obj", mesh, int(i));
    if (inputs[i].mesh.faces.rows() > 0) {
      ChartOutputOptions co;
      co.quiet = mesh.quiet;
      co.texture = mesh.texture;
      write_chart(atlas, inputs[i].normalization, inputs[i].mesh, sub + "/input_chart.obj", co,
                  int(i));
      // One view per shape, coloured by its position in the shared domain
      // (and, with a texture, textured through its chart).
      const Mesh& m = inputs[i].mesh;
      const Block<double> vt = texture_frame(atlas).to_texture(
          chart_vertices(atlas, m, inputs[i].normalization, int(i)));
      if (collection) coloured.push_back(domain_coloured_views(m.vertices, m.faces, vt, 320));
      if (texture.width > 0)
        textured.push_back(textured_views(m.vertices, m.faces, vt, texture, 320));
      captions.push_back("shape " + std::to_string(i));
    }
  }
  if (collection && !coloured.empty()) {
    GridOptions g;
    g.columns = 1;
    g.captions = captions;
    write_png(dir + "/collection.png", compose_grid(coloured, g));
  }
  if (!textured.empty()) {
    GridOptions g;
    g.columns = 1;
    g.captions = captions;
    write_png(dir + "/texture_transfer.png", compose_grid(textured, g));
  }
  const DomainMesh dm = mesh_domain(atlas, DomainMeshOptions{64, mesh.threshold});
  write_png(dir + "/domain.png", domain_picture(atlas, dm.level));
  if (!log.rows.empty()) write_png(dir + "/losses.png", loss_curves(log));
}

}  // namespace jsa::cli
