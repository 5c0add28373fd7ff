#include "bin/run_files.h"

#include <chrono>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>

#include "io/atomic_write.h"
#include "io/geometry/nearest.h"
#include "io/geometry/valid_uv.h"
#include "io/mesh_io.h"
#include "io/pictures/raster.h"
#include "io/pictures/run_pictures.h"
#include "losses/metrics/uv_quality.h"
#include "model/tool/chart_mesh.h"
#include "model/tool/domain_mesh.h"

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

nlohmann::json stats_json(const ValidUvStats& s, bool packed) {
  nlohmann::json j;
  j["charts"] = s.charts;
  j["charts_from_psi"] = s.from_psi;
  j["charts_repaired"] = s.repaired;
  j["charts_lscm"] = s.lscm;
  j["charts_inherited"] = s.inherited;
  j["charts_tutte"] = s.tutte;
  j["single_faces"] = s.single_faces;
  j["slim_reverted"] = s.slim_reverted;
  j["mirrored_charts"] = s.mirrored_charts;
  j["slim_iterations"] = s.slim_iterations;
  j["symmetric_dirichlet_start"] = s.energy_start;
  j["symmetric_dirichlet_end"] = s.energy_end;
  j["packed"] = packed;
  j["packing_efficiency"] = s.packing_efficiency;
  j["padding_texels"] = s.padding_texels;
  j["torn_edges_cut"] = s.cut.torn_edges;
  j["slits_closed"] = s.cut.slits_closed;
  j["nonmanifold_edges"] = s.cut.nonmanifold_edges;
  j["inconsistent_edges"] = s.cut.inconsistent_edges;
  j["boundary_edges"] = s.cut.boundary_edges;
  j["skipped_faces"] = s.cut.skipped_faces.size();
  j["charts_split_to_disks"] = s.cut.split_charts;
  j["cut_paths"] = s.cut.path_cuts;
  j["faces_psi_unusable"] = s.cut.unusable_faces;
  j["seconds"] = s.seconds;
  j["warnings"] = s.warnings;
  return j;
}

// One 3D vertex per UV index, so per-vertex renderers draw seamed UVs.
Block<double> unweld(const Block<double>& vertices, const Faces& faces, const Faces& uv_faces,
                     Index uv_count) {
  Block<double> out = Block<double>::Zero(uv_count, 3);
  for (Index f = 0; f < faces.rows(); ++f)
    for (int k = 0; k < 3; ++k) out.row(uv_faces(f, k)) = vertices.row(faces(f, k));
  return out;
}

}  // namespace

Block<double> shared_layout(const Block<double>& frame_uv, int texture_size, double padding) {
  const double p = std::clamp(padding / std::max(texture_size, 1), 0.0, 0.25);
  return (frame_uv.array() * (1 - 2 * p) + p).matrix();
}

std::string json_quote(const std::string& s) { return nlohmann::json(s).dump(); }

// The share of the mesh's area (unit frame) whose faces point away from the
// surface: each face's normal against the normal of the surface sample
// nearest its centroid. The meshed domain's faces are counter-clockwise in
// UV, so their normals are phi's (J_u x J_v); a flap of phi folded back over
// the surface faces away from it.
double back_facing_area_fraction(const Block<double>& points, const Faces& faces,
                                 const Block<double>& surface) {
  Block<double> centre(faces.rows(), 3);
  for (Index f = 0; f < faces.rows(); ++f)
    centre.row(f) =
        (points.row(faces(f, 0)) + points.row(faces(f, 1)) + points.row(faces(f, 2))) / 3;
  const NearestIndex<double> index(surface.leftCols(3));
  std::vector<int> nn;
  index.query(centre, nn);
  double back = 0, total = 0;
  for (Index f = 0; f < faces.rows(); ++f) {
    const Eigen::Vector3d p0 = points.row(faces(f, 0)).transpose();
    const Eigen::Vector3d e1 = points.row(faces(f, 1)).transpose() - p0;
    const Eigen::Vector3d e2 = points.row(faces(f, 2)).transpose() - p0;
    const Eigen::Vector3d n = e1.cross(e2);
    const Eigen::Vector3d ns = surface.row(nn[size_t(f)]).rightCols<3>().transpose();
    total += 0.5 * n.norm();
    if (n.dot(ns) < 0) back += 0.5 * n.norm();
  }
  return total > 0 ? back / total : 0.0;
}

