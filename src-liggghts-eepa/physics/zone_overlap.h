// Which zones a sphere overlaps, and how much of its volume lies in each, dependency-free.
//
// Zones are slabs x_start <= x < x_end (zones.h); the volume of the sphere inside a slab is exact
// (sphere_slab.h), not a count of centres. On a periodic axis the image of a sphere cut by the
// periodic boundary is included, so that sphere contributes to the zones at both ends of the box.
#ifndef TSG_ZONE_OVERLAP_H
#define TSG_ZONE_OVERLAP_H

#include <cstddef>
#include <vector>

#include "sphere_slab.h"
#include "zones.h"

namespace tsg::zones {

// f(zone_index_0_based, fraction_of_sphere_volume) for every zone the sphere overlaps with a
// positive volume. period = 0: open axis; otherwise the axis is periodic over [box_lo, box_lo + period)
// and the image of a sphere sticking out through either end is included.
template <class F>
inline void for_each_overlap(const std::vector<Zone> &zones, double centre, double radius, double period, double box_lo,
                             F &&f)
{
  auto one = [&](double c) {
    for (std::size_t z = first_zone_ending_after(zones, c - radius); z < zones.size() && zones[z].x_start < c + radius;
         ++z) {
      const double fraction = geometry::sphere_slab_fraction(c, radius, zones[z].x_start, zones[z].x_end);
      if (fraction > 0) f(static_cast<int>(z), fraction);
    }
  };
  one(centre);
  if (period > 0) {
    if (centre - radius < box_lo) one(centre + period);
    if (centre + radius > box_lo + period) one(centre - period);
  }
}

}  // namespace tsg::zones

#endif
