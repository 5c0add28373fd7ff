// Tests for io/input_file: the shared open checks and the shape of error messages.
#include <sys/stat.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>

#include "engine/check.h"
#include "io/input_file.h"
#include "test/scratch.h"

using test_support::message_of;
using test_support::ScratchDir;

namespace {}  // namespace

TEST_CASE("read_input_file returns the bytes of a file", "[io][input_file]") {
  ScratchDir dir;
  const std::string path = dir.file("a.txt", std::string("ab\0c", 4));
  CHECK(jsa::read_input_file(path) == std::string("ab\0c", 4));
}

TEST_CASE("read_input_file rejects missing, directory and empty paths, naming them",
          "[io][input_file]") {
  ScratchDir dir;
  const std::string missing = dir.path + "/nope.obj";
  const std::string empty = dir.file("empty.obj", "");
  const std::string m1 = message_of([&] { jsa::read_input_file(missing); });
  CHECK(m1.find(missing) == 0);
  CHECK(m1.find("No such file") != std::string::npos);
  const std::string m2 = message_of([&] { jsa::read_input_file(dir.path); });
  CHECK(m2.find(dir.path) == 0);
  CHECK(m2.find("directory") != std::string::npos);
  const std::string m3 = message_of([&] { jsa::read_input_file(empty); });
  CHECK(m3.find(empty) == 0);
  CHECK(m3.find("empty") != std::string::npos);
}

TEST_CASE("reject_binary_bytes names the line of the first NUL byte", "[io][input_file]") {
  CHECK_NOTHROW(jsa::reject_binary_bytes("f.off", "OFF\n1 2 3\n"));
  const std::string m =
      message_of([] { jsa::reject_binary_bytes("f.off", std::string("OFF\n1 2\0 3\n", 11)); });
  CHECK(m.find("f.off:line 2: binary data") == 0);
}

TEST_CASE("input_error formats path, where and what on one line", "[io][input_file]") {
  CHECK(message_of([] { jsa::input_error("x.ply", "line 3", "bad"); }) == "x.ply:line 3: bad");
  CHECK(message_of([] { jsa::input_error("x.ply", "", "bad"); }) == "x.ply: bad");
}

TEST_CASE("extension_of lower-cases and ignores dots in directories", "[io][input_file]") {
  CHECK(jsa::extension_of("a/b.OBJ") == ".obj");
  CHECK(jsa::extension_of("a.dir/file") == "");
  CHECK(jsa::extension_of("shape.tar.ply") == ".ply");
}
