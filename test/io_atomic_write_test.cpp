// Tests for io/atomic_write: complete replacement, and an old file left intact
// (with no temporary left behind) when the writer throws.
#include <unistd.h>

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "engine/check.h"
#include "io/atomic_write.h"

namespace {

struct ScratchDir {
  std::string path;
  ScratchDir() {
    char pattern[] = "/tmp/jsatlas_io_atomic_XXXXXX";
    path = ::mkdtemp(pattern);
  }
  ~ScratchDir() { std::filesystem::remove_all(path); }
  std::size_t entries() const {
    std::size_t count = 0;
    for (const auto& entry : std::filesystem::directory_iterator(path)) (void)entry, ++count;
    return count;
  }
};

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

}  // namespace

TEST_CASE("write_file_atomically creates and replaces files", "[io][atomic_write]") {
  ScratchDir dir;
  const std::string path = dir.path + "/out.txt";
  jsa::write_file_atomically(path, [](std::ostream& out) { out << "first"; });
  CHECK(slurp(path) == "first");
  jsa::write_file_atomically(path, [](std::ostream& out) { out << "second, longer"; });
  CHECK(slurp(path) == "second, longer");
  CHECK(dir.entries() == 1);
  CHECK((std::filesystem::status(path).permissions() & std::filesystem::perms::owner_read) !=
        std::filesystem::perms::none);
}

TEST_CASE("a throwing writer leaves the old file intact and no temporary", "[io][atomic_write]") {
  ScratchDir dir;
  const std::string path = dir.path + "/keep.txt";
  jsa::write_file_atomically(path, [](std::ostream& out) { out << "precious"; });
  CHECK_THROWS_WITH(jsa::write_file_atomically(path,
                                               [](std::ostream& out) {
                                                 out << "half written";
                                                 out.flush();
                                                 throw std::runtime_error("writer failed");
                                               }),
                    "writer failed");
  CHECK(slurp(path) == "precious");
  CHECK(dir.entries() == 1);
}

TEST_CASE("unwritable targets are InputErrors naming the path", "[io][atomic_write]") {
  ScratchDir dir;
  const std::string missing = dir.path + "/no/such/dir/out.txt";
  try {
    jsa::write_file_atomically(missing, [](std::ostream& out) { out << "x"; });
    FAIL("no exception");
  } catch (const jsa::InputError& e) {
    CHECK(std::string(e.what()).find(missing + ": cannot write: directory") == 0);
  }
  CHECK_THROWS_AS(jsa::write_file_atomically(dir.path, [](std::ostream& out) { out << "x"; }),
                  jsa::InputError);
  if (::geteuid() != 0) {  // root ignores permission bits
    const std::string locked = dir.path + "/locked";
    std::filesystem::create_directory(locked);
    std::filesystem::permissions(
        locked, std::filesystem::perms::owner_read | std::filesystem::perms::owner_exec);
    CHECK_THROWS_AS(
        jsa::write_file_atomically(locked + "/out.txt", [](std::ostream& out) { out << "x"; }),
        jsa::InputError);
    std::filesystem::permissions(locked, std::filesystem::perms::owner_all);
  }
}
