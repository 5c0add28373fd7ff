// Eigen's GEMM without its heap: the same product, the same blocking and the
// same bits as `C.noalias() (+)= A * B`, with the packing buffers kept from one
// product to the next instead of taken from the heap every time.
//
// Why: Eigen packs panels of A and B into scratch buffers for each large
// product. It takes them from the stack up to EIGEN_STACK_ALLOCATION_LIMIT
// (128 KiB) and from the heap beyond, and its threaded product always takes A's
// from the heap: one to three mallocs per product, 80 of a single shape's
// training step and 2,160 of a two-shape collection's (whose row-tiled layers,
// engine/ops_linear_softplus.cpp, make many small products). Eigen has no
// allocator hook; it does let the caller pass the blocking object that owns
// the buffers (level3_blocking), and the product kernel type.
//
// What is here, all of it Eigen 3.4's own code (GeneralMatrixMatrix.h,
// Mozilla Public License 2.0, Copyright (C) 2008-2009 Gael Guennebaud)
// except where marked KEPT:
//   KeptBlocking  gemm_blocking_space<..., Dynamic>, its sizes computed as
//                 Eigen computes them, its buffers the calling thread's kept
//                 ones (KEPT);
//   KeptGemm      general_matrix_matrix_product: the sequential branch as is
//                 (it takes the blocking's buffers), the threaded branch with
//                 each thread's packed B in its own kept buffer (KEPT; Eigen's
//                 takes it from the stack or the heap);
//   kept_scale_and_add  generic_product_impl<..., GemmProduct>::scaleAndAddTo
//                 with those two types, and Eigen's own parallelize_gemm.
// The blocking sizes, the packing, the kernels and the threads' split are
// Eigen's, so the results are the bits of Eigen's product
// (test/engine_gemm_test.cpp compares them). Used by engine/gemm.cpp only.
#pragma once
#include <omp.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cstddef>
#include <type_traits>

