// Eigen's GEMM without a heap allocation per product: row-major C (+)= op(A)
// op(B) through Eigen's own blocked product, with the packing buffers kept by
// each thread from one product to the next.
//
// Why: Eigen packs panels of A and B into scratch buffers for each large
// product. `C.noalias() = A * B` takes them from the stack up to
// EIGEN_STACK_ALLOCATION_LIMIT (128 KiB) and from the heap beyond, and its
// threaded product always takes A's from the heap: one to three mallocs a
// product, 80 of a single shape's training step and 2,160 of a two-shape
// collection's (whose row-tiled layers, engine/ops_linear_softplus.cpp, make
// many small products). Eigen has no allocator hook, but its product routine
// (internal::general_matrix_matrix_product<...>::run) packs into the buffers
// of the blocking object its caller passes when that object has them. So this
// file only calls Eigen: it hands that routine a blocking object of ours whose
// buffers are the thread's kept ones, and it splits the threaded case itself.
//
// Bits: on one thread (and inside an OpenMP team) this is the call that
// `C.noalias() (+)= A * B` makes, with the same blocking sizes (Eigen's
// computeProductBlockingSizes), so the same bits. On several threads Eigen
// shares one packed B^T between the threads; here each thread runs the
// sequential product on its own rows of C, with the depth blocking Eigen's
// threaded product would choose. test/engine_gemm_test.cpp compares both with
// Eigen's own product. Used by engine/gemm.cpp only.
#pragma once
#include <omp.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cstddef>
#include <type_traits>

namespace jsa {
namespace kept_gemm {

using Index = Eigen::Index;

// One thread's two packing buffers (the left and the right operand's panels):
// grown when a product needs more, never shrunk, freed with the thread. A
// thread runs one product at a time, and a product uses them only while it
// runs, so one pair a thread is enough.
class ThreadBuffers {
 public:
  ThreadBuffers() = default;
  ThreadBuffers(const ThreadBuffers&) = delete;
  ThreadBuffers& operator=(const ThreadBuffers&) = delete;
  ~ThreadBuffers() {
    Eigen::internal::aligned_free(left_);
    Eigen::internal::aligned_free(right_);
  }
  template <class Scalar>
  Scalar* left(Index count) {
    return static_cast<Scalar*>(at_least(left_, left_bytes_, sizeof(Scalar) * size_t(count)));
  }
  template <class Scalar>
  Scalar* right(Index count) {
    return static_cast<Scalar*>(at_least(right_, right_bytes_, sizeof(Scalar) * size_t(count)));
  }
  static ThreadBuffers& mine() {
    thread_local ThreadBuffers buffers;
    return buffers;
  }

