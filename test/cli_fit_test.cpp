// The command line end to end on small settings: fit -> outputs -> mesh,
// chart, eval; resume follows the uninterrupted trajectory; SIGKILL loses at
// most one checkpoint interval and leaves a loadable checkpoint.
#include <tiny_obj_loader.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <csignal>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "io/geometry/builtin_shapes.h"
#include "io/pictures/image.h"
#include "model/tool/trainer.h"
#include "test/cli_test_support.h"

using namespace cli_test;
using jsa::Index;
namespace fs = std::filesystem;

namespace {
const std::string kSmall =
    " -K 200 -M 200 --width 16 --depth 2 --threads 1 --pool 5000 --mesh-resolution 32 -q";

// The loss columns of losses.csv, without the header.
std::string loss_rows(const std::string& dir) {
  std::string s = read_text(dir + "/losses.csv");
  return s.substr(s.find('\n') + 1);
}
}  // namespace

TEST_CASE("cli: fit writes every output and the follow-up commands read them", "[cli]") {
  const std::string dir = fresh_dir("fit");
  Result r = run("fit builtin:torus -o " + dir + " --iters 30" + kSmall);
  INFO(r.output);
  REQUIRE(r.code == 0);
  for (const char* f :
       {"config.json", "losses.csv", "model.ckpt", "domain_mesh.obj", "domain_mesh.mtl",
        "domain_mesh_uv.json", "domain_mesh.png", "input_chart.obj", "input_chart_uv.json",
        "input_chart.png", "input_chart_layout.png", "domain.png", "losses.png",
        "jsatlas_texture.png"})
    CHECK(fs::exists(dir + "/" + f));
  CHECK(count_lines(loss_rows(dir)) == 30);
  // The chart keeps the input's vertex count and face order.
  const std::string chart = read_text(dir + "/input_chart.obj");
  CHECK(chart.find("vt ") != std::string::npos);
  r = run("chart " + dir + " -o " + dir + "/again.obj --psi-only --split-cuts -q");
  CHECK(r.code == 0);
  r = run("mesh " + dir + " -o " + dir + "/m.obj --resolution 40 -q");
  CHECK(r.code == 0);
  // `show` regenerates the pictures from the checkpoint.
  fs::remove(dir + "/domain.png");
  r = run("show " + dir + " -q");
  CHECK(r.code == 0);
  CHECK(fs::exists(dir + "/domain.png"));
  r = run("eval " + dir + " --samples 300");
  INFO(r.output);
  CHECK(r.code == 0);
  CHECK(r.output.find("Chamfer spatial") != std::string::npos);
  // --draws: every metric the mean of the single draws seeded seed + d.
  const auto eval_json = [&](const std::string& flags) {
    const Result e = run("eval " + dir + " --samples 300 --threads 1 " + flags);
    INFO(e.output);
    REQUIRE(e.code == 0);
    return nlohmann::json::parse(read_text(dir + "/eval.json"));
  };
  const nlohmann::json mean = eval_json("--seed 5 --draws 3");
  CHECK(mean["draws"] == 3);
  REQUIRE(mean["emd_ratio_per_draw"].size() == 3);
  double emd = 0, floor_emd = 0, chamfer = 0, normal = 0;
  for (int d = 0; d < 3; ++d) {
    const nlohmann::json one = eval_json("--draws 1 --seed " + std::to_string(5 + d));
    emd += one["emd_spatial"].get<double>() / 3;
    floor_emd += one["floor_emd_spatial"].get<double>() / 3;
    chamfer += one["chamfer_spatial"].get<double>() / 3;
    normal += one["chamfer_normal_unit"].get<double>() / 3;
    CHECK(mean["emd_ratio_per_draw"][size_t(d)].get<double>() ==
          Approx(one["emd_spatial"].get<double>() / one["floor_emd_spatial"].get<double>())
              .epsilon(1e-12));
  }
  CHECK(mean["emd_spatial"].get<double>() == Approx(emd).epsilon(1e-12));
  CHECK(mean["floor_emd_spatial"].get<double>() == Approx(floor_emd).epsilon(1e-12));
  CHECK(mean["chamfer_spatial"].get<double>() == Approx(chamfer).epsilon(1e-12));
  CHECK(mean["chamfer_normal_unit"].get<double>() == Approx(normal).epsilon(1e-12));
  CHECK(run("eval " + dir + " --draws 0").code != 0);
}

