// compare_checkpoints A.ckpt B.ckpt [BOUND]: the parameters of two runs of the
// same model, for the MPI equivalence tests (test/mpi/run_tests.sh). Prints
//   max |a - b|, and rel = max |a - b| / max |a| (the largest difference as a
//   fraction of the largest parameter, so tiny parameters do not blow it up),
// with the parameter block where the largest difference lies, and exits 1 when
// rel > BOUND (or, without BOUND, when any value differs: bit-identical runs).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "model/tool/checkpoint.h"

int main(int argc, char** argv) {
  if (argc != 3 && argc != 4) {
    std::fprintf(stderr, "usage: compare_checkpoints A.ckpt B.ckpt [BOUND]\n");
    return 2;
  }
  try {
    const jsa::CheckpointContents ca = jsa::read_checkpoint(argv[1]),
                                  cb = jsa::read_checkpoint(argv[2]);
    const auto a = jsa::load_atlas(ca, argv[1]), b = jsa::load_atlas(cb, argv[2]);
    const std::vector<float>&va = a->params.values(), &vb = b->params.values();
    if (va.size() != vb.size()) {
      std::fprintf(stderr, "compare_checkpoints: %zu against %zu parameters\n", va.size(),
                   vb.size());
      return 1;
    }
    double worst = 0, scale = 0;
    size_t at = 0, differ = 0;
    for (size_t i = 0; i < va.size(); ++i) {
      const double d = std::abs(double(va[i]) - double(vb[i]));
      if (!(d <= worst) || std::isnan(d)) worst = std::isnan(d) ? INFINITY : d, at = i;
      scale = std::max(scale, std::abs(double(va[i])));
      differ += va[i] != vb[i] ? 1 : 0;
    }
    std::string where;
    for (int e = 0; e < a->params.count(); ++e) {
      const auto& entry = a->params.entry(e);
      if (at >= entry.offset && at < entry.offset + size_t(entry.rows * entry.cols))
        where = entry.name;
    }
    const double rel = worst / std::max(scale, 1e-30);
    std::printf(
        "%zu parameters, %zu differ; max |a - b| = %.3e (in %s), max |a| = %.3e, rel = %.3e\n",
        va.size(), differ, worst, where.c_str(), scale, rel);
    if (argc == 3) return differ == 0 ? 0 : 1;
    return rel <= std::atof(argv[3]) ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "compare_checkpoints: %s\n", e.what());
    return 1;
  }
}