 private:
  // The old contents need not survive (a product packs before it reads), so
  // a larger buffer is a fresh one rather than a reallocation.
  static void* at_least(void*& buffer, size_t& bytes, size_t wanted) {
    if (wanted > bytes) {
      Eigen::internal::aligned_free(buffer);
      buffer = Eigen::internal::aligned_malloc(wanted);
      bytes = wanted;
    }
    return buffer;
  }
  void* left_ = nullptr;
  void* right_ = nullptr;
  size_t left_bytes_ = 0, right_bytes_ = 0;
};

// Eigen's product loops over kc terms of the sum, mc rows of its left operand
// and nc columns of its right one at a time. A row-major C is computed by
// Eigen as the column-major C^T = op(B)^T op(A)^T, so its left operand has C's
// n columns as rows, and its right one C's m rows as columns.
struct BlockSizes {
  Index kc, mc, nc;
};

// The sizes Eigen picks for C = op(A) op(B), C m x n, k terms, when `threads`
// threads share it (1: the sequential product).
template <class Scalar>
BlockSizes eigen_block_sizes(Index m, Index n, Index k, Index threads) {
  BlockSizes s{k, n, m};
  if (threads == 1) {
    Eigen::internal::computeProductBlockingSizes<Scalar, Scalar, 1>(s.kc, s.mc, s.nc, Index(1));
  } else {
    // Eigen's threaded product keeps mc at the whole of its left operand
    // (each thread packs a slice of it) and lets kc and nc follow the threads.
    Index mc = s.mc;
    Eigen::internal::computeProductBlockingSizes<Scalar, Scalar, 1>(s.kc, mc, s.nc, threads);
  }
  return s;
}

// The blocking object Eigen's product reads its sizes and buffers from, the
// buffers being the calling thread's kept ones. Construct it on the thread
// that runs the product.
template <class Scalar>
class KeptBlocking : public Eigen::internal::level3_blocking<Scalar, Scalar> {
 public:
  explicit KeptBlocking(const BlockSizes& s) {
    this->m_kc = s.kc;
    this->m_mc = s.mc;
    this->m_nc = s.nc;
    ThreadBuffers& buffers = ThreadBuffers::mine();
    this->m_blockA = buffers.left<Scalar>(s.kc * s.mc);
    this->m_blockB = buffers.right<Scalar>(s.kc * s.nc);
  }
};

// Row-major C (m x n, row length ldc) += op(A) op(B) on this thread. op(A) is
// row-major with row length lda when A is not transposed; transposed, A's rows
// are op(A)'s columns, so op(A) is column-major with the same stride (likewise
// op(B)). The storage orders are template arguments of Eigen's product, hence
// the four instantiations.
template <class Scalar>
void sequential(Index m, Index n, Index k, const Scalar* a, Index lda, bool transpose_a,
                const Scalar* b, Index ldb, bool transpose_b, Scalar* c, Index ldc,
                const BlockSizes& sizes) {
  KeptBlocking<Scalar> blocking(sizes);
  auto run = [&](auto lhs_order, auto rhs_order) {
    using Product = Eigen::internal::general_matrix_matrix_product<
        Index, Scalar, decltype(lhs_order)::value, false, Scalar, decltype(rhs_order)::value, false,
        Eigen::RowMajor, /*ResInnerStride=*/1>;
    Product::run(m, n, k, a, lda, b, ldb, c, /*resIncr=*/1, ldc, Scalar(1), blocking,
                 /*info=*/nullptr);
  };
  using Row = std::integral_constant<int, Eigen::RowMajor>;
  using Col = std::integral_constant<int, Eigen::ColMajor>;
  if (transpose_a && transpose_b)
    run(Col{}, Col{});
  else if (transpose_a)
    run(Col{}, Row{});
  else if (transpose_b)
    run(Row{}, Col{});
  else
    run(Row{}, Row{});
}

// How many threads Eigen's own product would use: one inside a team, else up
// to Eigen::nbThreads() (engine/parallel.cpp sets it), no more than one per
// nr-row slice of C (nr: the width of Eigen's register block) nor one per
// 50,000 multiply-adds (Eigen's threshold for a thread's share).
template <class Scalar>
Index eigen_threads(Index m, Index n, Index k) {
  if (omp_get_num_threads() > 1) return 1;
  const Index nr = Eigen::internal::gebp_traits<Scalar, Scalar>::nr;
  const double work = double(m) * double(n) * double(k);
  const Index by_rows = m / nr, by_work = Index(work / 50000);
  return std::max<Index>(1, std::min<Index>({Index(Eigen::nbThreads()), by_rows, by_work}));
}

// Row-major C += op(A) op(B) for a product Eigen runs as a GEMM, on the
// threads Eigen would use: C's rows in contiguous slices, one a thread, each a
// multiple of 4 rows but the last (as Eigen splits them), each thread running
// the sequential product on its slice with its own buffers.
template <class Scalar>
void add_product(Index m, Index n, Index k, const Scalar* a, Index lda, bool transpose_a,
                 const Scalar* b, Index ldb, bool transpose_b, Scalar* c, Index ldc) {
  const Index threads = eigen_threads<Scalar>(m, n, k);
  if (threads == 1) {
    sequential(m, n, k, a, lda, transpose_a, b, ldb, transpose_b, c, ldc,
               eigen_block_sizes<Scalar>(m, n, k, 1));
    return;
  }
  const BlockSizes sizes = eigen_block_sizes<Scalar>(m, n, k, threads);
#pragma omp parallel num_threads(int(threads))
  {
    const Index team = omp_get_num_threads(), i = omp_get_thread_num();
    const Index slice = (m / team) & ~Index(3);
    const Index first = i * slice, rows = i + 1 == team ? m - first : slice;
    // op(A)'s row r: A's row r, or A's column r when transposed.
    const Scalar* a_rows = transpose_a ? a + first : a + first * lda;
    if (rows > 0)
      sequential(rows, n, k, a_rows, lda, transpose_a, b, ldb, transpose_b, c + first * ldc, ldc,
                 sizes);
  }
}

// C = op(A) op(B), or C += op(A) op(B) with `accumulate`: A, B and C row-major
// Eigen blocks or maps (contiguous rows, any row length). Products Eigen does
// not pack for (the small ones it evaluates coefficient by coefficient, the
// matrix-vector ones, the empty ones) go to Eigen's own expression. The others
// zero C first when assigning, then add with alpha = 1, which is what Eigen's
// `C.noalias() = A * B` does.
template <class A, class B, class C>
void product(const A& a, bool transpose_a, const B& b, bool transpose_b, C& c, bool accumulate) {
  static_assert(A::IsRowMajor && B::IsRowMajor && C::IsRowMajor, "row-major blocks only");
  static_assert(A::InnerStrideAtCompileTime == 1 && B::InnerStrideAtCompileTime == 1 &&
                    C::InnerStrideAtCompileTime == 1,
                "contiguous rows only");
  using Scalar = typename C::Scalar;
  const Index m = c.rows(), n = c.cols(), k = transpose_a ? a.rows() : a.cols();
  const bool coefficient_based = k > 0 && (k + m + n) < EIGEN_GEMM_TO_COEFFBASED_THRESHOLD;
  if (coefficient_based || m == 1 || n == 1 || m == 0 || n == 0 || k == 0) {
    auto eigen = [&](const auto& opa, const auto& opb) {
      if (accumulate)
        c.noalias() += opa * opb;
      else
        c.noalias() = opa * opb;
    };
    if (transpose_a && transpose_b)
      eigen(a.transpose(), b.transpose());
    else if (transpose_a)
      eigen(a.transpose(), b);
    else if (transpose_b)
      eigen(a, b.transpose());
    else
      eigen(a, b);
    return;
  }
  if (!accumulate) c.setZero();
  add_product<Scalar>(m, n, k, a.data(), a.outerStride(), transpose_a, b.data(), b.outerStride(),
                      transpose_b, c.data(), c.outerStride());
}

}  // namespace kept_gemm
}  // namespace jsa
