// Exact linear assignment: the minimum-cost perfect matching of a dense n x n
// cost matrix, by Jonker & Volgenant (1987), "LAPJV". The EMD of the paper's
// evaluation (Eq. 13, "computed ... via Hungarian Algorithm") stands on it; see
// losses/metrics/emd.h. Also here: the optimality certificate (LP duality) that proves a
// returned matching optimal, and the obvious oracle over all n! permutations.
#pragma once
#include <vector>

#include "engine/block.h"

namespace jsa {

// A perfect matching of rows to columns, with the dual potentials (u, v) that
// prove it optimal: u_i + v_j <= cost(i, j) for every pair, with equality on the
// matched pairs j = column_of_row[i]. Summing over the matching gives
// sum u + sum v = its cost, and over any other permutation gives <= that
// permutation's cost: no matching is cheaper.
struct Assignment {
  std::vector<int> column_of_row;   // n entries, a permutation of 0..n-1
  double cost = 0;                  // sum_i cost(i, column_of_row[i])
  std::vector<double> row_dual;     // u, n entries (empty from the brute force)
  std::vector<double> column_dual;  // v, n entries (empty from the brute force)
};

// cost: n x n with finite entries (n >= 0). Serial and deterministic: the same
// matrix gives the same matching, whatever the thread count.
// Ties between equally cheap matchings are broken by the scan order, so do not
// expect a particular one of them; the cost is what is unique.
Assignment assign_lapjv(const Block<double>& cost);

// The solver's lists (the matching under construction, the free rows, the
// shortest-path search's arrays), kept by a caller that solves one problem
// after another: the training step's L_EMD (losses/transport.h), which must
// not allocate once warm.
struct AssignmentWorkspace {
  std::vector<int> row_of_column, columns_won, free_rows, still_free;
  std::vector<int> predecessor, settled;
  std::vector<double> distance, closed;
};

// The same solve into `result`, its vectors and `workspace`'s reused: no
// allocation once both have held a problem of this n.
void assign_lapjv(const Block<double>& cost, Assignment& result, AssignmentWorkspace& workspace);

// How far (u, v) are from proving `assignment` optimal for `cost`.
struct AssignmentCertificate {
  bool is_permutation = false;         // column_of_row is a permutation of 0..n-1
  double max_dual_violation = 0;       // max(0, max_ij u_i + v_j - cost(i, j))
  double max_slackness_violation = 0;  // max over matched pairs |cost(i, j) - u_i - v_j|
  // The matching's cost exceeds the optimum by at most n * (the two violations).
  double cost_gap_bound = 0;

  bool proves_optimal(double tolerance) const {
    return is_permutation && max_dual_violation <= tolerance &&
           max_slackness_violation <= tolerance;
  }
};

// O(n^2); rows are checked in parallel (a max does not depend on the order).
AssignmentCertificate check_certificate(const Block<double>& cost, const Assignment& assignment);

// The oracle: tries all n! permutations (n <= 8) and keeps the first cheapest in
// lexicographic order. Leaves the duals empty.
Assignment assign_brute_force(const Block<double>& cost);

}  // namespace jsa
