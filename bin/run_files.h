// Glue shared by the subcommands: loading a run's input, its loss log, and
// writing the files a finished fit leaves behind.
#pragma once
#include <string>

#include "model/atlas.h"
#include "model/loss_log.h"
#include "model/shape_input.h"

namespace jsa::cli {

std::string json_quote(const std::string& s);
// DIR/domain_mesh.obj (the thresholded domain mapped through phi, in the
// input's frame, with vt and vn).
void write_run_outputs(Atlas<float>& atlas, const RunInput& input, const std::string& dir,
                       int mesh_resolution, double mesh_threshold, bool quiet);

}  // namespace jsa::cli
