// LAPJV (Jonker & Volgenant 1987, "A shortest augmenting path algorithm for
// dense and sparse linear assignment problems"), in three phases:
//  1. column reduction: v_j = min_i c_ij; each column goes to its cheapest row
//     if that row is still free, then "reduction transfer" moves slack from a
//     row with one column onto that column's price;
//  2. augmenting row reduction (two passes): a free row takes its cheapest
//     column, lowering that column's price so the column stays its best, and
//     evicts the previous holder (an auction with zero epsilon);
//  3. augmentation: from each remaining free row, Dijkstra over the columns
//     with reduced costs c_ij - v_j - u_i >= 0 finds the shortest alternating
//     path to a free column; the prices of the columns it settled are shifted
//     so every matched pair keeps reduced cost 0, then the path is flipped.
// Invariant throughout: every matched row i holds a column that minimises
// c_ij - v_j over j. Then u_i = c_{i,x_i} - v_{x_i} makes (u, v) dual feasible
// and tight on the matching, which is the certificate checked below.
#include "losses/metrics/assignment.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>

#include "engine/check.h"
#include "engine/parallel.h"

namespace jsa {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// The matching under construction: x (row -> column) and y (column -> row),
// -1 where free, and the column prices v. x and v are the result's own
// vectors (Assignment::column_of_row, column_dual), y the workspace's.
struct Matching {
  std::vector<int>& column_of_row;
  std::vector<int>& row_of_column;
  std::vector<double>& price;  // v
};

// Phase 1. Leaves the rows still free in `free_rows`.
void column_reduction(const Block<double>& cost, Matching& m, std::vector<int>& columns_won,
                      std::vector<int>& free_rows) {
  const int n = int(cost.rows());
  columns_won.assign(size_t(n), 0);  // how many columns chose each row
  // Right to left, as in the paper: the last column a row wins is the one it keeps.
  for (int j = n - 1; j >= 0; --j) {
    int cheapest_row = 0;
    for (int i = 1; i < n; ++i)
      if (cost(i, j) < cost(cheapest_row, j)) cheapest_row = i;
    m.price[j] = cost(cheapest_row, j);
    if (++columns_won[cheapest_row] == 1) {
      m.column_of_row[cheapest_row] = j;
      m.row_of_column[j] = cheapest_row;
    }
  }
  free_rows.clear();
  for (int i = 0; i < n; ++i) {
    if (columns_won[i] == 0) {
      free_rows.push_back(i);
    } else if (columns_won[i] == 1) {
      // Reduction transfer: lower the price of i's column until it costs row i
      // as much as its second-best column. i's column stays its best (a tie).
      const int held = m.column_of_row[i];
      double second = kInfinity;
      for (int j = 0; j < n; ++j)
        if (j != held) second = std::min(second, cost(i, j) - m.price[j]);
      m.price[held] -= second;  // second >= 0: all prices are column minima here
    }
  }
}

// Phase 2, one pass over `free_rows`; the rows still free afterwards are left
// in `still_free`. `bid_budget` caps the work: in floating point a price drop
// can round to nothing and two rows could evict each other forever. Rows left
// when the budget runs out simply stay free for phase 3, which handles any
// free row.
void augmenting_row_reduction(const Block<double>& cost, std::vector<int>& free_rows, Matching& m,
                              long& bid_budget, std::vector<int>& still_free) {
  const int n = int(cost.rows());
  still_free.clear();
  size_t k = 0;
  while (k < free_rows.size()) {
    const int i = free_rows[k++];
    if (bid_budget-- <= 0) {
      still_free.push_back(i);
      continue;
    }
    const double* row = cost.data() + size_t(i) * n;
    // Best and second-best reduced cost c_ij - v_j over the columns.
    double best = row[0] - m.price[0], second = kInfinity;
    int best_column = 0, second_column = -1;
    for (int j = 1; j < n; ++j) {
      const double h = row[j] - m.price[j];
      if (h < second) {
        if (h >= best) {
          second = h;
          second_column = j;
        } else {
          second = best;
          second_column = best_column;
          best = h;
          best_column = j;
        }
      }
    }
    int column = best_column;
    int evicted = m.row_of_column[column];
    const bool strict = best < second;
    if (strict) {
      // Lower the best column's price so it costs row i exactly `second`: the
      // column stays i's best and becomes less attractive to every other row.
      const double lowered = m.price[column] - (second - best);
      if (!(lowered < m.price[column])) {  // the drop rounded away: no progress
        still_free.push_back(i);
        continue;
      }
      m.price[column] = lowered;
    } else if (evicted >= 0) {
      // A tie: take the other best column instead, so two rows do not keep
      // evicting each other from the same column.
      column = second_column;
      evicted = m.row_of_column[column];
    }
    m.column_of_row[i] = column;
    m.row_of_column[column] = i;
    if (evicted >= 0) {
      m.column_of_row[evicted] = -1;
      if (strict)
        free_rows[--k] = evicted;  // it bids next, while its prices are fresh
      else
        still_free.push_back(evicted);
    }
  }
}

// Scratch space for phase 3 (the workspace's arrays, sized once per solve).
// Every loop over the columns runs over all n of them, contiguous, so the
// compiler can vectorize it; settled columns are masked out by `closed`
// instead of being skipped.
struct PathSearch {
  std::vector<double>& distance;  // shortest alternating-path length to each column
  std::vector<double>& closed;    // 0 while a column is open, +inf once settled
  std::vector<int>& predecessor;  // the row before each column on its shortest path
  std::vector<int>& settled;      // settled columns, in order
};

// path_length(j) = c_rj - v_j - offset; keep it where it beats distance[j] on
// an open column. __restrict: the five arrays never overlap.
void relax(const double* __restrict c, const double* __restrict price, double offset, int row,
           double* __restrict distance, const double* __restrict closed,
           int* __restrict predecessor, int n) {
  for (int j = 0; j < n; ++j) {
    const double length = c[j] - price[j] - offset;
    const bool shorter = length + closed[j] < distance[j];
    distance[j] = shorter ? length : distance[j];
    predecessor[j] = shorter ? row : predecessor[j];
  }
}

// argmin_j distance[j] over the open columns, the lowest index among ties.
// Kept in 8 lanes (lane l sees columns j = l mod 8) so the loop vectorizes;
// strict < keeps each lane's first minimum, and the merge its lowest index.
int nearest_open_column(const double* __restrict distance, const double* __restrict closed, int n) {
  constexpr int kLanes = 8;
  double lane_distance[kLanes];
  int64_t lane_column[kLanes];  // 64-bit, like the doubles, so lanes line up
  for (int l = 0; l < kLanes; ++l) {
    lane_distance[l] = kInfinity;
    lane_column[l] = n;
  }
  int j = 0;
  for (; j + kLanes <= n; j += kLanes)
    for (int l = 0; l < kLanes; ++l) {
      const double key = distance[j + l] + closed[j + l];
      const bool nearer = key < lane_distance[l];
      lane_distance[l] = nearer ? key : lane_distance[l];
      lane_column[l] = nearer ? int64_t(j + l) : lane_column[l];
    }
  for (; j < n; ++j) {  // the last n mod 8 columns, in their lanes
    const double key = distance[j] + closed[j];
    const int l = j % kLanes;
    if (key < lane_distance[l]) {
      lane_distance[l] = key;
      lane_column[l] = j;
    }
  }
  double best = kInfinity;
  int64_t column = n;
  for (int l = 0; l < kLanes; ++l)
    if (lane_distance[l] < best || (lane_distance[l] == best && lane_column[l] < column)) {
      best = lane_distance[l];
      column = lane_column[l];
    }
  return int(column);
}

// Phase 3 for one free row: Dijkstra over the columns, from `start_row`, until
// the nearest open column is free; then the price update and the flip.
void augment(const Block<double>& cost, int start_row, Matching& m, PathSearch& s) {
  const int n = int(cost.rows());
  std::fill(s.distance.begin(), s.distance.end(), kInfinity);
  std::fill(s.closed.begin(), s.closed.end(), 0.0);
  s.settled.clear();
  // Path length to column j through row r: (length to r's column) + reduced
  // cost c_rj - v_j - u_r = c_rj - v_j - offset. For the start row offset = 0.
  int row = start_row;
  double offset = 0, nearest = 0;
  int free_column = -1;
  while (free_column < 0) {
    const double* c = cost.data() + size_t(row) * n;
    relax(c, m.price.data(), offset, row, s.distance.data(), s.closed.data(), s.predecessor.data(),
          n);
    // With ties the lowest column wins, free or not: a free column at the same
    // distance stays open at `nearest` and is taken on a following step.
    const int column = nearest_open_column(s.distance.data(), s.closed.data(), n);
    nearest = s.distance[column];
    if (m.row_of_column[column] < 0) {
      free_column = column;
    } else {
      s.closed[column] = kInfinity;
      s.settled.push_back(column);
      row = m.row_of_column[column];
      // u_row = c_{row,column} - v_column: the row's held column is its best.
      offset = cost(row, column) - m.price[column] - nearest;
    }
  }
  // Settled columns: v_j += d_j - nearest (<= 0). Their rows' reduced costs
  // keep 0 on the held column and stay >= 0 elsewhere (Dijkstra's optimality).
  for (int j : s.settled) m.price[j] += s.distance[j] - nearest;
  // Flip the alternating path back from the free column to the start row.
  int column = free_column;
  for (;;) {
    const int r = s.predecessor[column];
    m.row_of_column[column] = r;
    std::swap(column, m.column_of_row[r]);
    if (r == start_row) break;
  }
}

}  // namespace

