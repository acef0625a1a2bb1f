// compute element/stats — per-zone (screw element) solid fraction, velocities, count and mass.
//
//   compute ID group element/stats zones ZONES_FILE
//
// Global array, one row per zone of the zones file (physics/zones.h), columns:
//   1 solid_fraction       volume of particle matter inside the zone / the zone's free volume; the
//                          volume of each sphere inside the slab x_start <= x < x_end is exact
//                          (spherical caps, physics/sphere_slab.h), spheres cut by a zone boundary
//                          count in both zones, and on a periodic x axis across the box boundary too
//   2 mean_speed           mean |v| of the matter in the zone (each particle weighted by its mass
//                          inside the zone), m/s
//   3 mean_axial_velocity  mean v_x, same weights, m/s
//   4 count                particles whose centre lies in the zone
//   5 mass                 mass of particle matter inside the zone, kg
//   6 mass_speed           sum of mass-in-zone x |v|, kg m/s   (= column 5 x column 2)
//   7 axial_momentum       sum of mass-in-zone x v_x, kg m/s   (= column 5 x column 3)
// Columns 2 and 3 are 0 for an empty zone. Time averages: fix ave/time N R N*R c_ID[1] ... c_ID[7]
// mode vector file elements.txt; the mass-weighted time average of the velocities is
// <column 6>/<column 5> and <column 7>/<column 5> (the plain average of columns 2 and 3 counts the
// samples in which a zone was empty as 0).
#ifdef COMPUTE_CLASS
// clang-format off
ComputeStyle(element/stats,ComputeElementStats)
// clang-format on
#else
#ifndef TSG_COMPUTE_ELEMENT_STATS_H
#define TSG_COMPUTE_ELEMENT_STATS_H

#include <string>
#include <vector>

#include "compute.h"

#include "zones.h"

namespace LAMMPS_NS {

class ComputeElementStats : public Compute {
public:
  ComputeElementStats(class LAMMPS *, int &, int, char **);
  ~ComputeElementStats() override;
  void init() override;
  void compute_array() override;

private:
  std::string zones_path_;
  std::vector<tsg::zones::Zone> zones_;
  std::vector<double> local_, global_;
};

}  // namespace LAMMPS_NS

#endif
#endif