TEST_CASE("cli: a run stopped by SIGTERM and resumed gives the uninterrupted losses", "[cli]") {
  const std::string a = fresh_dir("straight"), c = fresh_dir("interrupted");
  const std::string args = " --iters 400 --checkpoint-every 20" + kSmall;
  REQUIRE(run("fit builtin:sphere -o " + a + args).code == 0);
  // Stop a second run as soon as its first checkpoint exists: it saves and exits with 130.
  Result r = run("fit builtin:sphere -o " + c + args + " & pid=$!; while [ ! -f " + c +
                 "/model.ckpt ]; do sleep 0.005; done; kill -TERM $pid; wait $pid; echo exit=$?");
  INFO(r.output);
  CHECK(r.output.find("exit=130") != std::string::npos);
  const int stopped_at = count_lines(loss_rows(c));
  CHECK(stopped_at >= 20);
  CHECK(stopped_at < 400);
  r = run("fit --resume " + c + " -q");
  INFO(r.output);
  REQUIRE(r.code == 0);
  CHECK(count_lines(loss_rows(c)) == 400);
  CHECK(loss_rows(c) == loss_rows(a));  // bit for bit: the same trajectory
}

TEST_CASE("cli: a NaN/Inf fault is undone and reported in losses.csv, config.json and the summary",
          "[cli]") {
  // One NaN forced at iteration 63 (hidden test option): the run goes back to
  // the snapshot of iteration 50, halves the learning rate, redoes 51..63 and
  // ends at 80 with each iteration logged once.
  const std::string dir = fresh_dir("fault");
  Result r = run("fit builtin:sphere -o " + dir + " --iters 80 --inject-fault-at 63" + kSmall);
  INFO(r.output);
  REQUIRE(r.code == 0);
  CHECK(
      r.output.find(
          "it     63: NaN/Inf in the step from iteration 63; restored the state of iteration 50") !=
      std::string::npos);  // printed even with -q
  CHECK(r.output.find("fit: 80 iterations, 1 NaN/Inf fault, ") != std::string::npos);
  CHECK(r.output.find("learning-rate scale now 0.5") != std::string::npos);
  const std::string config = read_text(dir + "/config.json");
  CHECK(config.find("\"faults\": 1, \"fault_actions\": [\"NaN/Inf in the step from iteration 63") !=
        std::string::npos);
  const std::string rows = loss_rows(dir);
  CHECK(count_lines(rows) == 81);  // 80 iterations and the fault
  CHECK(rows.find(",1,fault: restored iteration 50; lr scale 0.5\n") != std::string::npos);
  CHECK(rows.find("\n50,") < rows.find("\n63,"));  // the fault row follows the row it went back to
  CHECK(rows.find("\n63,") < rows.find("\n51,"));
}

TEST_CASE("cli: SIGKILL at a random moment leaves a loadable checkpoint", "[cli]") {
  const std::string dir = fresh_dir("kill");
  // Kill in the middle of a run that checkpoints every 5 iterations (0.7 s after
  // its first checkpoint, however slow the machine or the build is).
  Result r = run("fit builtin:sphere -o " + dir + " --iters 100000 --checkpoint-every 5" + kSmall +
                 " & pid=$!; while [ ! -f " + dir +
                 "/model.ckpt ]; do sleep 0.02; done; sleep 0.7; "
                 "kill -KILL $pid; wait $pid");
  REQUIRE(fs::exists(dir + "/model.ckpt"));
  // No temp files left half-written next to it that could be mistaken for results,
  // and the checkpoint loads: evaluation and resumption work.
  r = run("eval " + dir + " --samples 200");
  INFO(r.output);
  CHECK(r.code == 0);
  const int done = count_lines(loss_rows(dir));
  CHECK(done % 5 == 0);  // losses.csv is rewritten with each checkpoint, never torn
  CHECK(done > 0);
}

