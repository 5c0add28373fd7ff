#include "model/tool/loss_log.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "io/atomic_write.h"

namespace jsa {

static const char* kHeader =
    "iteration,lr,total,surface_6d,chart_2d,cycle_2d,cycle_6d,isometry,repulsion,faults,event";

void record_step(LossLog& log, const StepReport& step) {
  if (!step.fault) {
    log.rows.push_back({step.iteration, step.lr, step.terms, step.faults});
    return;
  }
  const int64_t restored = step.fault->restored;
  log.rows.erase(std::remove_if(log.rows.begin(), log.rows.end(),
                                [&](const LossLog::Row& r) { return r.iteration > restored; }),
                 log.rows.end());
  log.faults.push_back({step.lr, step.terms, *step.fault});
}

void write_loss_log(const std::string& path, const LossLog& log) {
  write_file_atomically(path, [&](std::ostream& out) {
    out << kHeader << "\n";
    out.precision(8);
    auto terms = [&](const LossTerms& t) {
      out << t.total << "," << t.surface << "," << t.chart << "," << t.cycle_2d << "," << t.cycle_6d
          << "," << t.isometry << "," << t.repulsion;
    };
    size_t f = 0;
    auto faults_up_to = [&](int64_t iteration) {  // the faults that went back to <= iteration
      for (; f < log.faults.size() && log.faults[f].recovery.restored <= iteration; ++f) {
        const LossLog::Fault& e = log.faults[f];
        out << e.recovery.iteration << "," << e.lr << ",";
        terms(e.terms);
        out << "," << f + 1 << ",fault: restored iteration " << e.recovery.restored << "; lr scale "
            << e.recovery.lr_scale << "\n";
      }
    };
    faults_up_to(-1);
    for (const auto& r : log.rows) {
      faults_up_to(r.iteration - 1);
      out << r.iteration << "," << r.lr << ",";
      terms(r.terms);
      out << "," << r.faults << ",\n";
    }
    faults_up_to(INT64_MAX);
  });
}

LossLog read_loss_log(const std::string& path, int64_t up_to, int max_faults) {
  LossLog log;
  std::ifstream in(path);
  if (!in) return log;
  std::string line;
  std::getline(in, line);
  int lineno = 1;
  while (std::getline(in, line)) {
    ++lineno;
    const std::string where = path + ":" + std::to_string(lineno);
    // Nine numbers (files before the fault columns), or ten and the event.
    std::vector<std::string> fields;
    std::istringstream s(line);
    for (std::string field; std::getline(s, field, ',');) fields.push_back(field);
    if (!line.empty() && line.back() == ',') fields.emplace_back();
    if (fields.size() != 9 && fields.size() != 11) throw InputError(where + ": malformed loss row");
    double v[10] = {};
    for (size_t k = 0; k < std::min<size_t>(fields.size(), 10); ++k) {
      char* end = nullptr;
      v[k] = std::strtod(fields[k].c_str(), &end);  // strtod reads "nan" and "inf" too
      if (fields[k].empty() || *end != '\0') throw InputError(where + ": malformed loss row");
    }
    // The counts as integers (a cast of NaN or 1e300 would be undefined).
    if (!(v[0] >= 0 && v[0] < 1e15 && v[9] >= 0 && v[9] < 1e9))
      throw InputError(where + ": malformed loss row");
    const LossTerms terms{v[2], v[3], v[4], v[5], v[6], v[7], v[8]};
    const std::string event = fields.size() == 11 ? fields[10] : std::string();
    if (event.empty()) {
      if (int64_t(v[0]) <= up_to) log.rows.push_back({int64_t(v[0]), v[1], terms, int(v[9])});
      continue;
    }
    LossLog::Fault f{v[1], terms, {}};
    f.recovery.iteration = int64_t(v[0]);
    long long restored = 0;
    if (std::sscanf(event.c_str(), "fault: restored iteration %lld; lr scale %lf", &restored,
                    &f.recovery.lr_scale) != 2)
      throw InputError(where + ": unknown event '" + event + "'");
    f.recovery.restored = restored;
    if (f.recovery.restored <= up_to && (max_faults < 0 || int(log.faults.size()) < max_faults))
      log.faults.push_back(f);
  }
  return log;
}

}  // namespace jsa
