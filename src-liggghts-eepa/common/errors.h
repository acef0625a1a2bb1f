// How our styles stop a run: "<who>: <message>" (who = "fix ID style"), on every rank or from one.
// A message that one rank composed reaches every rank first (fail_from), so that rank 0 writes it to
// the screen and to log.lammps and every rank stops in error->all.
#ifndef TSG_ERRORS_H
#define TSG_ERRORS_H

#include <mpi.h>

#include <string>

#include "error.h"
#include "lammps.h"

namespace tsg {

// An error that every rank finds (input checks, a reduced value): error->all.
inline void fail(LAMMPS_NS::LAMMPS *lmp, const std::string &who, const std::string &message)
{
  lmp->error->all(FLERR, (who + ": " + message).c_str());
}

// The same, raised by one rank only (a file that only rank 0 opens, a particle that one rank owns):
// error->one (patched, patches/error-cpp.patch: a rank other than 0 appends it to log.lammps).
inline void fail_one(LAMMPS_NS::LAMMPS *lmp, const std::string &who, const std::string &message)
{
  lmp->error->one(FLERR, (who + ": " + message).c_str());
}

// The text `root` holds, on every rank (the other ranks' `text` is ignored).
inline std::string broadcast_text(MPI_Comm world, std::string text, int root)
{
  int size = static_cast<int>(text.size());
  MPI_Bcast(&size, 1, MPI_INT, root, world);
  text.resize(static_cast<std::string::size_type>(size));
  if (size > 0) MPI_Bcast(&text[0], size, MPI_CHAR, root, world);
  return text;
}

// Called on every rank: stops the run with the message composed on `rank` (found, e.g., by an
// MPI_MAXLOC reduction of who has the worst value), as error->all: rank 0 logs it.
[[noreturn]] inline void fail_from(LAMMPS_NS::LAMMPS *lmp, int rank, const std::string &message)
{
  lmp->error->all(FLERR, broadcast_text(lmp->world, message, rank).c_str());
  throw;  // not reached: error->all exits
}

}  // namespace tsg

#endif
