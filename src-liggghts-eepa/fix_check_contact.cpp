// fix check/contact: see fix_check_contact.h.
#include "fix_check_contact.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "atom.h"
#include "comm.h"
#include "error.h"
#include "fix_property_global.h"
#include "force.h"
#include "modify.h"
#include "neigh_list.h"
#include "pair.h"
#include "update.h"

#include "contact_timestep.h"

using namespace LAMMPS_NS;

FixCheckContact::FixCheckContact(LAMMPS *lmp, int narg, char **arg)
  : Fix(lmp, narg, arg), step_fraction_(0.2), error_on_violation_(false), warned_(false),
    max_overlap_ratio_run_(0), max_overlap_ratio_now_(0), estimate_(0),
    youngs_modulus_(nullptr), poisson_ratio_(nullptr), plasticity_ratio_(nullptr)
{
  nevery = 1000;
  for (int iarg = 3; iarg < narg; iarg += 2) {
    if (iarg + 1 >= narg)
      error->fix_error(FLERR, this, (std::string("keyword '") + arg[iarg] + "' needs a value").c_str());
    const std::string key = arg[iarg];
    const char *value = arg[iarg + 1];
    if (key == "every") {
      nevery = force->inumeric(FLERR, value);
      if (nevery < 1)
        error->fix_error(FLERR, this, (std::string("every = ") + value + " must be a positive integer").c_str());
    } else if (key == "step_fraction") {
      step_fraction_ = force->numeric(FLERR, value);
      if (!(step_fraction_ > 0 && step_fraction_ <= 1))
        error->fix_error(FLERR, this, (std::string("step_fraction = ") + value + " is outside the allowed range (0, 1]").c_str());
    } else if (key == "action") {
      if (strcmp(value, "warn") == 0) error_on_violation_ = false;
      else if (strcmp(value, "error") == 0) error_on_violation_ = true;
      else error->fix_error(FLERR, this, (std::string("action = ") + value + " must be 'warn' or 'error'").c_str());
    } else {
      error->fix_error(FLERR, this, (std::string("unknown keyword '") + key + "' (allowed: every, step_fraction, action)").c_str());
    }
  }
  vector_flag = 1;
  size_vector = 4;
  global_freq = nevery;
  extvector = 0;
}

int FixCheckContact::setmask() { return FixConst::END_OF_STEP; }

void FixCheckContact::init()
{
  if (!force->pair_match("gran", 0))
    error->fix_error(FLERR, this, "needs a granular pair style (pair_style gran ...)");
  const int ntypes = atom->ntypes;
  youngs_modulus_ = static_cast<FixPropertyGlobal *>(
      modify->find_fix_property("youngsModulus", "property/global", "peratomtype", ntypes, 0, style));
  poisson_ratio_ = static_cast<FixPropertyGlobal *>(
      modify->find_fix_property("poissonsRatio", "property/global", "peratomtype", ntypes, 0, style));
  plasticity_ratio_ = static_cast<FixPropertyGlobal *>(
      modify->find_fix_property("plasticityRatio", "property/global", "peratomtypepair", ntypes, ntypes, style, false));
}

void FixCheckContact::setup(int) { check(); }

void FixCheckContact::end_of_step() { check(); }

// Smallest Rayleigh time over all particles (each with its own radius, density and material),
// times sqrt(1 - λp) for the largest λp when EEPA is configured.
double FixCheckContact::critical_step() const
{
  double smallest = INFINITY;
  for (int i = 0; i < atom->nlocal; ++i) {
    if (!(atom->mask[i] & groupbit)) continue;
    const int type = atom->type[i];
    const double youngs = youngs_modulus_->compute_vector(type - 1);
    const double poisson = poisson_ratio_->compute_vector(type - 1);
    const double shear = youngs / (2 * (1 + poisson));
    smallest = std::min(smallest, tsg::timestep::rayleigh_time(atom->radius[i], atom->density[i], shear, poisson));
  }
  double global = INFINITY;
  MPI_Allreduce(&smallest, &global, 1, MPI_DOUBLE, MPI_MIN, world);
  if (plasticity_ratio_) {
    double largest_ratio = 0;
    for (int i = 0; i < atom->ntypes; ++i)
      for (int j = 0; j < atom->ntypes; ++j)
        largest_ratio = std::max(largest_ratio, plasticity_ratio_->compute_array(i, j));
    global *= tsg::timestep::eepa_step_factor(largest_ratio);
  }
  return global;
}

// Largest δ / min(Ri, Rj) over the pair style's neighbour list.
double FixCheckContact::largest_overlap_ratio() const
{
  double largest = 0;
  const NeighList *list = force->pair->list;
  if (list) {
    double **x = atom->x;
    const double *radius = atom->radius;
    for (int ii = 0; ii < list->inum; ++ii) {
      const int i = list->ilist[ii];
      if (!(atom->mask[i] & groupbit)) continue;
      const int *neighbours = list->firstneigh[i];
      for (int jj = 0; jj < list->numneigh[i]; ++jj) {
        const int j = neighbours[jj] & NEIGHMASK;
        const double dx = x[i][0] - x[j][0], dy = x[i][1] - x[j][1], dz = x[i][2] - x[j][2];
        const double overlap = radius[i] + radius[j] - std::sqrt(dx * dx + dy * dy + dz * dz);
        if (overlap > 0) largest = std::max(largest, overlap / std::min(radius[i], radius[j]));
      }
    }
  }
  double global = 0;
  MPI_Allreduce(&largest, &global, 1, MPI_DOUBLE, MPI_MAX, world);
  return global;
}

void FixCheckContact::check()
{
  max_overlap_ratio_now_ = largest_overlap_ratio();
  max_overlap_ratio_run_ = std::max(max_overlap_ratio_run_, max_overlap_ratio_now_);
  const double estimate = critical_step();
  if (!std::isfinite(estimate)) return;  // no particles yet
  const bool changed = estimate != estimate_;
  estimate_ = estimate;
  const double ratio = update->dt / estimate_;
  if (changed && comm->me == 0) {
    char line[512];
    snprintf(line, sizeof line,
             "check/contact: critical step estimate %.4g s (Rayleigh time of the smallest particle%s); "
             "time step %.4g s = %.3g of it (allowed: %.3g)\n",
             estimate_, plasticity_ratio_ ? " x sqrt(1 - max plasticityRatio)" : "", update->dt, ratio, step_fraction_);
    if (screen) fputs(line, screen);
    if (logfile) fputs(line, logfile);
  }
  if (ratio > step_fraction_) {
    char message[512];
    snprintf(message, sizeof message,
             "check/contact: time step %.4g s is %.3g of the critical step estimate %.4g s, "
             "above the allowed step_fraction %.3g; use timestep <= %.4g",
             update->dt, ratio, estimate_, step_fraction_, step_fraction_ * estimate_);
    if (error_on_violation_) error->all(FLERR, message);
    if (!warned_ && comm->me == 0) error->warning(FLERR, message);
    warned_ = true;
  }
}

double FixCheckContact::compute_vector(int n)
{
  switch (n) {
    case 0: return max_overlap_ratio_run_;
    case 1: return max_overlap_ratio_now_;
    case 2: return estimate_;
    default: return estimate_ > 0 ? update->dt / estimate_ : 0;
  }
}
