// Plots the CSV that bench/quality_vs_time.sh writes: each fit's Chamfer,
// unit-normal error and EMD as ratios to their sampling floors, against its
// wall time, one line per schedule and shape (the mean over the seeds at each
// budget). Several runs' CSVs may be concatenated (repeated headers are skipped).
//   bench_quality_plot RESULTS.csv OUT_PREFIX
//     -> OUT_PREFIX_chamfer.png, OUT_PREFIX_normals.png, OUT_PREFIX_emd.png
#include <cstdio>
#include <exception>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "io/pictures/image.h"
#include "io/pictures/plot.h"

namespace {

struct Point {
  double seconds = 0, chamfer = 0, normals = 0, emd = 0;
  int count = 0;
};

}  // namespace

int main(int argc, char** argv) try {
  if (argc != 3) {
    std::fprintf(stderr, "usage: bench_quality_plot RESULTS.csv OUT_PREFIX\n");
    return 2;
  }
  std::ifstream in(argv[1]);
  if (!in) {
    std::fprintf(stderr, "cannot open %s\n", argv[1]);
    return 1;
  }
  // header: schedule,shape,seed,minutes,wall_s,iterations,chamfer_ratio,normal_ratio,emd_ratio
  std::string line;
  std::getline(in, line);
  std::map<std::string, std::map<double, Point>> lines;  // "schedule shape" -> budget -> mean
  int row = 1;
  while (std::getline(in, line)) {
    ++row;
    std::vector<std::string> cells;
    std::stringstream s(line);
    std::string cell;
    while (std::getline(s, cell, ',')) cells.push_back(cell);
    if (cells.size() < 9 || cells[0] == "schedule") continue;
    try {
      Point& p = lines[cells[0] + " " + cells[1]][std::stod(cells[3])];
      p.seconds += std::stod(cells[4]);
      p.chamfer += std::stod(cells[6]);
      p.normals += std::stod(cells[7]);
      p.emd += std::stod(cells[8]);
      ++p.count;
    } catch (const std::exception&) {
      std::fprintf(stderr, "%s:%d: not a number where one is expected\n", argv[1], row);
      return 1;
    }
  }
  std::vector<jsa::Series> chamfer, normals, emd;
  for (const auto& [name, budgets] : lines) {
    jsa::Series c{name, {}, {}}, n{name, {}, {}}, e{name, {}, {}};
    for (const auto& [minutes, p] : budgets) {
      for (jsa::Series* s : {&c, &n, &e}) s->x.push_back(p.seconds / p.count);
      c.y.push_back(p.chamfer / p.count);
      n.y.push_back(p.normals / p.count);
      e.y.push_back(p.emd / p.count);
    }
    chamfer.push_back(c);
    normals.push_back(n);
    emd.push_back(e);
  }
  jsa::PlotOptions o;
  o.log_x = true;
  o.markers = true;
  o.x_label = "seconds on 2 cores (fit + outputs)";
  o.title = "Chamfer / sampling floor";
  o.y_label = "ratio";
  const std::string prefix = argv[2];
  jsa::write_png(prefix + "_chamfer.png", jsa::line_plot(chamfer, o));
  o.title = "unit-normal distance / sampling floor";
  jsa::write_png(prefix + "_normals.png", jsa::line_plot(normals, o));
  o.title = "EMD (samples through P and phi) / sampling floor";
  jsa::write_png(prefix + "_emd.png", jsa::line_plot(emd, o));
  return 0;
} catch (const std::exception& e) {  // an unwritable output, a plot without data
  std::fprintf(stderr, "bench_quality_plot: %s\n", e.what());
  return 1;
}
