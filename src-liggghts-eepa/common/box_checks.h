// Positions given in the input checked against the simulation box along x (the screws' axis).
#ifndef TSG_BOX_CHECKS_H
#define TSG_BOX_CHECKS_H

#include <string>

#include "domain.h"
#include "lammps.h"

#include "errors.h"
#include "numbers.h"

namespace tsg {

// Whether the box along x is fixed (periodic or fixed walls) rather than shrink-wrapped (the box
// follows the particles, so positions in the input cannot be checked against it).
inline bool fixed_box_x(const LAMMPS_NS::Domain *domain)
{
  return domain->boundary[0][0] <= 1 && domain->boundary[0][1] <= 1;
}

// An error unless x lies in the box along x: [lo, hi], or [lo, hi) on a periodic axis where hi is lo.
inline void check_plane_in_box(LAMMPS_NS::LAMMPS *lmp, const std::string &who, const std::string &what, double x,
                               bool upper_open)
{
  const double lo = lmp->domain->boxlo[0], hi = lmp->domain->boxhi[0];
  if (x < lo || x > hi || (upper_open && x >= hi))
    fail(lmp, who,
         what + " x = " + number(x) + " lies outside the simulation box along x [" + number(lo) + ", " + number(hi) +
             (upper_open ? ")" : "]"));
}

}  // namespace tsg

#endif