namespace jsa {
namespace kept_gemm {

// One thread's packing buffers: grown when a product needs more, never
// shrunk, freed with the thread. A product uses them only while it runs, and a
// thread runs one product at a time.
struct PackingBuffers {
  void* a = nullptr;
  void* b = nullptr;
  size_t a_bytes = 0, b_bytes = 0;
  ~PackingBuffers() {
    Eigen::internal::aligned_free(a);
    Eigen::internal::aligned_free(b);
  }
  static void* grow(void*& p, size_t& have, size_t want) {
    if (want > have) {
      Eigen::internal::aligned_free(p);
      p = Eigen::internal::aligned_malloc(want);
      have = want;
    }
    return p;
  }
};
inline PackingBuffers& thread_buffers() {
  thread_local PackingBuffers buffers;
  return buffers;
}

// gemm_blocking_space<StorageOrder, Lhs, Rhs, Dynamic, Dynamic, Dynamic>.
template <int StorageOrder, class LhsScalar_, class RhsScalar_, int KcFactor = 1>
class KeptBlocking
    : public Eigen::internal::level3_blocking<
          std::conditional_t<StorageOrder == Eigen::RowMajor, RhsScalar_, LhsScalar_>,
          std::conditional_t<StorageOrder == Eigen::RowMajor, LhsScalar_, RhsScalar_>> {
  enum { Transpose = StorageOrder == Eigen::RowMajor };
  using LhsScalar = std::conditional_t<Transpose, RhsScalar_, LhsScalar_>;
  using RhsScalar = std::conditional_t<Transpose, LhsScalar_, RhsScalar_>;
  using Index = Eigen::Index;
  Index size_a_ = 0, size_b_ = 0;

 public:
  KeptBlocking(Index rows, Index cols, Index depth, Index num_threads, bool l3_blocking) {
    this->m_mc = Transpose ? cols : rows;
    this->m_nc = Transpose ? rows : cols;
    this->m_kc = depth;
    if (l3_blocking) {
      Eigen::internal::computeProductBlockingSizes<LhsScalar, RhsScalar, KcFactor>(
          this->m_kc, this->m_mc, this->m_nc, num_threads);
    } else {
      Index n = this->m_nc;
      Eigen::internal::computeProductBlockingSizes<LhsScalar, RhsScalar, KcFactor>(
          this->m_kc, this->m_mc, n, num_threads);
    }
    size_a_ = this->m_mc * this->m_kc;
    size_b_ = this->m_kc * this->m_nc;
    // KEPT: the sequential product packs into the blocking's buffers when it
    // has them (Eigen's own leaves them null: stack or heap).
    allocateAll();
  }

  void initParallel(Index rows, Index cols, Index depth, Index num_threads) {
    this->m_mc = Transpose ? cols : rows;
    this->m_nc = Transpose ? rows : cols;
    this->m_kc = depth;
    this->m_blockA = nullptr;  // KEPT: taken again below at the threaded sizes
    this->m_blockB = nullptr;
    Index m = this->m_mc;
    Eigen::internal::computeProductBlockingSizes<LhsScalar, RhsScalar, KcFactor>(
        this->m_kc, m, this->m_nc, num_threads);
    size_a_ = this->m_mc * this->m_kc;
    size_b_ = this->m_kc * this->m_nc;
  }

  // KEPT: the calling thread's buffers, not aligned_new.
  void allocateA() {
    if (!this->m_blockA) {
      PackingBuffers& own = thread_buffers();
      this->m_blockA = static_cast<LhsScalar*>(
          PackingBuffers::grow(own.a, own.a_bytes, sizeof(LhsScalar) * size_t(size_a_)));
    }
  }
  void allocateB() {
    if (!this->m_blockB) {
      PackingBuffers& own = thread_buffers();
      this->m_blockB = static_cast<RhsScalar*>(
          PackingBuffers::grow(own.b, own.b_bytes, sizeof(RhsScalar) * size_t(size_b_)));
    }
  }
  void allocateAll() {
    allocateA();
    allocateB();
  }
};

// general_matrix_matrix_product: a row-major destination is the transposed
// column-major product.
template <class Index, class LhsScalar, int LhsStorageOrder, bool ConjugateLhs, class RhsScalar,
          int RhsStorageOrder, bool ConjugateRhs, int ResStorageOrder, int ResInnerStride>
struct KeptGemm;

template <class Index, class LhsScalar, int LhsStorageOrder, bool ConjugateLhs, class RhsScalar,
          int RhsStorageOrder, bool ConjugateRhs, int ResInnerStride>
struct KeptGemm<Index, LhsScalar, LhsStorageOrder, ConjugateLhs, RhsScalar, RhsStorageOrder,
                ConjugateRhs, Eigen::RowMajor, ResInnerStride> {
  using Traits = Eigen::internal::gebp_traits<RhsScalar, LhsScalar>;
  using ResScalar = typename Eigen::ScalarBinaryOpTraits<LhsScalar, RhsScalar>::ReturnType;
  static void run(Index rows, Index cols, Index depth, const LhsScalar* lhs, Index lhsStride,
                  const RhsScalar* rhs, Index rhsStride, ResScalar* res, Index resIncr,
                  Index resStride, ResScalar alpha,
                  Eigen::internal::level3_blocking<RhsScalar, LhsScalar>& blocking,
                  Eigen::internal::GemmParallelInfo<Index>* info = nullptr) {
    KeptGemm<Index, RhsScalar,
             RhsStorageOrder == Eigen::RowMajor ? Eigen::ColMajor : Eigen::RowMajor, ConjugateRhs,
             LhsScalar, LhsStorageOrder == Eigen::RowMajor ? Eigen::ColMajor : Eigen::RowMajor,
             ConjugateLhs, Eigen::ColMajor, ResInnerStride>::run(cols, rows, depth, rhs, rhsStride,
                                                                 lhs, lhsStride, res, resIncr,
                                                                 resStride, alpha, blocking, info);
  }
};

template <class Index, class LhsScalar, int LhsStorageOrder, bool ConjugateLhs, class RhsScalar,
          int RhsStorageOrder, bool ConjugateRhs, int ResInnerStride>
struct KeptGemm<Index, LhsScalar, LhsStorageOrder, ConjugateLhs, RhsScalar, RhsStorageOrder,
                ConjugateRhs, Eigen::ColMajor, ResInnerStride> {
  using Traits = Eigen::internal::gebp_traits<LhsScalar, RhsScalar>;
  using ResScalar = typename Eigen::ScalarBinaryOpTraits<LhsScalar, RhsScalar>::ReturnType;
  static void run(Index rows, Index cols, Index depth, const LhsScalar* _lhs, Index lhsStride,
                  const RhsScalar* _rhs, Index rhsStride, ResScalar* _res, Index resIncr,
                  Index resStride, ResScalar alpha,
                  Eigen::internal::level3_blocking<LhsScalar, RhsScalar>& blocking,
                  Eigen::internal::GemmParallelInfo<Index>* info = nullptr) {
    using namespace Eigen::internal;
    typedef const_blas_data_mapper<LhsScalar, Index, LhsStorageOrder> LhsMapper;
    typedef const_blas_data_mapper<RhsScalar, Index, RhsStorageOrder> RhsMapper;
    typedef blas_data_mapper<typename Traits::ResScalar, Index, Eigen::ColMajor, Eigen::Unaligned,
                             ResInnerStride>
        ResMapper;
    LhsMapper lhs(_lhs, lhsStride);
    RhsMapper rhs(_rhs, rhsStride);
    ResMapper res(_res, resStride, resIncr);

    Index kc = blocking.kc();
    Index mc = (std::min)(rows, blocking.mc());
    Index nc = (std::min)(cols, blocking.nc());

    gemm_pack_lhs<LhsScalar, Index, LhsMapper, Traits::mr, Traits::LhsProgress,
                  typename Traits::LhsPacket4Packing, LhsStorageOrder>
        pack_lhs;
    gemm_pack_rhs<RhsScalar, Index, RhsMapper, Traits::nr, RhsStorageOrder> pack_rhs;
    gebp_kernel<LhsScalar, RhsScalar, Index, ResMapper, Traits::mr, Traits::nr, ConjugateLhs,
                ConjugateRhs>
        gebp;

    if (info) {
      // The threaded product (Eigen's parallel branch).
      int tid = omp_get_thread_num();
      int threads = omp_get_num_threads();

      LhsScalar* blockA = blocking.blockA();
      std::size_t sizeB = kc * nc;
      // KEPT: this thread's own buffer (Eigen: the stack up to 128 KiB, else the heap).
      PackingBuffers& own = thread_buffers();
      RhsScalar* blockB = static_cast<RhsScalar*>(
          PackingBuffers::grow(own.b, own.b_bytes, sizeof(RhsScalar) * sizeB));

      for (Index k = 0; k < depth; k += kc) {
        const Index actual_kc = (std::min)(k + kc, depth) - k;
        pack_rhs(blockB, rhs.getSubMapper(k, 0), actual_kc, nc);
        while (info[tid].users != 0) {
        }
        info[tid].users = threads;
        pack_lhs(blockA + info[tid].lhs_start * actual_kc, lhs.getSubMapper(info[tid].lhs_start, k),
                 actual_kc, info[tid].lhs_length);
        info[tid].sync = k;
        for (int shift = 0; shift < threads; ++shift) {
          int i = (tid + shift) % threads;
          if (shift > 0) {
            while (info[i].sync != k) {
            }
          }
          gebp(res.getSubMapper(info[i].lhs_start, 0), blockA + info[i].lhs_start * actual_kc,
               blockB, info[i].lhs_length, actual_kc, nc, alpha);
        }
        for (Index j = nc; j < cols; j += nc) {
          const Index actual_nc = (std::min)(j + nc, cols) - j;
          pack_rhs(blockB, rhs.getSubMapper(k, j), actual_kc, actual_nc);
          gebp(res.getSubMapper(0, j), blockA, blockB, rows, actual_kc, actual_nc, alpha);
        }
        for (Index i = 0; i < threads; ++i) info[i].users -= 1;
      }
    } else {
      // The sequential product (Eigen's own branch: the blocking's buffers).
      namespace internal = Eigen::internal;  // Eigen's stack-buffer macro names it unqualified
      std::size_t sizeA = kc * mc;
      std::size_t sizeB = kc * nc;
      ei_declare_aligned_stack_constructed_variable(LhsScalar, blockA, sizeA, blocking.blockA());
      ei_declare_aligned_stack_constructed_variable(RhsScalar, blockB, sizeB, blocking.blockB());
      const bool pack_rhs_once = mc != rows && kc == depth && nc == cols;
      for (Index i2 = 0; i2 < rows; i2 += mc) {
        const Index actual_mc = (std::min)(i2 + mc, rows) - i2;
        for (Index k2 = 0; k2 < depth; k2 += kc) {
          const Index actual_kc = (std::min)(k2 + kc, depth) - k2;
          pack_lhs(blockA, lhs.getSubMapper(i2, k2), actual_kc, actual_mc);
          for (Index j2 = 0; j2 < cols; j2 += nc) {
            const Index actual_nc = (std::min)(j2 + nc, cols) - j2;
            if ((!pack_rhs_once) || i2 == 0)
              pack_rhs(blockB, rhs.getSubMapper(k2, j2), actual_kc, actual_nc);
            gebp(res.getSubMapper(i2, j2), blockA, blockB, actual_mc, actual_kc, actual_nc, alpha);
          }
        }
      }
    }
  }
};

// generic_product_impl<Lhs, Rhs, DenseShape, DenseShape, GemmProduct>::scaleAndAddTo
// for a product Eigen would run as a GEMM (the caller checks: not the small
// sizes Eigen evaluates coefficient by coefficient, not a matrix-vector one).
template <class Dest, class Lhs, class Rhs>
void kept_scale_and_add(Dest& dst, const Lhs& a_lhs, const Rhs& a_rhs,
                        const typename Dest::Scalar& alpha) {
  using namespace Eigen::internal;
  using Scalar = typename Eigen::Product<Lhs, Rhs>::Scalar;
  using LhsScalar = typename Lhs::Scalar;
  using RhsScalar = typename Rhs::Scalar;
  typedef blas_traits<Lhs> LhsBlasTraits;
  typedef typename LhsBlasTraits::DirectLinearAccessType ActualLhsType;
  typedef typename remove_all<ActualLhsType>::type ActualLhsTypeCleaned;
  typedef blas_traits<Rhs> RhsBlasTraits;
  typedef typename RhsBlasTraits::DirectLinearAccessType ActualRhsType;
  typedef typename remove_all<ActualRhsType>::type ActualRhsTypeCleaned;

  typename add_const_on_value_type<ActualLhsType>::type lhs = LhsBlasTraits::extract(a_lhs);
  typename add_const_on_value_type<ActualRhsType>::type rhs = RhsBlasTraits::extract(a_rhs);
  Scalar actualAlpha = combine_scalar_factors(alpha, a_lhs, a_rhs);

  typedef KeptBlocking<(Dest::Flags & Eigen::RowMajorBit) ? Eigen::RowMajor : Eigen::ColMajor,
                       LhsScalar, RhsScalar>
      BlockingType;
  typedef gemm_functor<
      Scalar, Eigen::Index,
      KeptGemm<
          Eigen::Index, LhsScalar,
          (ActualLhsTypeCleaned::Flags & Eigen::RowMajorBit) ? Eigen::RowMajor : Eigen::ColMajor,
          bool(LhsBlasTraits::NeedToConjugate), RhsScalar,
          (ActualRhsTypeCleaned::Flags & Eigen::RowMajorBit) ? Eigen::RowMajor : Eigen::ColMajor,
          bool(RhsBlasTraits::NeedToConjugate),
          (Dest::Flags & Eigen::RowMajorBit) ? Eigen::RowMajor : Eigen::ColMajor,
          Dest::InnerStrideAtCompileTime>,
      ActualLhsTypeCleaned, ActualRhsTypeCleaned, Dest, BlockingType>
      GemmFunctor;

  BlockingType blocking(dst.rows(), dst.cols(), lhs.cols(), 1, true);
  parallelize_gemm<(Dest::MaxRowsAtCompileTime > 32 ||
                    Dest::MaxRowsAtCompileTime == Eigen::Dynamic)>(
      GemmFunctor(lhs, rhs, dst, actualAlpha, blocking), a_lhs.rows(), a_rhs.cols(), a_lhs.cols(),
      Dest::Flags & Eigen::RowMajorBit);
}

// C = A B, or C += A B: Eigen's `C.noalias() (+)= A * B` to the bit, through
// the kept buffers whenever Eigen would pack.
template <class Dest, class Lhs, class Rhs>
void product(Dest& dst, const Lhs& lhs, const Rhs& rhs, bool accumulate) {
  using Scalar = typename Dest::Scalar;
  const bool coefficient_based =
      (rhs.rows() + dst.rows() + dst.cols()) < EIGEN_GEMM_TO_COEFFBASED_THRESHOLD && rhs.rows() > 0;
  const bool vector_shaped = dst.rows() == 1 || dst.cols() == 1;
  const bool empty = lhs.cols() == 0 || lhs.rows() == 0 || rhs.cols() == 0;
  if (coefficient_based || vector_shaped || empty) {  // Eigen packs nothing for these
    if (accumulate)
      dst.noalias() += lhs * rhs;
    else
      dst.noalias() = lhs * rhs;
    return;
  }
  if (!accumulate) dst.setZero();  // as Eigen's evalTo
  kept_scale_and_add(dst, lhs, rhs, Scalar(1));
}

}  // namespace kept_gemm
}  // namespace jsa
