// The Team of model/tool/team.h over MPI_COMM_WORLD, for `mpirun -np P jsatlas
// fit` (docs/mpi.md). Compiled when CMake finds MPI (-DJSATLAS_MPI=AUTO/ON);
// without it, mpi_available() is false and join_mpi_team() throws. Not a room:
// compiled into the jsatlas binary only, so that no library depends on MPI.
#pragma once
#include <memory>

#include "model/tool/team.h"

namespace jsa {

// This build speaks MPI.
bool mpi_available();
// This process was started by an MPI launcher (mpirun, mpiexec, srun): its
// environment names a rank. Checked before MPI_Init, so that a plain
// `jsatlas fit` never initialises MPI.
bool launched_by_mpi();
// MPI_Init and the team of every process of the job; MPI_Finalize when it is
// destroyed. Throws InputError in a build without MPI.
std::unique_ptr<Team> join_mpi_team();
// Ends every process of the job with exit code `code` (MPI_Abort): for an error
// that one rank meets alone, which would otherwise leave the others waiting.
[[noreturn]] void abort_mpi_job(int code);

}  // namespace jsa
