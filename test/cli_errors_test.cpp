// Bad input on the command line: one clear line, a non-zero exit, no crash, and
// nothing the user had is damaged.
#include <catch2/catch.hpp>

#include "test/cli_test_support.h"

using namespace cli_test;
namespace fs = std::filesystem;

namespace {
// Exactly one line of output (the error), exit code as given, and the message
// contains `needle`.
void expect_error(const std::string& args, int code, const std::string& needle) {
  const Result r = run(args);
  INFO("jsatlas " << args << "\n" << r.output);
  CHECK(r.code == code);
  CHECK(count_lines(r.output) == 1);
  CHECK(r.output.find(needle) != std::string::npos);
}
}  // namespace

TEST_CASE("cli: bad inputs and flags give one line and a non-zero exit", "[cli]") {
  const std::string dir = fresh_dir("errors");
  write_text(dir + "/empty.obj", "");
  write_text(dir + "/nan.off", "OFF\n3 1 0\n0 0 0\nnan 1 0\n0 1 0\n3 0 1 2\n");
  write_text(dir + "/range.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
  write_text(dir + "/garbage.ply",
             std::string("ply\nformat binary_little_endian 1.0\nelement vertex 1000000000\n"
                         "property float x\nproperty float y\nproperty float z\nend_header\n") +
                 std::string(64, '\x7f'));
  write_text(dir + "/shape.xyz", "0 0 0\n1 0 0\n");
  expect_error("fit " + dir + "/missing.obj -o " + dir + "/out", 1, "missing.obj");
  expect_error("fit " + dir + " -o " + dir + "/out", 1, dir);
  expect_error("fit " + dir + "/empty.obj -o " + dir + "/out", 1, "empty.obj");
  expect_error("fit " + dir + "/nan.off -o " + dir + "/out", 1, "nan.off");
  expect_error("fit " + dir + "/range.off -o " + dir + "/out", 1, "range.off");
  expect_error("fit " + dir + "/garbage.ply -o " + dir + "/out", 1, "garbage.ply");
  expect_error("fit " + dir + "/shape.xyz -o " + dir + "/out", 1, "shape.xyz");
  expect_error("fit builtin:nothing -o " + dir + "/out", 1, "nothing");
  expect_error("fit builtin:sphere -o " + dir + "/out --iters -5", 2, "--iters");
  expect_error("fit builtin:sphere -o " + dir + "/out --points 0", 2, "--points");
  expect_error("fit builtin:sphere -o " + dir + "/out --lr nan", 2, "--lr");
  expect_error("fit builtin:sphere -o " + dir + "/out --softplus nan", 2, "--softplus");
  expect_error("fit builtin:sphere -o " + dir + "/out --softplus -1", 2, "--softplus");
  expect_error("fit builtin:sphere -o " + dir + "/out --wrap -3", 2, "--wrap");
  expect_error("fit builtin:sphere -o " + dir + "/out --table-row 3", 2, "--table-row");
  expect_error("fit builtin:sphere -o " + dir + "/out --no-such-flag", 2, "no-such-flag");
  expect_error("fit builtin:sphere", 1, "-o");
  expect_error("mesh " + dir + " -o " + dir + "/m.obj", 1, "model.ckpt");
  expect_error("eval " + dir + "/nowhere", 1, "model.ckpt");
  expect_error("frobnicate", 2, "frobnicate");
}

TEST_CASE("cli: a corrupted or truncated checkpoint is rejected, never half-loaded", "[cli]") {
  const std::string dir = fresh_dir("ckpt");
  REQUIRE(run("fit builtin:sphere -o " + dir +
              " --iters 5 -K 100 -M 100 --width 8 --depth 1 --threads 1 "
              "--pool 1000 --mesh-resolution 16 -q")
              .code == 0);
  const std::string good = read_text(dir + "/model.ckpt");
  std::string flipped = good;
  flipped[flipped.size() / 2] ^= 0x20;
  write_text(dir + "/model.ckpt", flipped);
  expect_error("eval " + dir, 1, "checksum");
  write_text(dir + "/model.ckpt", good.substr(0, good.size() - 100));
  expect_error("eval " + dir, 1, "model.ckpt");
  write_text(dir + "/model.ckpt", "not a checkpoint");
  expect_error("fit --resume " + dir, 1, "not a jsatlas checkpoint");
}

TEST_CASE("cli: a failing output never damages the file the user had", "[cli]") {
  const std::string dir = fresh_dir("keep");
  REQUIRE(run("fit builtin:sphere -o " + dir +
              " --iters 5 -K 100 -M 100 --width 8 --depth 1 --threads 1 "
              "--pool 1000 --mesh-resolution 16 -q")
              .code == 0);
  write_text(dir + "/mine.obj", "precious\n");
  // A threshold no cell reaches: the command fails before writing anything.
  expect_error("mesh " + dir + " -o " + dir + "/mine.obj --threshold 99", 1, "threshold");
  CHECK(read_text(dir + "/mine.obj") == "precious\n");
}

TEST_CASE("cli: --help documents every subcommand", "[cli]") {
  const Result r = run("--help");
  CHECK(r.code == 0);
  for (const char* sub : {"fit", "mesh", "chart", "correspond", "eval", "eval-corr"})
    CHECK(r.output.find(sub) != std::string::npos);
  const Result f = run("fit --help");
  for (const char* flag :
       {"--iters", "--points", "--gaussians", "--lr", "--seed", "--threads", "--w-6d", "--w-2d",
        "--w-cycle", "--w-iso", "--w-rep", "--no-chart", "--resume", "--table-row"})
    CHECK(f.output.find(flag) != std::string::npos);
}
