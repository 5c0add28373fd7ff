// Randomly posed copies of a collection, and how well a fit recovered the poses
// (issue 26; docs/collections.md, "Shapes in any pose").
//
//   bench_rotate_shapes rotate --seed S --out DIR A.obj B.obj ...
//     writes DIR/A.obj, ... with every `v` and `vn` line turned by a seeded
//     uniform random rotation A_i (one per shape, Rng(S, i)) and moved by a
//     random offset; NAME.vts beside NAME.obj is copied with its x y z turned
//     the same way (the vertex indices stay valid: the lines keep their order).
//     DIR/applied_rotations.json lists A_i (rows: x' = x A_i + t_i).
//   bench_rotate_shapes align [--trim 1,0.7,0.5] [--normal-weight 0,0.08] [--seed S] A.obj B.obj
//   ...
//                                                     (the pose step alone)
//   bench_rotate_shapes compare --applied DIR/applied_rotations.json --found RUN/rotations.json
//                               [--reference RUN0/rotations.json]
//     the angle between the rotation the fit found for each copy and the one
//     it should have found, A_i^T R0_i A_0, where R0_i is what the fit of the
//     unposed shapes found (identity without --reference).
#include <CLI/CLI.hpp>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "engine/block.h"
#include "engine/rng.h"
#include "io/atomic_write.h"
#include "io/geometry/rigid_align.h"
#include "model/tool/shape_input.h"

