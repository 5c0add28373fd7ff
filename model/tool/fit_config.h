// FitOptions <-> JSON, so a run's settings are written next to its results
// (config.json), stored in its checkpoint, and read back on --resume.
#pragma once
#include <string>

#include "model/tool/trainer.h"

namespace jsa {

std::string fit_options_to_json(const FitOptions& o, int indent = 2);
// Throws InputError naming the field when a value is missing or of the wrong type.
FitOptions fit_options_from_json(const std::string& text, const std::string& what);

}  // namespace jsa
