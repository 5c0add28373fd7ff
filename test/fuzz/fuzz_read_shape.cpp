// Fuzz target: read_shape on a file whose extension is JSATLAS_FUZZ_EXTENSION
// (".obj", ".off", ".ply" or ".xyz"), one executable per extension. The whole
// path a user's file takes is exercised: format parser, then validate_mesh.
#include "io/mesh_io.h"
#include "test/fuzz/fuzz_input_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path =
      jsa_fuzz::write_input(data, size, std::string("shape") + JSATLAS_FUZZ_EXTENSION);
  jsa_fuzz::expect_only_input_errors([&] { jsa::read_shape(path); });
  return 0;
}