void write_domain_mesh(Atlas<float>& atlas, const Normalization& normalization,
                       const std::string& obj_path, const MeshOutputOptions& o, int shape,
                       const Block<double>* surface) {
  const auto start = std::chrono::steady_clock::now();
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
  // The domain's grid is one injective chart by construction; its UVs are the
  // shared layout (the TextureFrame inset by the padding), the same on every shape.
  const Block<double> vt =
      shared_layout(texture_frame(atlas).to_texture(dm.uv), o.texture_size, o.padding);
  write_obj(obj_path, out, &vt, write_material(obj_path, o.texture), "atlas");
  const std::string stem = stem_of(obj_path);
  const UvQuality q = measure_uv_quality(out.vertices, out.faces, vt, out.faces);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  nlohmann::json extra = {{"domain_mass_fraction", dm.mass_fraction},
                          {"threshold", o.threshold},
                          {"level", dm.level},
                          {"map", "domain uv -> phi (3D)"},
                          {"seconds", seconds},
                          {"padding_texels", o.padding},
                          {"texture_size", o.texture_size}};
  double back = -1;
  if (surface && surface->rows() > 0) {  // `show` has no surface samples: nothing to measure
    back = back_facing_area_fraction(points, out.faces, *surface);
    extra["back_facing_area_fraction"] = back;
  }
  write_report(stem + "_uv.json", q, extra);
  write_png(stem + ".png", domain_coloured_views(out.vertices, out.faces, vt));
  if (!o.quiet) {
    std::cerr << "mesh: " << obj_path << "  (" << out.vertices.rows() << " vertices, "
              << out.faces.rows() << " triangles; the domain holds "
              << int(100 * dm.mass_fraction + 0.5) << "% of P's mass)\n";
    std::cerr << to_text(q);
    if (back >= 0)
      std::cerr << "  back-facing (of 3D area) " << 100 * back
                << "%   ideal 0; phi's flaps folded over the surface\n";
  }
}

