// Keyword values of our styles' arguments that are words, not numbers (numbers: numbers.h).
#ifndef TSG_ARGUMENTS_H
#define TSG_ARGUMENTS_H

#include <string>

#include "lammps.h"

#include "errors.h"

namespace tsg {

// "yes" or "no", else an error naming the keyword and the value.
inline bool parse_yes_no(LAMMPS_NS::LAMMPS *lmp, const std::string &who, const std::string &keyword, const char *value)
{
  if (std::string(value) == "yes") return true;
  if (std::string(value) == "no") return false;
  fail(lmp, who, keyword + " = '" + value + "' must be 'yes' or 'no'");
  return false;
}

}  // namespace tsg

#endif
