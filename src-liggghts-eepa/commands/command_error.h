// `error "message"` — stop the run with a LIGGGHTS error carrying the message (exit status 1).
// Input scripts use it to reject a bad variable value with a clear text, as cases/include/models.in:
//   else "error cohesion = ${cohesion} is not allowed: use 0 (cohesionless, Hertz) or 1 (high cohesion, EEPA)"
#ifdef COMMAND_CLASS
// clang-format off
CommandStyle(error,ErrorCommand)
// clang-format on
#else
#ifndef TSG_COMMAND_ERROR_H
#define TSG_COMMAND_ERROR_H

#include <string>

#include "error.h"
#include "pointers.h"

namespace LAMMPS_NS {

class ErrorCommand : protected Pointers {
public:
  explicit ErrorCommand(class LAMMPS *lmp) : Pointers(lmp) {}
  void command(int narg, char **arg)
  {
    std::string message;
    for (int i = 0; i < narg; ++i) message += (i ? " " : "") + std::string(arg[i]);
    error->all(FLERR, message.empty() ? "error command" : message.c_str());
  }
};

}  // namespace LAMMPS_NS

#endif
#endif
