// What the measurement styles (fix residence/time, fix massflow/planes) share about particles along
// the axis: the unwrapped axial position and the list of particles near an interval's edges.
// (Errors, numbers, output files, box checks: common/.)
#ifndef TSG_AXIAL_POSITION_H
#define TSG_AXIAL_POSITION_H

#include <cmath>
#include <vector>

#include "atom.h"
#include "domain.h"
#include "lammps.h"
#include "neighbor.h"

namespace tsg::measure {

// Axial coordinate of particle i with its periodic images unwrapped (x itself on an open axis). Image
// flags wrap after IMGMAX periods: when `near` is finite, the result is kept within half that span
// of it (callers pass a cell edge the particle was near a few steps ago).
inline double unwrapped_x(const LAMMPS_NS::Atom *atom, const LAMMPS_NS::Domain *domain, int i, double near = NAN)
{
  double u = atom->x[i][0];
  if (!domain->xperiodic) return u;
  const double length = domain->xprd;
  u += ((atom->image[i] & IMGMASK) - IMGMAX) * length;
  const double span = 2.0 * IMGMAX * length;
  if (std::isfinite(near)) {
    while (u - near > 0.5 * span) u -= span;
    while (near - u > 0.5 * span) u += span;
  }
  return u;
}

// The unwrapped position without the wrap-around guard, for the per-step loops: x0 = &x[0][0],
// length = the period along x (0 on an open axis).
inline double unwrapped_x_fast(const double *x0, const int *image, int i, double length)
{
  return x0[3 * i] + (length > 0 ? ((image[i] & IMGMASK) - IMGMAX) * length : 0.0);
}

// Between neighbour-list builds no particle moves more than half the skin (when every step checks
// the displacements: neigh_modify delay 0 every 1 check yes, radii constant), so a particle more
// than one skin inside its interval [lo, hi) — between zone edges or sensor planes — cannot leave it
// before the next build. NearList keeps the others; the per-step loop reads only their x (and image).
class NearList {
public:
  void configure(const LAMMPS_NS::Neighbor *neighbor, const LAMMPS_NS::Atom *atom)
  {
    usable_ = neighbor->dist_check && neighbor->every == 1 && neighbor->delay == 0 && !neighbor->build_once &&
              !atom->radvary_flag;
    reach_ = neighbor->skin;  // twice the largest move between builds
  }

  // everyone (a build, a set-up) or an unusable list: look(i) for every particle of the group, then
  // list those near an edge of their interval bounds[i] = {lo, hi}; otherwise look(i) only for
  // listed particles that left their interval. look(i) updates bounds[i]. length: the period along x
  // (0 on an open axis).
  template <class Look>
  void visit(bool everyone, const LAMMPS_NS::Atom *atom, int groupbit, double length, double *const *bounds, Look look)
  {
    const double *x = atom->x[0];  // x is one contiguous block: x[i][0] = x[0][3 i]
    const int *image = atom->image;
    if (everyone || !usable_) {
      items_.clear();
      const int nlocal = atom->nlocal;
      const int *mask = atom->mask;
      for (int i = 0; i < nlocal; ++i) {
        if (!(mask[i] & groupbit)) continue;
        look(i);
        if (!usable_) continue;
        const double u = unwrapped_x_fast(x, image, i, length);
        const double lo = bounds[i][0], hi = bounds[i][1];
        if (u - lo < reach_ || hi - u <= reach_) items_.push_back({i, lo, hi});
      }
      return;
    }
    for (Item &n : items_) {
      const double u = unwrapped_x_fast(x, image, n.i, length);
      if (u >= n.lo && u < n.hi) continue;
      look(n.i);
      n.lo = bounds[n.i][0];
      n.hi = bounds[n.i][1];
    }
  }

private:
  struct Item {
    int i;          // local index (valid until the next build)
    double lo, hi;  // copy of its bounds
  };
  std::vector<Item> items_;
  bool usable_ = false;
  double reach_ = 0;
};

}  // namespace tsg::measure

#endif
