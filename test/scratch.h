// Shared by the io tests: a scratch directory that cleans up after itself, and
// the message of the InputError an action throws.
#pragma once
#include <stdlib.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include "engine/check.h"

namespace test_support {

// A fresh directory under /tmp, removed with everything in it at the end of the test.
struct ScratchDir {
  std::string path;
  explicit ScratchDir(const std::string& tag = "io") {
    std::string pattern = "/tmp/jsatlas_" + tag + "_XXXXXX";
    path = ::mkdtemp(pattern.data());
  }
  ~ScratchDir() { std::filesystem::remove_all(path); }
  std::string file(const std::string& name, const std::string& bytes) const {
    const std::string full = path + "/" + name;
    std::ofstream(full, std::ios::binary) << bytes;
    return full;
  }
};

inline std::string message_of(const std::function<void()>& action) {
  try {
    action();
  } catch (const jsa::InputError& e) {
    return e.what();
  }
  return "<no InputError thrown>";
}

}  // namespace test_support
