// A block is the unit every op works on: a row-major Eigen matrix whose rows are
// points and whose columns are features (N x C). Row-major keeps one point's
// features contiguous, which is what nearest-neighbour search and gathers want.
#pragma once
#include <Eigen/Dense>

namespace jsa {

template <class T>
using Block = Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

template <class T>
using RowVector = Eigen::Matrix<T, 1, Eigen::Dynamic, Eigen::RowMajor>;

using Index = Eigen::Index;

}  // namespace jsa