TEST_CASE(
    "cli: the chart OBJ reads back in tinyobjloader with the input's vertices, faces in order",
    "[cli]") {
  const std::string dir = fresh_dir("objback");
  REQUIRE(run("fit builtin:torus -o " + dir + " --iters 10" + kSmall).code == 0);
  const jsa::Mesh input = jsa::builtin_shape("torus");
  // psi: psi's UVs, one vt per vertex; split: the same with torn faces split;
  // valid: input_chart.obj as fit writes it (seams split vt, packed in [0, 1]).
  for (const std::string mode : {"psi", "split", "valid"}) {
    INFO(mode);
    const std::string path = mode == "valid" ? dir + "/input_chart.obj" : dir + "/" + mode + ".obj";
    if (mode == "psi") REQUIRE(run("chart " + dir + " -o " + path + " --psi-only -q").code == 0);
    if (mode == "split")
      REQUIRE(
          run("chart " + dir + " -o " + path + " --psi-only --split-cuts --torn-ratio 2 -q").code ==
          0);
    tinyobj::ObjReader reader;
    REQUIRE(reader.ParseFromFile(path));
    const auto& attrib = reader.GetAttrib();
    REQUIRE(reader.GetShapes().size() == 1);
    const auto& indices = reader.GetShapes()[0].mesh.indices;
    CHECK(attrib.vertices.size() == size_t(3 * input.vertices.rows()));
    if (mode == "psi")
      CHECK(attrib.texcoords.size() == size_t(2 * input.vertices.rows()));
    else
      CHECK(attrib.texcoords.size() >= size_t(2 * input.vertices.rows()));
    REQUIRE(indices.size() == size_t(3 * input.faces.rows()));
    bool same_order = true, uv_in_range = true;
    for (size_t k = 0; k < indices.size(); ++k) {
      same_order = same_order && indices[k].vertex_index == input.faces(Index(k / 3), int(k % 3));
      if (mode == "psi")
        same_order = same_order && indices[k].texcoord_index == indices[k].vertex_index;
    }
    const float lo = mode == "valid" ? 0.f : -0.5f, hi = mode == "valid" ? 1.f : 1.5f;
    for (float t : attrib.texcoords) uv_in_range = uv_in_range && t >= lo && t <= hi;
    CHECK(same_order);
    CHECK(uv_in_range);
  }
}

TEST_CASE("cli: --spectral-map refuses a point cloud before any training", "[cli]") {
  const std::string dir = fresh_dir("spectral_map");
  // Points alone have no Laplace-Beltrami basis here: one line, before any training.
  std::string cloud;
  for (int i = 0; i < 200; ++i) {
    // A point of the unit sphere, twice: as the point and as its normal.
    const double a = 0.1 * i, b = 0.37 * i;
    const std::string p = std::to_string(std::cos(a) * std::sin(b)) + " " +
                          std::to_string(std::sin(a) * std::sin(b)) + " " +
                          std::to_string(std::cos(b));
    cloud += p + " " + p + "\n";
  }
  write_text(dir + "/cloud.xyz", cloud);
  const std::string other = fresh_dir("spectral_map_cloud");
  const Result r = run("fit builtin:sphere " + dir + "/cloud.xyz -o " + other +
                       " --iters 2 --spectral-map 1 --code-size 8" + kSmall);
  CHECK(r.code == 1);
  CHECK(r.output.find("--spectral-map needs triangle meshes") != std::string::npos);
  CHECK(!fs::exists(other + "/model.ckpt"));
}