ChartWritten write_chart(Atlas<float>& atlas, const Normalization& normalization, const Mesh& mesh,
                         const std::string& obj_path, const ChartOutputOptions& o, int shape) {
  if (mesh.faces.rows() == 0)
    throw InputError("chart: the input has no faces (a point cloud has no UV map to write)");
  const auto start = std::chrono::steady_clock::now();
  const Block<double> uv = chart_vertices(atlas, mesh, normalization, shape);
  const TextureFrame frame = texture_frame(atlas);
  const Block<double> psi_vt = frame.to_texture(uv);
  UvQualityOptions qo;
  qo.torn_ratio = o.torn_ratio;
  const UvQuality psi_q = measure_uv_quality(mesh.vertices, mesh.faces, psi_vt, mesh.faces, qo);
  ChartWritten w;
  w.vt = psi_vt;
  w.uv_faces = mesh.faces;
  nlohmann::json extra = {{"map", "input mesh -> psi (2D); measured as uv -> 3D"}};
  std::string summary;
  if (o.psi_only) {
    if (o.split_cuts && psi_q.torn > 0) {
      SplitUv split = split_torn(atlas, mesh, normalization, uv, psi_q.torn_faces, shape);
      w.vt = frame.to_texture(split.uv);
      w.uv_faces = split.uv_faces;
    }
    extra["uvs"] = o.split_cuts ? "psi, torn faces split" : "psi as is";
    summary = std::to_string(psi_q.torn) + " torn across the cut" +
              (o.split_cuts ? ", split" : "") + "; psi's UVs";
  } else {
    ValidUvOptions vo;
    vo.pack_charts = o.pack;
    vo.pack.texture_size = o.texture_size;
    vo.pack.padding = o.padding;
    UvProgress progress;
    if (!o.quiet && mesh.faces.rows() >= 100000)
      progress = [](const std::string& stage, double x) {
        std::cerr << "chart: " << stage << " " << int(100 * x + 0.5) << "%\n";
      };
    const ValidUv v = make_valid_uv(mesh.vertices, mesh.faces, psi_vt, vo, progress);
    w.vt = o.pack ? v.uv : shared_layout(v.uv, o.texture_size, o.padding);
    w.uv_faces = v.uv_faces;
    extra["uvs"] = o.pack ? "valid, packed" : "valid, shared-domain layout (not packed)";
    extra["valid_uv"] = stats_json(v.stats, o.pack);
    extra["psi"] = nlohmann::json::parse(to_json(psi_q));
    extra["psi"].erase("torn_faces");
    extra["psi"].erase("flipped_faces");
    for (const std::string& warning : v.stats.warnings)
      if (!o.quiet) std::cerr << "warning: chart: " << warning << "\n";
    char line[200];
    std::snprintf(line, sizeof line,
                  "%lld charts (%lld from psi, %lld repaired, %lld LSCM, %lld Tutte, %lld halves "
                  "of a split); %.2f s",
                  (long long)v.stats.charts, (long long)v.stats.from_psi,
                  (long long)v.stats.repaired, (long long)v.stats.lscm, (long long)v.stats.tutte,
                  (long long)v.stats.inherited, v.stats.seconds);
    summary = line;
  }
  const UvQuality q = measure_uv_quality(mesh.vertices, mesh.faces, w.vt, w.uv_faces, qo);
  const bool split = o.split_cuts || !o.psi_only;
  write_obj(obj_path, mesh, &w.vt, write_material(obj_path, o.texture), "atlas",
            split ? &w.uv_faces : nullptr);
  const std::string stem = stem_of(obj_path);
  extra["seconds"] =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  write_report(stem + "_uv.json", q, extra);
  write_png(stem + ".png", domain_coloured_views(mesh.vertices, mesh.faces, psi_vt));
  write_png(stem + "_layout.png", uv_layout_picture(mesh.vertices, mesh.faces, w.vt, w.uv_faces,
                                                    q.flipped_faces, q.torn_faces));
  if (!o.quiet) {
    std::cerr << "chart: " << obj_path << "  (" << mesh.vertices.rows() << " vertices, "
              << mesh.faces.rows() << " faces in the input's order; " << summary << ")\n";
    std::cerr << to_text(q);
  }
  return w;
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
    write_domain_mesh(atlas, inputs[i].normalization, sub + "/domain_mesh.obj", mesh, int(i),
                      &inputs[i].pool);
    if (inputs[i].mesh.faces.rows() > 0) {
      ChartOutputOptions co;
      co.quiet = mesh.quiet;
      co.texture = mesh.texture;
      co.texture_size = mesh.texture_size;
      co.padding = mesh.padding;
      // A texture painted in the shared domain fits every shape only through
      // the shared layout: with --texture the charts stay unpacked.
      co.pack = mesh.texture.empty();
      const ChartWritten written = write_chart(atlas, inputs[i].normalization, inputs[i].mesh,
                                               sub + "/input_chart.obj", co, int(i));
      // One view per shape, coloured by its position in the shared domain
      // (and, with a texture, textured through its valid, seamed UVs).
      const Mesh& m = inputs[i].mesh;
      const Block<double> vt = texture_frame(atlas).to_texture(
          chart_vertices(atlas, m, inputs[i].normalization, int(i)));
      if (collection) coloured.push_back(domain_coloured_views(m.vertices, m.faces, vt, 320));
      if (texture.width > 0)
        textured.push_back(
            textured_views(unweld(m.vertices, m.faces, written.uv_faces, written.vt.rows()),
                           written.uv_faces, written.vt, texture, 320));
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
