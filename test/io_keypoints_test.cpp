// SHREC .vts keypoint files: indices read, coordinates ignored, bad lines named.
#include <catch2/catch.hpp>

#include "io/keypoints.h"
#include "test/scratch.h"

using test_support::message_of;
using test_support::ScratchDir;

TEST_CASE("keypoints: the index of each line, in order; coordinates are ignored",
          "[io][keypoints]") {
  ScratchDir dir("vts");
  const std::string f = dir.file("a.vts", "# comment\n12 0.1 0.2 0.3\n\n0 9 9 9\n7\n");
  CHECK(jsa::read_keypoints(f, 13) == std::vector<int>{12, 0, 7});
  CHECK(jsa::read_keypoints(f) == std::vector<int>{12, 0, 7});
}

TEST_CASE("keypoints: bad files are rejected naming the file and the line", "[io][keypoints]") {
  ScratchDir dir("vts");
  const std::string beyond = dir.file("beyond.vts", "1 0 0 0\n13 0 0 0\n");
  std::string m = message_of([&] { jsa::read_keypoints(beyond, 13); });
  CHECK(m.find("beyond.vts:2") != std::string::npos);
  CHECK(m.find("beyond the mesh's 13 vertices") != std::string::npos);
  m = message_of([&] { jsa::read_keypoints(dir.file("neg.vts", "-1 0 0 0\n"), 10); });
  CHECK(m.find("neg.vts:1: negative vertex index") != std::string::npos);
  m = message_of([&] { jsa::read_keypoints(dir.file("word.vts", "x 0 0 0\n"), 10); });
  CHECK(m.find("word.vts:1: expected a vertex index") != std::string::npos);
  m = message_of([&] { jsa::read_keypoints(dir.file("empty.vts", ""), 10); });
  CHECK(m.find("empty.vts: no keypoints") != std::string::npos);
  m = message_of([&] { jsa::read_keypoints(dir.path, 10); });
  CHECK(m.find("is a directory") != std::string::npos);
  m = message_of([&] { jsa::read_keypoints(dir.path + "/missing.vts", 10); });
  CHECK(m.find("missing.vts: cannot open") != std::string::npos);
}