TEST_CASE(
    "cli: a collection with a shape batch, the intrinsic descriptors, a spectral map and a user "
    "texture writes the texture transfer",
    "[cli]") {
  const std::string dir = fresh_dir("texture");
  const std::string texture = dir + "/../jsatlas_test_paint_" + std::to_string(::getpid()) + ".png";
  jsa::write_png(texture, jsa::checkerboard(64, 8));
  Result r =
      run("fit builtin:sphere builtin:capsule builtin:torus -o " + dir +
          " --iters 12 --batch-shapes 2 --code-size 8 --intrinsic 0.5 --spectral-map 2 --no-align "
          "--texture " +
          texture + kSmall);
  INFO(r.output);
  REQUIRE(r.code == 0);
  CHECK(read_text(dir + "/config.json").find("\"batch_shapes\": 2") != std::string::npos);
  CHECK(read_text(dir + "/config.json").find("\"intrinsic\": 0.5") != std::string::npos);
  CHECK(read_text(dir + "/config.json").find("\"spectral_map\": 2.0") != std::string::npos);
  // The template (-1 by default: the medoid) is saved as the shape chosen.
  const std::string config = read_text(dir + "/config.json");
  const auto at = config.find("\"template_shape\": ");
  REQUIRE(at != std::string::npos);
  const int chosen = std::stoi(config.substr(at + 18));
  CHECK((chosen >= 0 && chosen < 3));
  CHECK(fs::exists(dir + "/texture_transfer.png"));
  CHECK(fs::exists(dir + "/collection.png"));
  // The atlas's map refined by ZoomOut: a vertex carried by correspond lands on
  // a vertex of the target (--snap gives its index), and eval-corr says the rule.
  r = run("correspond " + dir + " --from 0 --to 2 --vertices 0,7 --snap --spectral " +
          "--spectral-functions 12");
  INFO(r.output);
  REQUIRE(r.code == 0);
  CHECK(r.output.find("nearest vertex index") != std::string::npos);
  for (int i = 0; i < 3; ++i) write_text(dir + "/k" + std::to_string(i) + ".vts", "0\n3\n9\n");
  r = run("eval-corr " + dir + " --keypoints " + dir + "/k0.vts " + dir + "/k1.vts " + dir +
          "/k2.vts --spectral --spectral-functions 12 --spectral-k-start 4 --spectral-one-way");
  INFO(r.output);
  REQUIRE(r.code == 0);
  CHECK(r.output.find("refined by ZoomOut") != std::string::npos);
  CHECK(read_text(dir + "/eval_corr.json").find("\"spectral_refinement\": true") !=
        std::string::npos);
  // Both readings of the paper's L2: the mean distance and the mean squared one.
  CHECK(r.output.find("mean squared distance") != std::string::npos);
  CHECK(read_text(dir + "/eval_corr.json").find("\"mean_squared_unit_frame\"") !=
        std::string::npos);
  const std::string stem = fs::path(texture).stem().string();
  for (int i = 0; i < 3; ++i) {
    const std::string sub = dir + "/shape_" + std::to_string(i);
    CHECK(read_text(sub + "/input_chart.mtl").find(stem + "_texture.png") != std::string::npos);
    CHECK(jsa::read_image(sub + "/" + stem + "_texture.png").width == 64);
  }
  // A texture that cannot be read stops the fit before any training.
  const std::string other = fresh_dir("texture_bad");
  r = run("fit builtin:sphere -o " + other + " --iters 5 --texture " + dir + "/config.json" +
          kSmall);
  CHECK(r.code == 1);
  CHECK(r.output.find("config.json: not a readable image") != std::string::npos);
  CHECK(!fs::exists(other + "/model.ckpt"));
  // A template the collection does not have: one line naming the flag.
  r = run("fit builtin:sphere builtin:torus -o " + other + " --iters 2 --template-shape 2" +
          kSmall);
  CHECK(r.code == 1);
  CHECK(r.output.find("--template-shape") != std::string::npos);
  fs::remove(texture);
}

TEST_CASE("cli: moving flipped Gaussians is reported and saved", "[cli]") {
  // The inside-out sphere: the random start's sheet faces the wrong way somewhere.
  const std::string dir = fresh_dir("reseed");
  Result r = run("fit builtin:sphere -o " + dir + " --iters 40 --reseed 10" +
                 kSmall.substr(0, kSmall.size() - 3));
  INFO(r.output);
  REQUIRE(r.code == 0);
  CHECK(r.output.find("Gaussians off back-facing flaps") != std::string::npos);
  CHECK(read_text(dir + "/config.json").find("\"reseed_every\": 10") != std::string::npos);
  CHECK(run("fit builtin:sphere -o " + dir + "_bad --reseed -1" + kSmall).code == 2);
}

TEST_CASE("cli: the dense surface flag is saved, and its negation turns it off", "[cli]") {
  const std::string dir = fresh_dir("dense");
  Result r = run("fit builtin:sphere -o " + dir + " --iters 5 --dense-surface" + kSmall);
  INFO(r.output);
  REQUIRE(r.code == 0);
  CHECK(read_text(dir + "/config.json").find("\"dense_surface\": true") != std::string::npos);
  r = run("fit builtin:sphere -o " + dir + "_off --iters 5 --no-dense-surface" + kSmall);
  REQUIRE(r.code == 0);
  CHECK(read_text(dir + "_off/config.json").find("\"dense_surface\": false") != std::string::npos);
  CHECK(run("fit builtin:sphere -o " + dir + "_bad --dense-surface=maybe" + kSmall).code == 2);
}

TEST_CASE("cli: the starting wrap is reported, and Ctrl-C during it writes no checkpoint",
          "[cli]") {
  const std::string dir = fresh_dir("wrap");
  Result r = run("fit builtin:capsule -o " + dir + " --iters 5 --wrap 30" +
                 kSmall.substr(0, kSmall.size() - 3));  // without -q: the progress lines
  INFO(r.output);
  REQUIRE(r.code == 0);
  CHECK(r.output.find("wrapped around the shape's ellipsoid (30 steps") != std::string::npos);
  CHECK(read_text(dir + "/config.json").find("\"wrap_steps\": 30") != std::string::npos);
  // A wrap that would take hours, interrupted once the run has started.
  const std::string stopped = fresh_dir("wrap_interrupted");
  r = run(
      "fit builtin:capsule -o " + stopped + " --iters 5 --wrap 1000000" + kSmall +
      " 2>&1 & pid=$!; while [ ! -f " + stopped +
      "/config.json ]; do sleep 0.01; done; sleep 0.3; kill -INT $pid; wait $pid; echo exit=$?");
  INFO(r.output);
  CHECK(r.output.find("exit=130") != std::string::npos);
  CHECK(r.output.find("interrupted while wrapping") != std::string::npos);
  CHECK_FALSE(fs::exists(stopped + "/model.ckpt"));
}

