// model.ckpt: everything needed to resume a run or use its atlas, as named
// sections, so that no reader depends on where a part sits in the file.
//
//   "JSATLAS-CKPT"  magic, 12 bytes
//   u32             format version (2; version 1 had no table of contents)
//   u32             section count S
//   S entries       table of contents: name (16 bytes, NUL-padded), u64 offset
//                   from the start of the file, u64 size
//   payloads        the sections, in table order, back to back
//   u64             64-bit FNV-1a checksum of every preceding byte
//
// Sections (all required): "inputs" (JSON list of what was fitted), "settings"
// (fit_options_to_json), "normalisation" (JSON, one frame per shape: centre,
// scale and rotation, rows; a frame without a rotation reads as the identity),
// "parameters", "optimiser", "rng", "iteration" (the Trainer's state, see
// TrainerState in model/tool/trainer.h). Written atomically (temp, fsync, rename); a
// truncated or corrupted file is rejected before anything is loaded.
#pragma once
#include <cstddef>
#include <cstdint>
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
  TrainerState state;                         // parameters, optimiser, RNG, iteration
};

void write_checkpoint(const std::string& path, const std::vector<std::string>& inputs,
                      const FitOptions& options, const std::vector<Normalization>& normalizations,
                      const Trainer& trainer);
// Reads and verifies (magic, version, table of contents, checksum); throws InputError.
CheckpointContents read_checkpoint(const std::string& path);
// The trailing checksum of a checkpoint whose other bytes are data[0, size): the
// 64-bit FNV-1a of them (for tools that build checkpoints byte by byte: the fuzz target).
uint64_t checkpoint_checksum(const char* data, size_t size);
// Restores a trainer built from contents.settings_json.
void restore_trainer(Trainer& trainer, const CheckpointContents& contents, const std::string& path);
// The atlas alone (no optimiser), for the commands that use a finished run.
std::unique_ptr<Atlas<float>> load_atlas(const CheckpointContents& contents,
                                         const std::string& path);

}  // namespace jsa
