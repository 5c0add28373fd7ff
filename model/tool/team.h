// The processes of a data-parallel fit (docs/mpi.md). Each of P ranks holds
// every shared parameter (phi, psi, the means) and the shapes of one
// contiguous block, with their codes. The only exchange a step needs is a sum
// over the ranks; a Team does it in rank order, ((x_0 + x_1) + x_2) + ..., so
// the result is the same on every rank and in every run whatever the timing.
// This header is the one-process team (nothing to exchange); model/tool/mpi/mpi_team.h
// is the same interface over MPI.
#pragma once
#include <cstddef>
#include <cstdint>
#include <utility>

namespace jsa {

class Team {
 public:
  virtual ~Team() = default;
  virtual int rank() const { return 0; }
  virtual int size() const { return 1; }
  // Every rank calls with the same n; on return data[i] = sum over ranks r = 0, 1, ...
  // of rank r's data[i], added in that order, bit-identical on every rank.
  virtual void sum_in_rank_order(float* data, size_t n) { (void)data, (void)n; }
  virtual void sum_in_rank_order(double* data, size_t n) { (void)data, (void)n; }
  // Bytes this rank has sent plus received so far.
  virtual uint64_t bytes_exchanged() const { return 0; }
};

// The shapes [first, last) of `rank` when `shapes` are split over `ranks` in
// contiguous blocks; the first (shapes mod ranks) ranks hold one more.
inline std::pair<int, int> shape_block(int shapes, int ranks, int rank) {
  const int base = shapes / ranks, extra = shapes % ranks;
  const int first = rank * base + (rank < extra ? rank : extra);
  return {first, first + base + (rank < extra ? 1 : 0)};
}

}  // namespace jsa