TEST_CASE("cli: the schedule's flags are saved, collections keep M fixed, a short budget is timed",
          "[cli][schedule]") {
  const std::string dir = fresh_dir("schedule");
  Result r = run("fit builtin:sphere -o " + dir +
                 " --iters 8 --points-start 0.5 --ramp-until 0.5 --ramp-levels 2 --warmup 0.25"
                 " --w-even 0.01 --w-even-from 0.25 --lr-drop-at 0.5 --lr-drop 0.25" +
                 kSmall.substr(0, kSmall.size() - 3));  // without -q: the first line says M
  INFO(r.output);
  REQUIRE(r.code == 0);
  CHECK(r.output.find("M = 200 ramped from 100") != std::string::npos);
  auto settings = [](const std::string& run) {
    return nlohmann::json::parse(read_text(run + "/config.json"))["settings"];
  };
  const nlohmann::json single = settings(dir);
  CHECK(single["iterations"] == 8);
  CHECK(single["schedule"]["kind"] == "ramp");  // the single-shape default
  CHECK(single["schedule"]["points_start"] == 0.5);
  CHECK(single["schedule"]["ramp_until"] == 0.5);
  CHECK(single["schedule"]["levels"] == 2);
  CHECK(single["schedule"]["warmup"] == 0.25);
  CHECK(single["schedule"]["drop_at"] == 0.5);
  CHECK(single["schedule"]["drop"] == 0.25);
  {
    // The rate each step used (losses.csv's second column): 2e-3 after the
    // warm-up (2 steps of 8), x 0.25 from step 4 on, before the decays (6, 7).
    std::istringstream rows(read_text(dir + "/losses.csv"));
    std::string row;
    std::map<int, double> lr;
    std::getline(rows, row);  // header
    while (std::getline(rows, row)) {
      const auto comma = row.find(',');
      lr[std::stoi(row.substr(0, comma))] = std::stod(row.substr(comma + 1));
    }
    REQUIRE(lr.size() == 8);
    CHECK(lr[3] == Approx(2e-3));
    CHECK(lr[5] == Approx(5e-4));
  }
  CHECK(single["weights"]["evenness"] == 0.01);  // L_even's weight and start
  CHECK(single["evenness_from"] == 0.25);
  // A collection without --schedule or --iters: M fixed for 5000 steps.
  r = run("fit builtin:sphere builtin:torus -o " + dir +
          "_pair --stop-at 1 --template-steps 0 --no-align" + kSmall);
  REQUIRE(r.code == 0);
  CHECK(settings(dir + "_pair")["schedule"]["kind"] == "step");
  CHECK(settings(dir + "_pair")["iterations"] == 5000);
  CHECK(settings(dir + "_pair")["weights"]["evenness"] == 0);  // L_even: single shapes only
  CHECK(settings(dir + "_pair")["lr"] == jsa::kCollectionLearningRate);  // 1e-3
  // psi on Fourier features: collections only (the paper's psi for one shape).
  CHECK(settings(dir + "_pair")["atlas"]["chart_fourier"] == jsa::kCollectionChartFourier);
  CHECK(jsa::kCollectionChartFourier > 0);
  CHECK(single["atlas"]["chart_fourier"] == 0);
  r = run("fit builtin:sphere builtin:torus -o " + dir +
          "_pair_ramp --stop-at 1 --template-steps 0 --no-align --schedule ramp --iters 30" +
          kSmall);
  REQUIRE(r.code == 0);
  CHECK(settings(dir + "_pair_ramp")["schedule"]["kind"] == "ramp");
  CHECK(settings(dir + "_pair_ramp")["iterations"] == 30);
  r = run("fit builtin:sphere builtin:torus -o " + dir +
          "_pair_lr --stop-at 1 --template-steps 0 --no-align --lr 5e-3 --chart-fourier 0" +
          kSmall);
  REQUIRE(r.code == 0);
  CHECK(settings(dir + "_pair_lr")["lr"] == 5e-3);                   // a given rate is kept
  CHECK(settings(dir + "_pair_lr")["atlas"]["chart_fourier"] == 0);  // and a given psi
  CHECK(run("fit builtin:sphere -o " + dir + "_bad --schedule cosine" + kSmall).code == 2);
  CHECK(run("fit builtin:sphere -o " + dir + "_bad --points-start 0" + kSmall).code == 2);
  CHECK(run("fit builtin:sphere -o " + dir + "_bad --ramp-levels 0" + kSmall).code == 2);
  CHECK(run("fit builtin:sphere -o " + dir + "_bad --w-even -1" + kSmall).code == 2);
  CHECK(run("fit builtin:sphere -o " + dir + "_bad --w-even-from 2" + kSmall).code == 2);
  // A budget with fewer iterations than the 25 timed ones (the loop used to
  // wait for iteration 25 forever): the timed steps run, then the budget sets --iters.
  r = run("fit builtin:sphere -o " + dir + "_budget --iters 3 --minutes 0.01" + kSmall);
  INFO(r.output);
  REQUIRE(r.code == 0);
  CHECK(settings(dir + "_budget")["iterations"] > 25);
  CHECK(settings(dir + "_budget")["weights"]["evenness"] == 0.003);  // the single-shape default
  CHECK(settings(dir + "_budget")["evenness_from"] == 0.5);
  CHECK(settings(dir + "_budget")["lr"] == jsa::FitOptions().lr);  // a single shape's, 2e-3
  CHECK(jsa::FitOptions().lr == 2 * jsa::kCollectionLearningRate);
  // Under --minutes the template start takes its share of the time, but no
  // more than --template-max-steps; the joint training gets the rest. (1.8 s
  // of template time for 40 steps of these tiny networks: a wide margin.)
  r = run("fit builtin:sphere builtin:torus -o " + dir +
          "_capped --minutes 0.1 --no-align --template-shape 0 --template-max-steps 40" + kSmall);
  INFO(r.output);
  REQUIRE(r.code == 0);
  CHECK(settings(dir + "_capped")["template_steps"] == 40);
  CHECK(settings(dir + "_capped")["template_max_steps"] == 40);
}

