// Fuzz target: read_checkpoint on model.ckpt. Random bytes almost never carry a
// valid trailing FNV-1a checksum, so the parser behind it would go unexplored:
// when the first byte is odd we drop it and append the right checksum to the
// rest, so that half the inputs reach the section parsing. The settings section
// of a checkpoint that parses is then read as FitOptions, as --resume does.
#include <cstring>

#include "model/tool/checkpoint.h"
#include "model/tool/fit_config.h"
#include "test/fuzz/fuzz_input_file.h"

namespace {

// The checkpoint's checksum (model/tool/checkpoint.cpp): 64-bit FNV-1a.
uint64_t fnv1a(const uint8_t* p, size_t n) {
  uint64_t h = 1469598103934665603ull;
  for (size_t i = 0; i < n; ++i) {
    h ^= p[i];
    h *= 1099511628211ull;
  }
  return h;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string bytes(reinterpret_cast<const char*>(data), size);
  if (size > 0 && (data[0] & 1)) {
    bytes.erase(0, 1);
    const uint64_t sum = fnv1a(data + 1, size - 1);
    bytes.append(reinterpret_cast<const char*>(&sum), sizeof sum);
  }
  const std::string path = jsa_fuzz::write_input(reinterpret_cast<const uint8_t*>(bytes.data()),
                                                 bytes.size(), "model.ckpt");
  jsa_fuzz::expect_only_input_errors([&] {
    const jsa::CheckpointContents contents = jsa::read_checkpoint(path);
    jsa::fit_options_from_json(contents.settings_json, path);
  });
  return 0;
}
