// compute element/stats: see compute_element_stats.h and docs/measurement.md.
#include "compute_element_stats.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "atom.h"
#include "domain.h"
#include "error.h"
#include "memory.h"
#include "update.h"

#include "box_checks.h"
#include "errors.h"
#include "run_files.h"
#include "sphere_slab.h"
#include "zone_overlap.h"
#include "zones_file.h"

using namespace LAMMPS_NS;

namespace {
enum Column { kVolume, kMass, kMassSpeed, kMassAxial, kCount, kColumns };
}

ComputeElementStats::ComputeElementStats(LAMMPS *lmp, int &iarg, int narg, char **arg) : Compute(lmp, iarg, narg, arg)
{
  const std::string who = std::string("compute ") + id + " element/stats";
  if (narg - iarg != 2 || std::string(arg[iarg]) != "zones")
    tsg::fail(lmp, who, "expected 'compute ID group element/stats zones ZONES_FILE'");
  zones_path_ = arg[iarg + 1];
  zones_ = tsg::measure::read_zones(lmp, zones_path_, who);
  iarg += 2;
  const int rows = static_cast<int>(zones_.size());
  array_flag = 1;
  size_array_rows = rows;
  size_array_cols = 7;
  extarray = 0;
  memory->create(array, rows, 7, "element/stats:array");
  local_.assign(static_cast<size_t>(rows) * kColumns, 0.0);
  global_.assign(local_.size(), 0.0);
}

ComputeElementStats::~ComputeElementStats()
{
  memory->destroy(array);
  tsg::run_files::release(std::string("compute ") + id + " element/stats");
}

void ComputeElementStats::init()
{
  const std::string who = std::string("compute ") + id + " element/stats";
  if (!atom->radius_flag || !atom->rmass_flag)
    tsg::fail(lmp, who, "needs per-particle radius and mass (atom_style granular or sphere)");
  if (tsg::fixed_box_x(domain)) {
    try {
      tsg::zones::check_inside(zones_, domain->boxlo[0], domain->boxhi[0], "zones file '" + zones_path_ + "'");
    } catch (const std::invalid_argument &e) {
      tsg::fail(lmp, who, e.what());
    }
  }
}

void ComputeElementStats::compute_array()
{
  invoked_array = update->ntimestep;
  std::fill(local_.begin(), local_.end(), 0.0);
  const double period = domain->xperiodic ? domain->xprd : 0.0;
  const double box_lo = domain->boxlo[0];
  const int nlocal = atom->nlocal;
  const int *mask = atom->mask;
  double **x = atom->x, **v = atom->v;
  const double *radius = atom->radius, *rmass = atom->rmass;
  for (int i = 0; i < nlocal; ++i) {
    if (!(mask[i] & groupbit)) continue;
    const double r = radius[i];
    const double volume = tsg::geometry::sphere_volume(r);
    const double m = rmass[i];
    const double speed = std::sqrt(v[i][0] * v[i][0] + v[i][1] * v[i][1] + v[i][2] * v[i][2]);
    const double vx = v[i][0];
    tsg::zones::for_each_overlap(zones_, x[i][0], r, period, box_lo, [&](int z, double fraction) {
      double *row = &local_[static_cast<size_t>(z) * kColumns];
      row[kVolume] += fraction * volume;
      row[kMass] += fraction * m;
      row[kMassSpeed] += fraction * m * speed;
      row[kMassAxial] += fraction * m * vx;
    });
    const int centre = tsg::zones::find_zone(zones_, x[i][0]);
    if (centre >= 0) local_[static_cast<size_t>(centre) * kColumns + kCount] += 1;
  }
  MPI_Allreduce(local_.data(), global_.data(), static_cast<int>(local_.size()), MPI_DOUBLE, MPI_SUM, world);
  for (size_t z = 0; z < zones_.size(); ++z) {
    const double *row = &global_[z * kColumns];
    array[z][0] = row[kVolume] / zones_[z].free_volume;
    array[z][1] = row[kMass] > 0 ? row[kMassSpeed] / row[kMass] : 0.0;
    array[z][2] = row[kMass] > 0 ? row[kMassAxial] / row[kMass] : 0.0;
    array[z][3] = row[kCount];
    array[z][4] = row[kMass];
    array[z][5] = row[kMassSpeed];
    array[z][6] = row[kMassAxial];
  }
}
