// Auction with epsilon-scaling (Bertsekas 1988, "The auction algorithm: a
// distributed relaxation method for the assignment problem"), written for
// minimisation: a row i prefers the column with the smallest c_ij + p_j, where
// p_j is the column's price. A free row bids for its best column j1, raising
// p_j1 by (second best - best + epsilon): the column now costs i as much as its
// second choice plus epsilon, and its previous holder becomes free.
// epsilon-complementary slackness holds for every matched pair throughout:
//   c_{i,x_i} + p_{x_i} <= min_j (c_ij + p_j) + epsilon,
// so a complete matching costs at most n * epsilon more than the optimum.
// Scaling: start with a large epsilon (few, coarse bids), divide by theta, keep
// the prices, and keep only the pairs that still satisfy the tighter condition.
#include "losses/metrics/assignment_auction.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>

#include "engine/check.h"

namespace jsa {
namespace {

constexpr int64_t kPriceLimit = int64_t(1) << 61;

// The best and second-best c_ij + p_j of one row.
struct Bid {
  int column;
  int64_t best, second;
};

Bid best_two(const int64_t* row, const std::vector<int64_t>& price, int n) {
  Bid b{0, row[0] + price[0], std::numeric_limits<int64_t>::max()};
  for (int j = 1; j < n; ++j) {
    const int64_t h = row[j] + price[j];
    if (h < b.second) {
      if (h < b.best) {
        b.second = b.best;
        b.best = h;
        b.column = j;
      } else {
        b.second = h;
      }
    }
  }
  return b;
}

}  // namespace

IntegerAssignment assign_auction(const Block<int64_t>& cost, const AuctionOptions& options) {
  JSA_CHECK(cost.rows() == cost.cols(), "auction needs a square cost matrix");
  JSA_CHECK(options.epsilon_divisor >= 2, "epsilon_divisor must be >= 2");
  JSA_CHECK(cost.rows() < (int64_t(1) << 20), "auction: n too large");
  const int n = int(cost.rows());
  IntegerAssignment result;
  if (n == 0) return result;
  result.column_of_row.assign(n, 0);
  if (n == 1) {
    result.cost = cost(0, 0);
    return result;
  }
  // Shift to non-negative costs (every matching moves by n * lowest, so the
  // optimum does not change) and scale by n + 1 (see the header).
  const int64_t lowest = cost.minCoeff(), highest = cost.maxCoeff();
  JSA_CHECK(highest >= lowest && double(highest) - double(lowest) < double(kPriceLimit),
            "auction: cost range too large");
  const int64_t range = highest - lowest;
  const int64_t scale = n + 1;
  JSA_CHECK(range <= kPriceLimit / scale / scale,
            "auction: costs up to " << range << " times (n+1)^2 would overflow 64 bits");
  Block<int64_t> scaled(n, n);
  for (Index k = 0; k < scaled.size(); ++k) scaled.data()[k] = (cost.data()[k] - lowest) * scale;

  std::vector<int64_t> price(n, 0);
  std::vector<int> column_of_row(n, -1), row_of_column(n, -1);
  std::deque<int> free_rows;
  int64_t epsilon = std::max<int64_t>(1, range * scale / options.epsilon_divisor);
  for (;;) {
    ++result.phases;
    // Keep the pairs that satisfy epsilon-CS for the new epsilon; free the rest.
    for (int i = 0; i < n; ++i) {
      const int j = column_of_row[i];
      if (j < 0) continue;
      const int64_t* row = scaled.data() + size_t(i) * n;
      if (row[j] + price[j] > best_two(row, price, n).best + epsilon) {
        column_of_row[i] = -1;
        row_of_column[j] = -1;
      }
    }
    for (int i = 0; i < n; ++i)
      if (column_of_row[i] < 0) free_rows.push_back(i);
    // Gauss-Seidel auction: one bid at a time, first come first served.
    while (!free_rows.empty()) {
      const int i = free_rows.front();
      free_rows.pop_front();
      const Bid bid = best_two(scaled.data() + size_t(i) * n, price, n);
      const int j = bid.column;
      price[j] += bid.second - bid.best + epsilon;
      JSA_CHECK(price[j] < kPriceLimit, "auction price overflow");
      ++result.bids;
      const int evicted = row_of_column[j];
      if (evicted >= 0) {
        column_of_row[evicted] = -1;
        free_rows.push_back(evicted);
      }
      column_of_row[i] = j;
      row_of_column[j] = i;
    }
    if (epsilon == 1) break;
    epsilon = std::max<int64_t>(1, epsilon / options.epsilon_divisor);
  }
  result.column_of_row = column_of_row;
  for (int i = 0; i < n; ++i) result.cost += cost(i, column_of_row[i]);
  return result;
}

Block<int64_t> integer_costs(const Block<double>& cost, double scale) {
  Block<int64_t> out(cost.rows(), cost.cols());
  for (Index k = 0; k < cost.size(); ++k) {
    const double x = scale * cost.data()[k];
    JSA_CHECK(std::isfinite(x) && std::abs(x) < 9007199254740992.0,
              "integer_costs: " << x << " is not exactly representable");
    out.data()[k] = int64_t(std::llround(x));
  }
  return out;
}

}  // namespace jsa
