// Running the jsatlas binary from tests: exit code and captured output.
#pragma once
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace cli_test {

struct Result {
  int code = -1;
  std::string output;  // stdout and stderr together
};

// The cache of `fit --gemm auto` is off unless a test sets JSATLAS_GEMM_CACHE
// itself (to a file of its own): no test writes the user's ~/.cache, run by
// ctest (which sets it off too) or not.
inline Result run(const std::string& args) {
  const std::string cmd = "export JSATLAS_GEMM_CACHE=\"${JSATLAS_GEMM_CACHE:-off}\"; " +
                          std::string(JSATLAS_BINARY) + " " + args + " 2>&1";
  Result r;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  std::array<char, 4096> buf;
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) r.output.append(buf.data(), n);
  const int status = pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return r;
}

// The directories made by fresh_dir, removed when the test program exits
// (set JSATLAS_KEEP_TEST_DIRS=1 to keep them for a look).
struct TestDirs {
  std::vector<std::filesystem::path> made;
  ~TestDirs() {
    if (std::getenv("JSATLAS_KEEP_TEST_DIRS")) return;
    std::error_code ignored;
    for (const auto& d : made) std::filesystem::remove_all(d, ignored);
  }
};
inline TestDirs test_dirs;

// A fresh empty directory under the system temp dir. The process id keeps test
// runs from different checkouts on one machine out of each other's way (a shared
// name failed with "cannot remove: Directory not empty" under concurrent ctest).
inline std::string fresh_dir(const std::string& name) {
  const auto d = std::filesystem::temp_directory_path() /
                 ("jsatlas_test_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  test_dirs.made.push_back(d);
  return d.string();
}

inline void write_text(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

inline std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

inline int count_lines(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

}  // namespace cli_test