// --min-steps (model/tool/schedule.h, budgeted_points): a budget that holds
// fewer steps than asked at M takes a smaller M, down to M/2. No budget holds
// 10^8 steps, so whatever this machine's speed the default M = 2500 becomes
// 1250; an M given with -M, --min-steps 0 and a collection keep theirs.
TEST_CASE("cli: a budget too short for --min-steps halves M, unless -M, 0 or a collection",
          "[cli][schedule]") {
  const std::string dir = fresh_dir("min_steps");
  const std::string tiny =
      " --minutes 0.01 --iters 3 -K 200 --width 16 --depth 2 --threads 1 --pool 5000"
      " --mesh-resolution 32 --checkpoint-every 0";
  auto points = [](const std::string& run) {
    return nlohmann::json::parse(read_text(run + "/config.json"))["settings"]["points"];
  };
  Result r = run("fit builtin:sphere -o " + dir + "_halved --min-steps 100000000" + tiny);
  INFO(r.output);
  REQUIRE(r.code == 0);
  CHECK(points(dir + "_halved") == 1250);
  CHECK(r.output.find("M = 1250 instead (--min-steps)") != std::string::npos);
  r = run("fit builtin:sphere -o " + dir + "_given --min-steps 100000000 -M 2000 -q" + tiny);
  REQUIRE(r.code == 0);
  CHECK(points(dir + "_given") == 2000);
  r = run("fit builtin:sphere -o " + dir + "_off --min-steps 0 -q" + tiny);
  REQUIRE(r.code == 0);
  CHECK(points(dir + "_off") == 2500);
  r = run("fit builtin:sphere builtin:torus -o " + dir + "_pair --template-steps 0 --no-align -q" +
          tiny);
  REQUIRE(r.code == 0);
  CHECK(points(dir + "_pair") == jsa::kCollectionPoints);
  CHECK(run("fit builtin:sphere -o " + dir + "_bad --min-steps -1 -q" + tiny).code == 2);
}

