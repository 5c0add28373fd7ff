// The checkpoint keeps each shape's pose (the rotation of the collections'
// pose step) inside the normalisation section of format 2; a frame written
// without one reads as the identity, and a rotation that is not one is refused.
#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <iterator>

#include "model/tool/checkpoint.h"
#include "test/scratch.h"
#include "test/sphere_pool.h"

using namespace jsa;

namespace {

FitOptions tiny_options() {
  FitOptions o;
  o.atlas.gaussians = 64;
  o.atlas.width = 16;
  o.atlas.hidden_layers = 2;
  o.points = 64;
  o.iterations = 10;
  o.pool = 1000;
  return o;
}

std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Rewrites a checkpoint after an edit of equal length: same table of contents,
// new trailing checksum.
void rewrite(const std::string& path, std::string bytes) {
  bytes.resize(bytes.size() - sizeof(uint64_t));
  const uint64_t sum = checkpoint_checksum(bytes.data(), bytes.size());
  bytes.append(reinterpret_cast<const char*>(&sum), sizeof sum);
  std::ofstream(path, std::ios::binary) << bytes;
}

}  // namespace

TEST_CASE("checkpoint: each shape's rotation is written and read back", "[checkpoint]") {
  const test_support::ScratchDir dir("ckpt");
  const std::vector<Block<double>> pools = {test_support::sphere_pool(500, 1),
                                            test_support::sphere_pool(500, 2)};
  const FitOptions o = tiny_options();
  Trainer trainer(o, pools);
  Normalization a, b;
  a.center = Eigen::RowVector3d(1, 2, 3);
  a.scale = 2;
  b.rotation = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, -1).normalized()).toRotationMatrix();
  const std::string path = dir.path + "/model.ckpt";
  write_checkpoint(path, {"builtin:sphere", "builtin:torus"}, o, {a, b}, trainer);
  const CheckpointContents c = read_checkpoint(path);
  REQUIRE(c.normalizations.size() == 2);
  CHECK(c.normalizations[0].rotation == Eigen::Matrix3d::Identity());
  CHECK(c.normalizations[0].center == a.center);
  CHECK(c.normalizations[0].scale == 2);
  // JSON numbers round-trip doubles exactly.
  CHECK(c.normalizations[1].rotation == b.rotation);

  SECTION("a frame without a rotation reads as the identity") {
    std::string bytes = read_all(path);
    size_t at = 0;
    int renamed = 0;
    while ((at = bytes.find("\"rotation\"", at)) != std::string::npos) {
      bytes.replace(at, 10, "\"rotatiox\"");  // an unknown key of the same length
      ++renamed;
    }
    REQUIRE(renamed == 2);
    rewrite(path, bytes);
    const CheckpointContents old = read_checkpoint(path);
    CHECK(old.normalizations[1].rotation == Eigen::Matrix3d::Identity());
    CHECK(old.normalizations[0].center == a.center);
  }
  SECTION("a matrix that is not a rotation is refused") {
    std::string bytes = read_all(path);
    const size_t at = bytes.find("\"rotation\":[[1.0,");
    REQUIRE(at != std::string::npos);
    bytes.replace(at + 13, 3, "2.0");
    rewrite(path, bytes);
    CHECK_THROWS_WITH(read_checkpoint(path), Catch::Contains("bad rotation"));
  }
}
