#include "model/tool/mpi/mpi_team.h"

#include <cstdlib>
#include <vector>

#include "engine/check.h"

#ifdef JSATLAS_WITH_MPI
#include <mpi.h>
#endif

namespace jsa {

bool launched_by_mpi() {
  // OpenMPI's mpirun, PMI (MPICH's hydra, srun --mpi=pmi2), PMIx (srun --mpi=pmix).
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK"})
    if (std::getenv(name)) return true;
  return false;
}

#ifdef JSATLAS_WITH_MPI

namespace {

template <class T>
MPI_Datatype mpi_type();
template <>
MPI_Datatype mpi_type<float>() {
  return MPI_FLOAT;
}
template <>
MPI_Datatype mpi_type<double>() {
  return MPI_DOUBLE;
}

class MpiTeam : public Team {
 public:
  MpiTeam() {
    int initialized = 0;
    MPI_Initialized(&initialized);
    if (!initialized) MPI_Init(nullptr, nullptr);
    // Errors return codes we check (JSA_CHECK) rather than abort without a word.
    MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
  }
  ~MpiTeam() override {
    int finalized = 0;
    MPI_Finalized(&finalized);
    if (!finalized) MPI_Finalize();
  }
  int rank() const override { return rank_; }
  int size() const override { return size_; }
  void sum_in_rank_order(float* data, size_t n) override { sum(data, n); }
  void sum_in_rank_order(double* data, size_t n) override { sum(data, n); }
  uint64_t bytes_exchanged() const override { return bytes_; }

 private:
  int rank_ = 0, size_ = 1;
  uint64_t bytes_ = 0;

  // A reduce-scatter then an all-gather, both written as data movement so that
  // we choose the order of the additions (MPI_Allreduce does not promise one):
  // rank r owns chunk r of the vector (model/tool/team.h's shape_block split of
  // the n entries); every rank sends chunk r of its data to rank r
  // (MPI_Alltoallv), rank r adds the P pieces in rank order, and every rank
  // collects the summed chunks (MPI_Allgatherv). Each rank sends and receives
  // about 2 n (P - 1) / P values, as a ring allreduce does.
  template <class T>
  void sum(T* data, size_t n) {
    if (size_ == 1 || n == 0) return;
    JSA_CHECK(n < size_t(1) << 31, "sum_in_rank_order: " << n << " values exceed MPI's int counts");
    const size_t p = size_t(size_);
    std::vector<int> count(p), first(p), mine_count(p), mine_first(p);
    for (size_t r = 0; r < p; ++r) {
      const auto block = shape_block(int(n), size_, int(r));
      first[r] = block.first;
      count[r] = block.second - block.first;
    }
    const int mine = count[size_t(rank_)];
    for (size_t r = 0; r < p; ++r) {
      mine_count[r] = mine;
      mine_first[r] = int(r) * mine;
    }
    std::vector<T> pieces(p * size_t(mine));
    JSA_CHECK(MPI_Alltoallv(data, count.data(), first.data(), mpi_type<T>(), pieces.data(),
                            mine_count.data(), mine_first.data(), mpi_type<T>(),
                            MPI_COMM_WORLD) == MPI_SUCCESS,
              "MPI_Alltoallv failed");
    T* out = data + first[size_t(rank_)];
    for (int i = 0; i < mine; ++i) {
      T s = pieces[size_t(i)];
      for (size_t r = 1; r < p; ++r) s += pieces[r * size_t(mine) + size_t(i)];
      out[i] = s;
    }
    JSA_CHECK(MPI_Allgatherv(MPI_IN_PLACE, 0, mpi_type<T>(), data, count.data(), first.data(),
                             mpi_type<T>(), MPI_COMM_WORLD) == MPI_SUCCESS,
              "MPI_Allgatherv failed");
    // Payload only: what leaves and what reaches this rank in the two collectives.
    const uint64_t others = uint64_t(n) - uint64_t(mine);
    bytes_ += sizeof(T) * (others + (p - 1) * uint64_t(mine)) * 2;
  }
};

}  // namespace

bool mpi_available() { return true; }

std::unique_ptr<Team> join_mpi_team() { return std::make_unique<MpiTeam>(); }

void abort_mpi_job(int code) {
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (initialized) MPI_Abort(MPI_COMM_WORLD, code);
  std::exit(code);
}

#else

bool mpi_available() { return false; }

std::unique_ptr<Team> join_mpi_team() {
  throw InputError(
      "this jsatlas was built without MPI: rebuild with OpenMPI installed (cmake "
      "-DJSATLAS_MPI=ON)");
}

void abort_mpi_job(int code) { std::exit(code); }

#endif

}  // namespace jsa