// --gemm (engine/gemm.h, model/tool/gemm_choice.h): the backend is a setting,
// saved and resumed; a fixed one gives the same bits twice, here with a
// collection's shapes split over two threads (each worker's products inside an
// OpenMP team); a bad name is one line; `auto` without a cache (the tests'
// JSATLAS_GEMM_CACHE=off) is Eigen unmeasured, with one it measures once and
// then reads its answer.
TEST_CASE(
    "cli: --gemm is saved and resumed, gives the same losses twice, and auto keeps its choice",
    "[cli][gemm]") {
  const std::string dir = fresh_dir("gemm");
  auto settings = [](const std::string& run) {
    return nlohmann::json::parse(read_text(run + "/config.json"));
  };
  const std::string pair =
      "fit builtin:sphere builtin:torus --iters 6 --template-steps 0 --no-align --code-size 8 -K "
      "200 -M 200 --width 16 --depth 2 --threads 2 --pool 5000 --mesh-resolution 16 -q "
      "--checkpoint-every 0 --gemm blas -o ";
  Result r = run(pair + dir + "/a");
  INFO(r.output);
  const bool no_blas = r.code == 1 && r.output.find("built without a CBLAS") != std::string::npos;
  if (no_blas) {
    CHECK(count_lines(r.output) == 1);  // a build without the BLAS backend
  } else {
    REQUIRE(r.code == 0);
    REQUIRE(run(pair + dir + "/b").code == 0);
    CHECK(loss_rows(dir + "/a") == loss_rows(dir + "/b"));  // bit for bit
    CHECK(settings(dir + "/a")["settings"]["gemm"] == "blas");
    CHECK(settings(dir + "/a")["gemm"]["asked"] == "blas");
    // Stopped and resumed: the checkpoint's backend, the same trajectory.
    const std::string one = " --iters 8 --gemm blas" + kSmall;
    REQUIRE(run("fit builtin:sphere -o " + dir + "/straight" + one).code == 0);
    REQUIRE(run("fit builtin:sphere -o " + dir + "/stopped --stop-at 4" + one).code == 0);
    r = run("fit --resume " + dir + "/stopped -q");
    REQUIRE(r.code == 0);
    CHECK(loss_rows(dir + "/stopped") == loss_rows(dir + "/straight"));
    CHECK(settings(dir + "/stopped")["settings"]["gemm"] == "blas");
    CHECK(settings(dir + "/stopped")["gemm"]["asked"] == "blas");  // the first record, kept
  }
  r = run("fit builtin:sphere -o " + dir + "/bad --gemm fast" + kSmall);
  CHECK(r.code == 2);
  CHECK(count_lines(r.output) == 1);
  CHECK(r.output.find("--gemm") != std::string::npos);
  // The default, auto, with no cache: Eigen, not measured, and said so.
  const std::string quiet_off = kSmall.substr(0, kSmall.size() - 3) + " --iters 2";
  r = run("fit builtin:sphere -o " + dir + "/auto" + quiet_off);
  INFO(r.output);
  REQUIRE(r.code == 0);
  CHECK(r.output.find(no_blas ? "fit: GEMMs by eigen: this jsatlas has no BLAS backend"
                              : "fit: GEMMs by eigen: no cache") != std::string::npos);
  CHECK(settings(dir + "/auto")["settings"]["gemm"] == "eigen");
  CHECK(settings(dir + "/auto")["gemm"]["asked"] == "auto");
  // With a cache (a file of this test's): measured by the first run, read by the second.
  const std::string cache = dir + "/cache/gemm.json";
  setenv("JSATLAS_GEMM_CACHE", cache.c_str(), 1);
  const Result measured = run("fit builtin:sphere -o " + dir + "/measured" + quiet_off);
  const Result cached = run("fit builtin:sphere -o " + dir + "/cached --gemm auto" + quiet_off);
  unsetenv("JSATLAS_GEMM_CACHE");
  INFO(measured.output << cached.output);
  REQUIRE(measured.code == 0);
  REQUIRE(cached.code == 0);
  const nlohmann::json first = settings(dir + "/measured"), second = settings(dir + "/cached");
  CHECK(first["settings"]["gemm"] == second["settings"]["gemm"]);
  CHECK(loss_rows(dir + "/measured") == loss_rows(dir + "/cached"));  // the probe leaves no trace
  if (first["gemm"]["blas"] != "") {
    CHECK(first["gemm"]["source"] == "measured");
    CHECK(first["gemm"]["eigen_ms"] > 0);
    CHECK(first["gemm"]["blas_ms"] > 0);
    CHECK(second["gemm"]["source"] == "cache");
    CHECK(second["gemm"]["blas_ms"].get<double>() ==
          Approx(first["gemm"]["blas_ms"].get<double>()));
    CHECK(measured.output.find(", kept in " + cache) != std::string::npos);
    CHECK(cached.output.find("from the cache " + cache) != std::string::npos);
  }
}

