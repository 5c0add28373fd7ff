// The bad-input cases of docs/bad-input.md that test/cli_errors_test.cpp does not
// already run through the binary: each is one line and exit code 1 (2 for flags),
// except non-manifold and multi-component meshes, which fit with a warning.
#include <catch2/catch.hpp>

#include "test/cli_test_support.h"

using namespace cli_test;

namespace {

// The smallest fit that still writes every output.
const std::string kTiny =
    " --iters 1 -K 2 -M 16 --width 4 --depth 1 --threads 1 --pool 100 --mesh-resolution 8";

// One line of output holding `needle`, and the exit code `code`.
void rejects(const std::string& args, int code, const std::string& needle) {
  const Result r = run(args);
  INFO("jsatlas " << args << "\n" << r.output);
  CHECK(r.code == code);
  CHECK(count_lines(r.output) == 1);
  CHECK(r.output.find(needle) != std::string::npos);
}

const std::string kTetrahedron =
    "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 2 3\n3 0 3 1\n3 1 3 2\n";

}  // namespace

TEST_CASE("cli: bad shape files are rejected with the file and the place", "[cli]") {
  const std::string dir = fresh_dir("bad_input");
  const std::string fit = "fit " + dir + "/";
  const std::string out = " -o " + dir + "/out";
  write_text(dir + "/no_faces.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  rejects(fit + "no_faces.obj" + out, 1, "no_faces.obj: no faces and no normals");
  write_text(dir + "/flat.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n2 0 0\n3 0 1 2\n");
  rejects(fit + "flat.off" + out, 1, "flat.off: all 1 faces are degenerate (zero area)");
  write_text(dir + "/inf.obj", "v 0 0 1e999\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  rejects(fit + "inf.obj" + out, 1, "inf.obj:vertex 0: coordinate is NaN or infinite");
  write_text(dir + "/inf.off", "OFF\n3 1 0\n0 0 0\ninf 1 0\n0 1 0\n3 0 1 2\n");
  rejects(fit + "inf.off" + out, 1, "inf.off:line 4: 'inf' is not a finite number");
  write_text(dir + "/negative.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n");
  rejects(fit + "negative.off" + out, 1,
          "negative.off:line 6: vertex index '-1' is not an integer in [0, 3)");
  write_text(dir + "/nul.obj", std::string("v 0 0 0\n\x7f\x00\x01garbage", 18));
  rejects(fit + "nul.obj" + out, 1, "nul.obj:line 2: binary data (NUL byte at offset 9)");
  std::string garbage;
  for (int i = 0; i < 256; ++i) garbage += char((i * 37 + 11) % 256);
  write_text(dir + "/garbage.ply", garbage);
  rejects(fit + "garbage.ply" + out, 1, "garbage.ply:line 1: not a PLY file");
  const std::string header =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n";
  write_text(dir + "/truncated.ply", header + std::string(20, '\0'));  // 3 vertices need 36 bytes
  rejects(fit + "truncated.ply" + out, 1,
          "truncated.ply:line 3: declares 3 'vertex' rows, but only 20 bytes");
  write_text(dir + "/cut.ply", header.substr(0, header.size() - 4));
  rejects(fit + "cut.ply" + out, 1, "cut.ply:line 7: the header has no 'end_header' line");
  write_text(dir + "/comments.xyz", "# no points here\n");
  rejects(fit + "comments.xyz" + out, 1, "comments.xyz: no points");
}

TEST_CASE("cli: non-manifold and multi-component meshes fit, with a warning", "[cli]") {
  const std::string dir = fresh_dir("odd_topology");
  // Three triangles on the edge 0-1 (a book of three pages).
  write_text(dir + "/book.off",
             "OFF\n5 3 0\n0 0 0\n1 0 0\n0 1 0\n0 -1 0.5\n0 0 1\n3 0 1 2\n3 0 1 3\n3 0 1 4\n");
  Result r = run("fit " + dir + "/book.off -o " + dir + "/book" + kTiny);
  INFO(r.output);
  CHECK(r.code == 0);
  CHECK(r.output.find("warning: " + dir + "/book.off: 1 non-manifold edges") != std::string::npos);
  write_text(dir + "/two.off",
             "OFF\n6 2 0\n0 0 0\n1 0 0\n0 1 0\n5 0 0\n6 0 0\n5 1 0\n3 0 1 2\n3 3 4 5\n");
  r = run("fit " + dir + "/two.off -o " + dir + "/two" + kTiny);
  INFO(r.output);
  CHECK(r.code == 0);
  CHECK(r.output.find("warning: " + dir + "/two.off: mesh has 2 connected components") !=
        std::string::npos);
}

TEST_CASE("cli: keypoint indices beyond the mesh are rejected with file and line", "[cli]") {
  const std::string dir = fresh_dir("keypoints");
  write_text(dir + "/a.off", kTetrahedron);
  write_text(dir + "/b.off", kTetrahedron);
  REQUIRE(run("fit " + dir + "/a.off " + dir + "/b.off -o " + dir + "/run -q" + kTiny).code == 0);
  write_text(dir + "/a.vts", "0\n1\n");
  write_text(dir + "/b.vts", "0 0 0 0\n7 1 0 0\n");
  const std::string eval = "eval-corr " + dir + "/run --keypoints " + dir + "/a.vts ";
  rejects(eval + dir + "/b.vts", 1, "b.vts:2: vertex index 7 is beyond the mesh's 4 vertices");
  write_text(dir + "/b.vts", "0\n-2\n");
  rejects(eval + dir + "/b.vts", 1, "b.vts:2: negative vertex index -2");
  write_text(dir + "/b.vts", "0\nseven\n");
  rejects(eval + dir + "/b.vts", 1, "b.vts:2: expected a vertex index, got 'seven'");
  rejects(eval + dir + "/missing.vts", 1, "missing.vts");
  // The spectral refinement on a tetrahedron: fewer vertices than eigenfunctions.
  write_text(dir + "/b.vts", "0\n1\n");
  rejects(eval + dir + "/b.vts --spectral", 1,
          "shape 0 has 4 vertices, fewer than 60 eigenfunctions (--spectral-functions)");
  rejects(eval + dir + "/b.vts --spectral-functions 1", 2, "--spectral-functions");
  // The geodesic refinement takes at most every vertex as a landmark.
  const Result g = run(eval + dir + "/b.vts --geodesic --snap");
  INFO(g.output);
  CHECK(g.code == 0);
  CHECK(g.output.find("finished by 256 geodesic landmarks, snapped to the target's vertices") !=
        std::string::npos);
  rejects(eval + dir + "/b.vts --geodesic-landmarks 0", 2, "--geodesic-landmarks");
  rejects(eval + dir + "/b.vts --geodesic-tau -1", 2, "--geodesic-tau");
}

TEST_CASE("cli: flag values out of range are refused before any work", "[cli]") {
  const std::string fit = "fit builtin:sphere -o " + fresh_dir("flags") + "/out ";
  rejects(fit + "--width 2", 2, "--width: Value 2 not in range 4 to 4096");
  rejects(fit + "--depth 0", 2, "--depth");
  rejects(fit + "--threads -1", 2, "--threads");
  rejects(fit + "--decay 2", 2, "--decay");
  rejects(fit + "--pool 10", 2, "--pool: Value 10 not in range 100 to 10000000");
  rejects(fit + "--w-iso -1", 2, "--w-iso");
  rejects(fit + "--alpha inf", 2, "--alpha");
  rejects(fit + "--surface-lr-scale -1", 2, "--surface-lr-scale");
  // D reading the domain point exists only in a deformed collection.
  rejects(fit + "--deform-domain", 1, "--deform-domain: needs a collection");
  rejects(fit + "--intrinsic -0.5", 2, "--intrinsic");
  rejects(fit + "--intrinsic 0.5", 1, "--intrinsic: needs a collection");
  rejects(fit + "--spectral-map -1", 2, "--spectral-map");
  rejects(fit + "--spectral-map-until 1.5", 2, "--spectral-map-until");
  rejects(fit + "--w-metric-until 1.5", 2, "--w-metric-until");
  // 0 is in the flag's range; the run's settings refuse it (exit 1, as a setting).
  rejects(fit + "--w-metric-until 0", 1, "--w-metric-until must be in (0, 1]");
  rejects(fit + "--spectral-map 1", 1, "--spectral-map: needs a collection");
  // The node displacement and its registration: collections only, nodes first.
  rejects(fit + "--deform-nodes -1", 2, "--deform-nodes");
  rejects(fit + "--deform-nodes 64", 1, "--deform-nodes: needs a collection");
  rejects(fit + "--nodes-width 0", 2, "--nodes-width");
  rejects(fit + "--nodes-lr-scale -1", 2, "--nodes-lr-scale");
  rejects(fit + "--register-prior -1", 2, "--register-prior");
  const std::string pair = "fit builtin:sphere builtin:torus -o " + fresh_dir("flags") + "/pair ";
  rejects(pair + "--register", 1, "--register: needs --deform-nodes > 0");
  rejects(pair + "--fine-nodes 16", 1,
          "--fine-nodes: a second field of nodes, needs --deform-nodes");
  rejects(fit + "--fine-width 0", 2, "--fine-width");
  rejects(fit + "--chart-width -1", 2, "--chart-width");
  rejects(fit + "--chart-fourier -1", 2, "--chart-fourier");
  rejects(fit + "--chart-fourier-sigma 0", 2, "--chart-fourier-sigma");
  rejects(pair + "--template-coverage --template-shape 1", 1, "--template-coverage: chooses");
  rejects(fit + "--template-coverage", 1, "--template-coverage: chooses");
  rejects(pair + "--deform-nodes 16 --template-steps 0", 1,
          "--deform-nodes: needs the template start");
}
