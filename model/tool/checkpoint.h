// model.ckpt: everything needed to resume a run or use its atlas.
//   "JSATLAS-CKPT" magic, u32 format version, then length-prefixed sections:
//   the inputs (one per shape), the settings (JSON), one normalisation per
//   shape, the trainer state (parameters, Adam, RNG, iteration); and last a 64-bit FNV-1a
//   checksum of all preceding bytes. Written atomically (temp, fsync, rename);
//   a truncated or corrupted file is rejected before anything is loaded.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "io/geometry/normalization.h"
#include "model/tool/trainer.h"

namespace jsa {

struct CheckpointContents {
  std::vector<std::string> inputs;  // what was fitted: paths or "builtin:NAME", one per shape
  std::string settings_json;        // fit_options_to_json of the run
  std::vector<Normalization> normalizations;  // input frame -> unit frame, one per shape
  std::string state;                          // Trainer::save_state bytes
};

void write_checkpoint(const std::string& path, const std::vector<std::string>& inputs,
                      const FitOptions& options, const std::vector<Normalization>& normalizations,
                      const Trainer& trainer);
// Reads and verifies (magic, version, sizes, checksum); throws InputError.
CheckpointContents read_checkpoint(const std::string& path);
// Restores a trainer built from contents.settings_json.
void restore_trainer(Trainer& trainer, const CheckpointContents& contents, const std::string& path);
// The atlas alone (no optimiser), for the commands that use a finished run.
std::unique_ptr<Atlas<float>> load_atlas(const CheckpointContents& contents,
                                         const std::string& path);

}  // namespace jsa
