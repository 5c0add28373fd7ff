// The shared harness of the file-reading fuzz targets: libFuzzer hands us bytes,
// the readers want a path. We write the bytes to one temp file per process (its
// extension chooses the reader) and treat jsa::InputError as the only allowed
// failure; anything else (another exception, a crash, a hang, a sanitizer report)
// is a bug and aborts so that libFuzzer saves the input.
#pragma once
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>

#include "engine/check.h"

namespace jsa_fuzz {

// The process's scratch directory "<tmp>/jsatlas_fuzz_<pid>", removed at exit.
struct ScratchDir {
  std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("jsatlas_fuzz_" + std::to_string(::getpid()));
  ScratchDir() { std::filesystem::create_directories(path); }
  ~ScratchDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
};

// "<scratch>/<file_name>" holding the bytes, rewritten on every call.
inline std::string write_input(const uint8_t* data, size_t size, const std::string& file_name) {
  static const ScratchDir dir;
  const std::string path = (dir.path / file_name).string();
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), std::streamsize(size));
  return path;
}

// Runs `read`; InputError is the expected outcome for bad bytes, anything else aborts.
template <class Read>
void expect_only_input_errors(Read read) {
  try {
    read();
  } catch (const jsa::InputError&) {
    // bad input, reported the way users see it: fine
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz: unexpected exception (not jsa::InputError): %s\n", e.what());
    std::abort();
  } catch (...) {
    std::fprintf(stderr, "fuzz: unexpected non-std exception\n");
    std::abort();
  }
}

}  // namespace jsa_fuzz
