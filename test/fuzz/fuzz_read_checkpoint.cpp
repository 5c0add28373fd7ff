// Fuzz target: read_checkpoint on model.ckpt. Random bytes almost never carry a
// valid trailing FNV-1a checksum, so the parser behind it would go unexplored:
// when the first byte is odd we drop it and append the right checksum to the
// rest, so that half the inputs reach the table of contents and the sections.
// The settings section of a checkpoint that parses is then read as FitOptions
// and the training state restored, as --resume does.
#include <cstring>

#include "model/tool/checkpoint.h"
#include "model/tool/fit_config.h"
#include "test/fuzz/fuzz_input_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string bytes(reinterpret_cast<const char*>(data), size);
  if (size > 0 && (data[0] & 1)) {
    bytes.erase(0, 1);
    const uint64_t sum = jsa::checkpoint_checksum(bytes.data(), bytes.size());
    bytes.append(reinterpret_cast<const char*>(&sum), sizeof sum);
  }
  const std::string path = jsa_fuzz::write_input(reinterpret_cast<const uint8_t*>(bytes.data()),
                                                 bytes.size(), "model.ckpt");
  jsa_fuzz::expect_only_input_errors([&] {
    const jsa::CheckpointContents contents = jsa::read_checkpoint(path);
    jsa::FitOptions o = jsa::fit_options_from_json(contents.settings_json, path);
    // The trainer's sections too (parameters, optimiser, RNG, iteration), as
    // --resume reads them, when the model they describe is small enough to build.
    if (o.atlas.gaussians > 1000 || o.atlas.width > 64 || o.atlas.hidden_layers > 4 ||
        contents.inputs.size() > 4 || o.atlas.code_size > 64 || o.points > 256)
      return;
    o.threads = 1;
    jsa::Block<double> pool = jsa::Block<double>::Zero(16, 6);
    for (jsa::Index i = 0; i < pool.rows(); ++i)
      pool.row(i) << double(i), double(i % 3), 1, 0, 0, 1;
    jsa::Trainer trainer(o, std::vector<jsa::Block<double>>(contents.inputs.size(), pool));
    jsa::restore_trainer(trainer, contents, path);
  });
  return 0;
}
