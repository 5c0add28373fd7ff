// The per-iteration record of every loss term: DIR/losses.csv.
#pragma once
#include <string>
#include <vector>

#include "model/objective.h"

namespace jsa {

struct LossLog {
  struct Row {
    int64_t iteration;
    double lr;
    LossTerms terms;
  };
  std::vector<Row> rows;
};

// Atomic rewrite of the whole file (it is small: ~100 bytes per iteration).
void write_loss_log(const std::string& path, const LossLog& log);
// Rows with iteration <= up_to; a missing file gives an empty log.
LossLog read_loss_log(const std::string& path, int64_t up_to);

}  // namespace jsa
