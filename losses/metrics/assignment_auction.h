// The second, independent assignment algorithm: Bertsekas' auction with
// epsilon-scaling, on integer costs, exact. It shares no code with LAPJV
// (losses/metrics/assignment.h), so the two agreeing on a matrix is real evidence.
// Float costs are compared by scaling them to integers first
// (integer_costs below) and handing both algorithms the same integer matrix.
#pragma once
#include <cstdint>
#include <vector>

#include "engine/block.h"

namespace jsa {

struct AuctionOptions {
  // theta: epsilon is divided by this between scaling phases. Bertsekas
  // recommends 4 to 10; larger means fewer phases but longer ones.
  int64_t epsilon_divisor = 5;
};

struct IntegerAssignment {
  std::vector<int> column_of_row;  // n entries, a permutation of 0..n-1
  int64_t cost = 0;                // sum_i cost(i, column_of_row[i]), exact
  int phases = 0;                  // epsilon-scaling phases run
  int64_t bids = 0;                // bids made over all phases (the work done)
};

// cost: n x n integers. Exact: internally costs are multiplied by n + 1 and the
// last phase runs at epsilon = 1 there, i.e. epsilon = 1/(n + 1) < 1/n in the
// caller's units. A matching within n * epsilon of optimal is then optimal,
// because two matchings of integer cost differ by at least 1.
// Throws InternalError if the scaled costs could overflow 64 bits
// (needs (max c - min c) (n + 1)^2 below 2^61). Serial and deterministic.
IntegerAssignment assign_auction(const Block<int64_t>& cost, const AuctionOptions& options = {});

// round(scale * cost) entry by entry (finite costs, |scale * cost| < 2^53).
Block<int64_t> integer_costs(const Block<double>& cost, double scale);

}  // namespace jsa