TEST_CASE("cli: --template-coverage takes the template whose registration covers the others",
          "[cli]") {
  const std::string dir = fresh_dir("register_template");
  const std::string small =
      " -K 200 -M 200 --width 16 --depth 2 --threads 1 --pool 5000 --mesh-resolution 32";
  // --no-align: the pose step's 25 candidate rotations of near-symmetric
  // shapes (a sphere, capsules) were most of this test's time, under the
  // sanitizers most of CI's; the pose step has tests of its own.
  const Result r = run("fit builtin:capsule builtin:sphere builtin:capsule -o " + dir +
                       " --template-steps 3 --iters 2 --code-size 8 --deform-nodes 16 --register "
                       "--template-coverage --no-align" +
                       small);
  INFO(r.output);
  REQUIRE(r.code == 0);
  const std::string said = "), whose registration covers the others best";
  const auto at = r.output.find(said);
  REQUIRE(at != std::string::npos);
  CHECK(r.output.find("the medoid") == std::string::npos);
  // "fit: template shape I (FILE), whose ...": the shape said is the one saved.
  const auto line = r.output.rfind("fit: template shape ", at);
  REQUIRE(line != std::string::npos);
  const int said_shape = std::stoi(r.output.substr(line + 20));
  const std::string config = read_text(dir + "/config.json");
  const auto saved = config.find("\"template_shape\": ");
  REQUIRE(saved != std::string::npos);
  CHECK(std::stoi(config.substr(saved + 18)) == said_shape);
  CHECK(r.output.find("spectral maps from the template (shape " + std::to_string(said_shape)) !=
        std::string::npos);
}

// --auto-register (model/tool/registration_check.h), on for collections of
// meshes: the decision is printed with its figures, and what it decided is
// what config.json keeps (the nodes a resumed run rebuilds); 0 asks nothing.
TEST_CASE("cli: a collection of meshes decides on its registration and keeps the decision",
          "[cli]") {
  const std::string dir = fresh_dir("auto_register");
  const std::string small =
      " -K 200 -M 200 --width 16 --depth 2 --threads 1 --pool 5000 --mesh-resolution 24"
      " --template-steps 3 --iters 2 --code-size 8 --checkpoint-every 0 --no-align";  // as above
  auto settings = [](const std::string& run) {
    return nlohmann::json::parse(read_text(run + "/config.json"))["settings"];
  };
  Result r = run("fit builtin:capsule builtin:capsule -o " + dir + "/same" + small);
  INFO(r.output);
  REQUIRE(r.code == 0);
  // Two copies of one mesh: every map comes back where it started, and the
  // registration (the identity) is trusted.
  CHECK(r.output.find("fit: the template's spectral maps come back 0 x 1e-2 off, the nearest "
                      "points 0") != std::string::npos);
  CHECK(r.output.find("registration as the start (--deform-nodes 256 --register "
                      "--nodes-lr-scale 0)") != std::string::npos);
  nlohmann::json s = settings(dir + "/same");
  CHECK(s["auto_register"] == 2.0);
  CHECK(s["atlas"]["deform_nodes"] == 256);
  CHECK(s["register_nodes"] == true);
  CHECK(s["nodes_lr_scale"] == 0.0);
  // Asked for nothing: no check, no nodes.
  r = run("fit builtin:capsule builtin:torus -o " + dir + "/never --auto-register 0" + small);
  REQUIRE(r.code == 0);
  CHECK(r.output.find("spectral maps come back") == std::string::npos);
  s = settings(dir + "/never");
  CHECK(s["atlas"]["deform_nodes"] == 0);
  CHECK(s["register_nodes"] == false);
  // Whatever a pair of different shapes decides, config.json says the same.
  r = run("fit builtin:capsule builtin:torus -o " + dir + "/pair" + small);
  REQUIRE(r.code == 0);
  // Two shapes have no medoid: the first is the template, and the run says so.
  CHECK(r.output.find("fit: template shape 0 (builtin:capsule), the first of two") !=
        std::string::npos);
  const bool trusted = r.output.find("registration as the start") != std::string::npos;
  CHECK((trusted || r.output.find("): no registration") != std::string::npos));
  s = settings(dir + "/pair");
  CHECK(s["register_nodes"] == trusted);
  CHECK(s["atlas"]["deform_nodes"] == (trusted ? 256 : 0));
}
