#include "engine/parallel.h"

#include <omp.h>

#include <Eigen/Core>

namespace jsa {

int max_threads() { return omp_get_max_threads(); }

void set_threads(int n) {
  if (n <= 0) return;
  omp_set_num_threads(n);
  Eigen::setNbThreads(n);
}

}  // namespace jsa
