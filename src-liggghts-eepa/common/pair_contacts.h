// The particle–particle contacts of this step, from the pair style's neighbour list: read by the
// guards (fix check/contact: the deepest contact) and the squeeze ledger (fix squeeze/ledger: each
// particle's deepest contact). With newton off a pair with a ghost partner is listed once on each of
// the two owners' ranks.
#ifndef TSG_PAIR_CONTACTS_H
#define TSG_PAIR_CONTACTS_H

#include <algorithm>
#include <cmath>

#include "atom.h"
#include "force.h"
#include "lammps.h"
#include "neigh_list.h"
#include "neighbor.h"
#include "pair.h"

namespace tsg {

// visit(i, j, ratio) for every listed pair whose spheres overlap: i local, j local or ghost, ratio
// the overlap δ / the smaller radius (0 < ratio, or 0 where the overlap rounds to nothing). No
// neighbour list yet (no pair style, before the first build): no contact.
template <class Visit>
void for_each_pair_contact(const LAMMPS_NS::LAMMPS *lmp, Visit visit)
{
  const LAMMPS_NS::NeighList *list = lmp->force->pair ? lmp->force->pair->list : nullptr;
  if (!list) return;
  double **x = lmp->atom->x;
  const double *radius = lmp->atom->radius;
  for (int ii = 0; ii < list->inum; ++ii) {
    const int i = list->ilist[ii];
    const int *neighbours = list->firstneigh[i];
    for (int jj = 0; jj < list->numneigh[i]; ++jj) {
      const int j = neighbours[jj] & NEIGHMASK;
      const double dx = x[i][0] - x[j][0], dy = x[i][1] - x[j][1], dz = x[i][2] - x[j][2];
      const double reach = radius[i] + radius[j];
      const double r2 = dx * dx + dy * dy + dz * dz;
      if (r2 >= reach * reach) continue;
      visit(i, j, (reach - std::sqrt(r2)) / std::min(radius[i], radius[j]));
    }
  }
}

}  // namespace tsg

#endif