namespace {

namespace fs = std::filesystem;
using jsa::Rng;

// A uniform random rotation: the unit quaternion of a 4D Gaussian.
Eigen::Matrix3d random_rotation(Rng& rng) {
  Eigen::Quaterniond q(rng.normal(), rng.normal(), rng.normal(), rng.normal());
  q.normalize();
  return q.toRotationMatrix();
}

std::string turned(const std::string& line, size_t skip, const Eigen::Matrix3d& a,
                   const Eigen::RowVector3d& t) {
  std::istringstream in(line.substr(skip));
  Eigen::RowVector3d p;
  if (!(in >> p(0) >> p(1) >> p(2))) return line;
  std::string rest;
  std::getline(in, rest);
  const Eigen::RowVector3d q = p * a + t;
  char buf[128];
  std::snprintf(buf, sizeof buf, "%.9g %.9g %.9g", q(0), q(1), q(2));
  const bool spaced = skip > 0 && std::isspace(static_cast<unsigned char>(line[skip - 1]));
  return line.substr(0, skip) + (spaced ? "" : " ") + buf + rest;
}

void rotate_file(const fs::path& from, const fs::path& to, const Eigen::Matrix3d& a,
                 const Eigen::RowVector3d& t, bool vts) {
  std::ifstream in(from);
  if (!in) throw std::runtime_error(from.string() + ": cannot open");
  std::ostringstream out;
  std::string line;
  while (std::getline(in, line)) {
    if (vts) {
      // "index x y z"
      std::istringstream s(line);
      std::string index;
      if (s >> index) {
        out << turned(line, line.find(index) + index.size(), a, t) << "\n";
        continue;
      }
    } else if (line.rfind("v ", 0) == 0) {
      out << turned(line, 2, a, t) << "\n";
      continue;
    } else if (line.rfind("vn ", 0) == 0) {
      out << turned(line, 3, a, Eigen::RowVector3d::Zero()) << "\n";
      continue;
    }
    out << line << "\n";
  }
  jsa::write_file_atomically(to.string(), [&](std::ostream& f) { f << out.str(); });
}

Eigen::Matrix3d matrix_of(const nlohmann::json& m) {
  Eigen::Matrix3d r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r(i, j) = m.at(size_t(i)).at(size_t(j)).get<double>();
  return r;
}

std::vector<Eigen::Matrix3d> read_rotations(const std::string& path, const char* list,
                                            const char* key) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  const nlohmann::json j = nlohmann::json::parse(in);
  std::vector<Eigen::Matrix3d> out;
  for (const auto& e : j.at(list)) out.push_back(matrix_of(e.at(key)));
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("Randomly posed copies of shapes, and the angle errors of recovered poses");
  uint64_t seed = 1;
  std::string out_dir, applied, found, reference;
  std::vector<std::string> inputs;
  CLI::App* rot = app.add_subcommand("rotate", "Write seeded randomly rotated copies (and .vts)");
  rot->add_option("--seed", seed)->capture_default_str();
  rot->add_option("--out", out_dir)->required();
  rot->add_option("inputs", inputs)->required();
  CLI::App* cmp = app.add_subcommand("compare", "Angle errors of a fit's rotations.json");
  cmp->add_option("--applied", applied)->required();
  cmp->add_option("--found", found)->required();
  cmp->add_option("--reference", reference);
  CLI::App* al = app.add_subcommand(
      "align",
      "The pose step alone (best candidate, no keep-the-input rule) onto the first shape, "
      "for each --trim: the angle each shape is turned by, its score and the runner-up's");
  std::vector<double> trims{1.0};
  al->add_option("--trim", trims,
                 "Shares of the closest pairs kept, comma-separated (RigidAlignOptions::trim)")
      ->delimiter(',')
      ->allow_extra_args(false)
      ->capture_default_str();
  double tie = jsa::RigidAlignOptions{}.tie;
  al->add_option("--tie", tie, "RigidAlignOptions::tie (0: the lowest Chamfer only)")
      ->capture_default_str();
  std::vector<double> normal_weights{0.0};
  al->add_option("--normal-weight", normal_weights,
                 "RigidAlignOptions::normal_weight, comma-separated (0: points only)")
      ->delimiter(',')
      ->allow_extra_args(false)
      ->capture_default_str();
  al->add_option("--seed", seed, "Seed of the surface samples")->capture_default_str();
  al->add_option("--applied", applied,
                 "applied_rotations.json of the inputs (rotate's): print each angle error");
  al->add_option("inputs", inputs)->required();
  app.require_subcommand(1);
  CLI11_PARSE(app, argc, argv);
  try {
    if (*rot) {
      fs::create_directories(out_dir);
      nlohmann::json list = nlohmann::json::array();
      for (size_t i = 0; i < inputs.size(); ++i) {
        Rng rng(seed, i);
        const Eigen::Matrix3d a = random_rotation(rng);
        const Eigen::RowVector3d t(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
        const fs::path obj(inputs[i]);
        rotate_file(obj, fs::path(out_dir) / obj.filename(), a, t, false);
        fs::path vts = obj;
        vts.replace_extension(".vts");
        if (fs::exists(vts)) rotate_file(vts, fs::path(out_dir) / vts.filename(), a, t, true);
        nlohmann::json m = nlohmann::json::array();
        for (int r = 0; r < 3; ++r) m.push_back({a(r, 0), a(r, 1), a(r, 2)});
        list.push_back({{"input", inputs[i]},
                        {"rotation", m},
                        {"angle_degrees", jsa::rotation_angle_degrees(a)},
                        {"offset", {t(0), t(1), t(2)}}});
        std::printf("%s: turned by %.1f deg\n", obj.filename().c_str(),
                    jsa::rotation_angle_degrees(a));
      }
      const nlohmann::json j = {
          {"seed", seed}, {"convention", "rows: x' = x * rotation + offset"}, {"shapes", list}};
      jsa::write_file_atomically((fs::path(out_dir) / "applied_rotations.json").string(),
                                 [&](std::ostream& f) { f << j.dump(2) << "\n"; });
    } else if (*al) {
      std::vector<jsa::RunInput> shapes;
      for (const std::string& in : inputs) shapes.push_back(jsa::load_run_input(in, 5000, seed));
      std::vector<Eigen::Matrix3d> a;
      if (!applied.empty()) a = read_rotations(applied, "shapes", "rotation");
      if (!a.empty() && a.size() != shapes.size()) throw std::runtime_error("shape counts differ");
      for (const double weight : normal_weights)
        for (const double trim : trims) {
          std::printf("trim %.2f, normal weight %.3f:\n", trim, weight);
          for (size_t i = 1; i < shapes.size(); ++i) {
            jsa::RigidAlignOptions o;
            o.keep_input = 0;
            o.trim = trim;
            o.tie = tie;
            o.normal_weight = weight;
            const jsa::Index c = weight > 0 ? 6 : 3;
            const jsa::RigidAlignment r =
                jsa::rigid_align(shapes[i].pool.leftCols(c), shapes[0].pool.leftCols(c), o);
            std::printf(
                "  %s: %.1f deg, score %.2f, runner-up %.2f (x 1e-4, margin %.2f), %d tied%s\n",
                fs::path(inputs[i]).filename().c_str(), r.angle_degrees(), 1e4 * r.chamfer,
                1e4 * r.runner_up, r.runner_up / r.chamfer, r.tied,
                r.tie_broken ? ", tie broken by ball shares" : "");
            // The stored shapes are taken as aligned: posed i goes onto posed 0 by A_i^T A_0.
            if (!a.empty())
              std::printf(
                  "    error %.1f deg\n",
                  jsa::rotation_angle_degrees(r.rotation.transpose() * a[i].transpose() * a[0]));
          }
        }
    } else {
      const auto a = read_rotations(applied, "shapes", "rotation");
      const auto r = read_rotations(found, "shapes", "rotation");
      std::vector<Eigen::Matrix3d> r0(r.size(), Eigen::Matrix3d::Identity());
      if (!reference.empty()) r0 = read_rotations(reference, "shapes", "rotation");
      if (a.size() != r.size() || r0.size() != r.size())
        throw std::runtime_error("shape counts differ");
      double sum = 0, worst = 0;
      for (size_t i = 1; i < r.size(); ++i) {
        // Relative poses (shape i's unit frame against shape 0's, r_i r_0^T):
        // the fit's against the applied turns' composed with the reference's.
        const Eigen::Matrix3d found_relative = r[i] * r[0].transpose();
        const Eigen::Matrix3d expected = a[i].transpose() * r0[i] * r0[0].transpose() * a[0];
        const double e = jsa::rotation_angle_degrees(found_relative.transpose() * expected);
        std::printf("shape %zu: found %.2f deg, expected %.2f deg, error %.2f deg\n", i,
                    jsa::rotation_angle_degrees(found_relative),
                    jsa::rotation_angle_degrees(expected), e);
        sum += e;
        worst = std::max(worst, e);
      }
      std::printf("mean angle error %.2f deg, worst %.2f deg\n", sum / double(r.size() - 1), worst);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_rotate_shapes: %s\n", e.what());
    return 1;
  }
  return 0;
}
