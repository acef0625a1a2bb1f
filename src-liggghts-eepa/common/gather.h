// Every rank's values concatenated in rank order: on rank 0 (records that rank 0 writes) or on every
// rank (what every rank needs: the whole screw mesh, the crossings a guard names).
#ifndef TSG_GATHER_H
#define TSG_GATHER_H

#include <mpi.h>

#include <vector>

namespace tsg {

// On rank 0; empty elsewhere.
inline std::vector<double> gather_to_root(MPI_Comm world, const std::vector<double> &mine, int me, int nprocs)
{
  int count = static_cast<int>(mine.size());
  std::vector<int> counts(nprocs), displs(nprocs, 0);
  MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, world);
  int total = 0;
  if (me == 0)
    for (int p = 0; p < nprocs; ++p) {
      displs[p] = total;
      total += counts[p];
    }
  std::vector<double> all(me == 0 ? static_cast<size_t>(total) : 0);
  MPI_Gatherv(mine.data(), count, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE, 0, world);
  return all;
}

// On every rank.
inline std::vector<double> gather_to_all(MPI_Comm world, const std::vector<double> &mine, int nprocs)
{
  int count = static_cast<int>(mine.size());
  std::vector<int> counts(nprocs), displs(nprocs, 0);
  MPI_Allgather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, world);
  int total = 0;
  for (int p = 0; p < nprocs; ++p) {
    displs[p] = total;
    total += counts[p];
  }
  std::vector<double> all(static_cast<size_t>(total));
  MPI_Allgatherv(mine.data(), count, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE, world);
  return all;
}

}  // namespace tsg

#endif
