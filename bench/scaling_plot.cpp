// Plots the CSV that bench_iteration --csv appends to: one training step's
// time against M, one line per thread count, log-log, as a PNG.
//   bench_scaling_plot RESULTS.csv OUT.png
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "io/pictures/image.h"
#include "io/pictures/plot.h"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: bench_scaling_plot RESULTS.csv OUT.png\n");
    return 2;
  }
  std::ifstream in(argv[1]);
  if (!in) {
    std::fprintf(stderr, "cannot open %s\n", argv[1]);
    return 1;
  }
  std::string line;
  std::getline(in, line);  // header: points,gaussians,width,depth,threads,...,step_ms,gemm_ms,...
  std::map<int, jsa::Series> step, gemm;
  while (std::getline(in, line)) {
    std::vector<double> v;
    std::stringstream s(line);
    std::string cell;
    while (std::getline(s, cell, ',')) v.push_back(std::stod(cell));
    if (v.size() < 13) continue;
    const int threads = int(v[4]);
    step[threads].name = "step, " + std::to_string(threads) + " thread(s)";
    step[threads].x.push_back(v[0]);
    step[threads].y.push_back(v[11]);
    gemm[threads].name = "SGEMM bound, " + std::to_string(threads) + " thread(s)";
    gemm[threads].x.push_back(v[0]);
    gemm[threads].y.push_back(v[12]);
  }
  std::vector<jsa::Series> series;
  for (auto& [t, s] : step) series.push_back(s);
  for (auto& [t, s] : gemm) series.push_back(s);
  jsa::PlotOptions o;
  o.log_x = o.log_y = true;
  o.markers = true;
  o.title = "one training step of the full method";
  o.x_label = "M (= K) points per step";
  o.y_label = "ms";
  jsa::write_png(argv[2], jsa::line_plot(series, o));
  return 0;
}
