// Exact nearest neighbours: for every query row, the index of the closest row of
// `points` (squared Euclidean distance, any number of columns). The Chamfer terms
// (Eqs. 6-8) and the evaluation metrics stand on this. Small sets (M N up to
// 2^24) are scanned, every distance computed; larger ones go to a kd-tree
// (nanoflann), which stays inside nearest.cpp so nothing else sees its templates.
//
// Ties: among points at exactly the same distance the lowest index wins, in both
// the kd-tree and the brute-force oracle, so the two return the same indices.
// Determinism: queries run in parallel, but each writes only its own slot, and the
// tree is built serially, so results do not depend on the thread count.
#pragma once
#include <memory>
#include <vector>

#include "engine/block.h"

namespace jsa {

// queries: M x C, points: N x C (N >= 1). On return index has M entries,
// index[i] = argmin_j |queries_i - points_j|^2, and if squared_distance is given
// it holds the M minimal squared distances. All coordinates must be finite.
// Tuned (fixed-size code) for C = 2, 3, 6, 9; other C take a generic path.
template <class NearestScalar>
class NearestScratch;
template <class T>
void nearest(const Block<T>& queries, const Block<T>& points, std::vector<int>& index,
             std::vector<T>* squared_distance = nullptr, NearestScratch<T>* scratch = nullptr);

// What a search needs besides its answer, for a caller that searches every
// step (the Chamfer op keeps one per search on its tape): the queries' visiting
// order and, for nearest(), the tree over `points`, rebuilt in place. With one,
// a search of the same sizes as the last allocates only the blocks nanoflann's
// node pool frees and takes again at every build (a few of 8 KiB); without,
// each call builds its own. Not shared between threads.
template <class T>
class NearestScratch {
 public:
  NearestScratch();
  ~NearestScratch();
  NearestScratch(NearestScratch&&) noexcept;
  NearestScratch& operator=(NearestScratch&&) noexcept;

  struct Impl;  // defined in nearest.cpp
  Impl& impl() { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

// Both halves of a Chamfer distance at once: x_to_y as nearest(x, y), y_to_x as
// nearest(y, x), the same answers. Small sets (M N up to 2^24) take one pass
// over their M x N distances for both; larger ones two tree searches, with
// x_scratch and y_scratch as nearest()'s.
template <class T>
void nearest_both_ways(const Block<T>& x, const Block<T>& y, std::vector<int>& x_to_y,
                       std::vector<T>* x_distance, std::vector<int>& y_to_x,
                       std::vector<T>* y_distance, NearestScratch<T>* x_scratch = nullptr,
                       NearestScratch<T>* y_scratch = nullptr);

// The oracle: the obvious O(M N) double loop, same contract as nearest().
template <class T>
void nearest_brute_force(const Block<T>& queries, const Block<T>& points, std::vector<int>& index,
                         std::vector<T>* squared_distance = nullptr);

// The same search against a point set that stays fixed over many calls (the
// surface pool of L_6D's dense variant): the tree is built once, here, and
// every query() reuses it. Same contract and tie rule as nearest().
template <class T>
class NearestIndex {
 public:
  explicit NearestIndex(Block<T> points);
  ~NearestIndex();
  NearestIndex(NearestIndex&&) noexcept;
  NearestIndex& operator=(NearestIndex&&) noexcept;

  void query(const Block<T>& queries, std::vector<int>& index,
             std::vector<T>* squared_distance = nullptr,
             NearestScratch<T>* scratch = nullptr) const;
  const Block<T>& points() const;

  struct Impl;  // the tree; defined in nearest.cpp, where nanoflann lives

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace jsa
