#include "model/tool/loss_log.h"

#include <fstream>
#include <sstream>

#include "io/atomic_write.h"

namespace jsa {

static const char* kHeader =
    "iteration,lr,total,surface_6d,chart_2d,cycle_2d,cycle_6d,isometry,repulsion";

void write_loss_log(const std::string& path, const LossLog& log) {
  write_file_atomically(path, [&](std::ostream& out) {
    out << kHeader << "\n";
    out.precision(8);
    for (const auto& r : log.rows)
      out << r.iteration << "," << r.lr << "," << r.terms.total << "," << r.terms.surface << ","
          << r.terms.chart << "," << r.terms.cycle_2d << "," << r.terms.cycle_6d << ","
          << r.terms.isometry << "," << r.terms.repulsion << "\n";
  });
}

LossLog read_loss_log(const std::string& path, int64_t up_to) {
  LossLog log;
  std::ifstream in(path);
  if (!in) return log;
  std::string line;
  std::getline(in, line);
  int lineno = 1;
  while (std::getline(in, line)) {
    ++lineno;
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream s(line);
    LossLog::Row r;
    if (!(s >> r.iteration >> r.lr >> r.terms.total >> r.terms.surface >> r.terms.chart >>
          r.terms.cycle_2d >> r.terms.cycle_6d >> r.terms.isometry >> r.terms.repulsion))
      throw InputError(path + ":" + std::to_string(lineno) + ": malformed loss row");
    if (r.iteration <= up_to) log.rows.push_back(r);
  }
  return log;
}

}  // namespace jsa