void assign_lapjv(const Block<double>& cost, Assignment& result, AssignmentWorkspace& w) {
  JSA_CHECK(cost.rows() == cost.cols(),
            "assignment needs a square cost matrix, got " << cost.rows() << " x " << cost.cols());
  JSA_CHECK(cost.rows() < std::numeric_limits<int>::max(), "cost matrix too large");
  JSA_CHECK(cost.allFinite(), "assignment costs must be finite");
  const int n = int(cost.rows());
  result.cost = 0;
  // assign() and resize() keep the vectors' capacity: a second solve of the
  // same n allocates nothing.
  result.column_of_row.assign(size_t(n), -1);
  result.column_dual.assign(size_t(n), 0.0);
  result.row_dual.resize(size_t(n));
  w.row_of_column.assign(size_t(n), -1);
  if (n == 0) return;
  Matching m{result.column_of_row, w.row_of_column, result.column_dual};
  if (n == 1) {
    m.column_of_row[0] = m.row_of_column[0] = 0;
    m.price[0] = cost(0, 0);
  } else {
    column_reduction(cost, m, w.columns_won, w.free_rows);
    long bid_budget = 16L * n;
    for (int pass = 0; pass < 2 && !w.free_rows.empty(); ++pass) {
      augmenting_row_reduction(cost, w.free_rows, m, bid_budget, w.still_free);
      std::swap(w.free_rows, w.still_free);
    }
    w.distance.resize(size_t(n));
    w.closed.resize(size_t(n));
    w.predecessor.resize(size_t(n));
    w.settled.reserve(size_t(n));
    PathSearch search{w.distance, w.closed, w.predecessor, w.settled};
    for (int row : w.free_rows) augment(cost, row, m, search);
  }
  for (int i = 0; i < n; ++i) {
    const int j = m.column_of_row[i];
    JSA_CHECK(j >= 0 && m.row_of_column[j] == i, "LAPJV left row " << i << " unmatched");
    result.row_dual[i] = cost(i, j) - m.price[j];
    result.cost += cost(i, j);
  }
}

