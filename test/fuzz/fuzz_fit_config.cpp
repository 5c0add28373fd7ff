// Fuzz target: fit_options_from_json on a config.json text (what --resume reads
// back from a run directory).
#include "model/tool/fit_config.h"
#include "test/fuzz/fuzz_input_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  jsa_fuzz::expect_only_input_errors([&] { jsa::fit_options_from_json(text, "config.json"); });
  return 0;
}
