// Fuzz target: read_keypoints on a SHREC .vts file, checked against a 100-vertex
// mesh (so indices beyond it must be refused) and without a mesh.
#include "io/keypoints.h"
#include "test/fuzz/fuzz_input_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = jsa_fuzz::write_input(data, size, "keypoints.vts");
  jsa_fuzz::expect_only_input_errors([&] { jsa::read_keypoints(path, 100); });
  jsa_fuzz::expect_only_input_errors([&] { jsa::read_keypoints(path); });
  return 0;
}
