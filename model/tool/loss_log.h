// The per-iteration record of every loss term, and of every NaN/Inf recovery:
// DIR/losses.csv.
#pragma once
#include <string>
#include <vector>

#include "model/objective.h"
#include "model/tool/trainer.h"

namespace jsa {

struct LossLog {
  struct Row {
    int64_t iteration;
    double lr;
    LossTerms terms;
    int faults = 0;  // recoveries before this row
  };
  struct Fault {
    double lr;        // the learning rate of the failed step
    LossTerms terms;  // what it computed (a NaN or Inf somewhere)
    FaultRecovery recovery;
  };
  std::vector<Row> rows;      // one per iteration kept, increasing
  std::vector<Fault> faults;  // in the order they happened
};

// Adds what one step did: a row, or for a fault the fault and what was done,
// dropping the rows of the iterations the fault undid (they are redone).
void record_step(LossLog& log, const StepReport& step);

// Atomic rewrite of the whole file (it is small: ~100 bytes per iteration).
// Columns: iteration, lr, the loss terms, faults (recoveries so far), event.
// A fault is a row of its own at the iteration its step started from, with the
// values it computed and event "fault: restored iteration R; lr scale S",
// placed after row R (the state it went back to).
void write_loss_log(const std::string& path, const LossLog& log);
// Rows with iteration <= up_to, and the first max_faults faults (all if < 0)
// that went back to an iteration <= up_to; a missing file gives an empty log.
LossLog read_loss_log(const std::string& path, int64_t up_to, int max_faults = -1);

}  // namespace jsa