Assignment assign_lapjv(const Block<double>& cost) {
  Assignment result;
  AssignmentWorkspace workspace;
  assign_lapjv(cost, result, workspace);
  return result;
}
AssignmentCertificate check_certificate(const Block<double>& cost, const Assignment& a) {
  const Index n = cost.rows();
  JSA_CHECK(cost.cols() == n, "square cost matrix expected");
  AssignmentCertificate cert;
  if (Index(a.column_of_row.size()) != n || Index(a.row_dual.size()) != n ||
      Index(a.column_dual.size()) != n)
    return cert;
  std::vector<char> taken(n, 0);
  cert.is_permutation = true;
  for (int j : a.column_of_row) {
    if (j < 0 || j >= n || taken[j]) {
      cert.is_permutation = false;
      break;
    }
    taken[j] = 1;
  }
  // Per-row worst violations, then a max over rows: the same whatever the threads.
  std::vector<double> dual(n, 0.0), slack(n, 0.0);
  parallel_rows(
      n,
      [&](Index begin, Index end) {
        for (Index i = begin; i < end; ++i) {
          const double u = a.row_dual[i];
          double worst = 0;
          for (Index j = 0; j < n; ++j) worst = std::max(worst, u + a.column_dual[j] - cost(i, j));
          dual[i] = worst;
          const int j = a.column_of_row[i];
          if (j >= 0 && j < n) slack[i] = std::abs(cost(i, j) - u - a.column_dual[j]);
        }
      },
      64);
  for (Index i = 0; i < n; ++i) {
    cert.max_dual_violation = std::max(cert.max_dual_violation, dual[i]);
    cert.max_slackness_violation = std::max(cert.max_slackness_violation, slack[i]);
  }
  cert.cost_gap_bound = double(n) * (cert.max_dual_violation + cert.max_slackness_violation);
  return cert;
}

Assignment assign_brute_force(const Block<double>& cost) {
  JSA_CHECK(cost.rows() == cost.cols(), "square cost matrix expected");
  JSA_CHECK(cost.rows() <= 8, "brute force tries n! permutations; n = " << cost.rows());
  const int n = int(cost.rows());
  std::vector<int> permutation(n);
  std::iota(permutation.begin(), permutation.end(), 0);
  Assignment best;
  best.cost = kInfinity;
  if (n == 0) best.cost = 0;
  do {
    double total = 0;
    for (int i = 0; i < n; ++i) total += cost(i, permutation[i]);
    if (total < best.cost) {
      best.cost = total;
      best.column_of_row = permutation;
    }
  } while (std::next_permutation(permutation.begin(), permutation.end()));
  return best;
}

}  // namespace jsa
