// fix massflow/planes: see fix_massflow_planes.h and docs/measurement.md.
#include "fix_massflow_planes.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string>

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "group.h"
#include "memory.h"
#include "neighbor.h"
#include "output.h"
#include "update.h"

#include "plane_crossing.h"

using namespace LAMMPS_NS;

namespace {
std::string number(double value) {
  char buffer[32];
  snprintf(buffer, sizeof buffer, "%.10g", value);
  return buffer;
}
}  // namespace

FixMassflowPlanes::FixMassflowPlanes(LAMMPS *lmp, int narg, char **arg)
  : Fix(lmp, narg, arg), window_(0), append_(false), fp_(nullptr), bounds_(nullptr), side_(nullptr), nside_(0), near_usable_(false), reach_(0), window_time_(0),
    clock_offset_(0), clock_from_restart_(false), restart_time_(0), restart_step_(0)
{
  const std::string who = std::string("fix ") + id + " massflow/planes";
  bool have_planes = false;
  for (int iarg = 3; iarg < narg;) {
    const std::string key = arg[iarg];
    if (key == "planes") {
      char *end = nullptr;
      const long k = iarg + 1 < narg ? strtol(arg[iarg + 1], &end, 10) : 0;
      if (iarg + 1 >= narg || *end != '\0' || k < 1 || k > 1000)
        error->all(FLERR, (who + ": 'planes K X1 ... XK' needs a sensor count K between 1 and 1000, got '" +
                           (iarg + 1 < narg ? arg[iarg + 1] : "") + "'").c_str());
      if (iarg + 1 + k >= narg)
        error->all(FLERR, (who + ": 'planes " + arg[iarg + 1] + "' needs " + std::to_string(k) + " positions").c_str());
      for (long j = 0; j < k; ++j) {
        const char *text = arg[iarg + 2 + j];
        char *stop = nullptr;
        errno = 0;
        const double x = strtod(text, &stop);
        if (*stop != '\0' || errno == ERANGE || !std::isfinite(x))
          error->all(FLERR, (who + ": plane " + std::to_string(j + 1) + " position '" + text +
                             "' is not a finite number (m); 'planes " + std::to_string(k) + "' needs " +
                             std::to_string(k) + " positions").c_str());
        planes_.push_back(x);
      }
      have_planes = true;
      iarg += 2 + static_cast<int>(k);
    } else if (key == "window") {
      char *end = nullptr;
      const long n = iarg + 1 < narg ? strtol(arg[iarg + 1], &end, 10) : 0;
      if (iarg + 1 >= narg || *end != '\0' || n < 1 || n > 2000000000L)
        error->all(FLERR, (who + ": window = '" + (iarg + 1 < narg ? arg[iarg + 1] : "") +
                           "' must be a positive number of steps").c_str());
      window_ = static_cast<int>(n);
      iarg += 2;
    } else if (key == "file") {
      if (iarg + 1 >= narg) error->all(FLERR, (who + ": 'file' needs a file name").c_str());
      path_ = arg[iarg + 1];
      iarg += 2;
    } else if (key == "append") {
      if (iarg + 1 >= narg || (strcmp(arg[iarg + 1], "yes") != 0 && strcmp(arg[iarg + 1], "no") != 0))
        error->all(FLERR, (who + ": append must be 'yes' or 'no'").c_str());
      append_ = strcmp(arg[iarg + 1], "yes") == 0;
      iarg += 2;
    } else {
      error->all(FLERR, (who + ": unknown keyword '" + key + "' (allowed: planes, window, file, append)").c_str());
    }
  }
  if (!have_planes) error->all(FLERR, (who + ": missing 'planes K X1 ... XK'").c_str());
  if (window_ == 0) error->all(FLERR, (who + ": missing 'window N' (averaging window, steps)").c_str());

  nevery = 1;
  vector_flag = 1;
  size_vector = static_cast<int>(planes_.size());
  global_freq = 1;
  extvector = 0;
  restart_global = 1;
  restart_peratom = 1;
  create_attribute = 1;
  mass_.assign(planes_.size(), 0.0);
  rate_.assign(planes_.size(), 0.0);

  nside_ = 1 + static_cast<int>(planes_.size());
  grow_arrays(atom->nmax);
  for (int i = 0; i < atom->nmax; ++i) set_arrays(i);
  atom->add_callback(0);
  atom->add_callback(1);

  if (!path_.empty() && comm->me == 0) {
    fp_ = fopen(path_.c_str(), append_ ? "a" : "w");
    if (!fp_)
      error->one(FLERR, (who + ": cannot open file '" + path_ + "' for writing: " + strerror(errno)).c_str());
    fseek(fp_, 0, SEEK_END);
    if (ftell(fp_) == 0) {
      std::string header = "# tsg-dem mass flow v1\n";
      header += std::string("# fix ") + id + " massflow/planes, group " + group->names[igroup] + "; window " +
                std::to_string(window_) + " steps; signed mass flow rate (+ towards +x), kg/h\n";
      for (size_t k = 0; k < planes_.size(); ++k)
        header += "# sensor_" + std::to_string(k + 1) + " at x = " + number(planes_[k]) + " m\n";
      header += "# columns: step time";
      for (size_t k = 0; k < planes_.size(); ++k) header += " sensor_" + std::to_string(k + 1);
      header += "\n";
      fputs(header.c_str(), fp_);
      fflush(fp_);
    }
  }
}

FixMassflowPlanes::~FixMassflowPlanes()
{
  atom->delete_callback(id, 0);
  atom->delete_callback(id, 1);
  memory->destroy(bounds_);
  memory->destroy(side_);
  if (fp_) fclose(fp_);
}

int FixMassflowPlanes::setmask() { return FixConst::END_OF_STEP; }

void FixMassflowPlanes::init()
{
  const std::string who = std::string("fix ") + id + " massflow/planes";
  if (!atom->rmass_flag) error->all(FLERR, (who + " needs per-particle mass (atom_style granular or sphere)").c_str());
  const double lo = domain->boxlo[0], hi = domain->boxhi[0];
  const bool fixed_box = domain->boundary[0][0] <= 1 && domain->boundary[0][1] <= 1;
  if (fixed_box)
    for (size_t k = 0; k < planes_.size(); ++k) {
      const double x = planes_[k];
      if (x < lo || x > hi || (domain->xperiodic && x >= hi))
        error->all(FLERR, (who + ": plane " + std::to_string(k + 1) + " at x = " + number(x) +
                           " lies outside the simulation box along x [" + number(lo) + ", " + number(hi) +
                           (domain->xperiodic ? ")" : "]")).c_str());
    }
  near_usable_ = neighbor->dist_check && neighbor->every == 1 && neighbor->delay == 0 && !neighbor->build_once &&
                 !atom->radvary_flag;
  reach_ = neighbor->skin;
}

double FixMassflowPlanes::unwrapped_x(int i, double near) const
{
  double u = atom->x[i][0];
  if (!domain->xperiodic) return u;
  const double length = domain->xprd;
  u += ((atom->image[i] & IMGMASK) - IMGMAX) * length;
  const double span = 2.0 * IMGMAX * length;  // image flags wrap after IMGMAX periods
  if (std::isfinite(near)) {
    while (u - near > 0.5 * span) u -= span;
    while (near - u > 0.5 * span) u += span;
  }
  return u;
}

double FixMassflowPlanes::now() const { return update->get_cur_time() + clock_offset_; }

double FixMassflowPlanes::period() const { return domain->xperiodic ? domain->xprd : 0.0; }

// Records particle i's side of every plane at u, and the interval around u where none changes
// (shrunk on a periodic axis by a margin far above rounding, so that the floor formula of
// plane_crossing.h cannot change inside it).
void FixMassflowPlanes::place(int i, double u)
{
  const double length = period();
  double lo = -INFINITY, hi = INFINITY;
  double *side = side_[i];
  side[0] = 1.0;
  for (size_t k = 0; k < planes_.size(); ++k) {
    const double plane = planes_[k];
    if (length > 0) {
      const double n = std::floor((u - plane) / length);
      side[1 + k] = n;
      lo = std::max(lo, plane + n * length);
      hi = std::min(hi, plane + (n + 1) * length);
    } else if (u >= plane) {
      side[1 + k] = 1.0;
      lo = std::max(lo, plane);
    } else {
      side[1 + k] = 0.0;
      hi = std::min(hi, plane);
    }
  }
  if (length > 0) {
    const double margin = 1e-12 * (std::fabs(u) + length);
    lo += margin;
    hi -= margin;
  }
  bounds_[i][0] = lo;
  bounds_[i][1] = hi;
}

void FixMassflowPlanes::setup(int)
{
  if (clock_from_restart_) {
    clock_offset_ = restart_time_ + static_cast<double>(update->ntimestep - static_cast<bigint>(restart_step_)) * update->dt -
                    update->get_cur_time();
    clock_from_restart_ = false;
  }
  // first sight of particles present now; positions changed between runs (set, displace_atoms) are
  // taken as they are, without counting
  near_.clear();
  for (int i = 0; i < atom->nlocal; ++i)
    if (atom->mask[i] & groupbit) {
      const double near = side_[i][0] != 0 ? bounds_[i][0] : NAN;
      const double u = unwrapped_x(i, std::isfinite(near) ? near : NAN);
      place(i, u);
      if (near_usable_ && (u - bounds_[i][0] < reach_ || bounds_[i][1] - u <= reach_))
        near_.push_back({i, bounds_[i][0], bounds_[i][1]});
    }
}

void FixMassflowPlanes::end_of_step()
{
  const double length = period();
  const double *x = atom->x[0];  // x is one contiguous block: x[i][0] = x[0][3 i]
  const tagint *image = atom->image;
  if (neighbor->ago == 0 || !near_usable_) {
    near_.clear();
    const int nlocal = atom->nlocal;
    const int *mask = atom->mask;
    for (int i = 0; i < nlocal; ++i) {
      if (!(mask[i] & groupbit)) continue;
      count_one(i, length);
      if (!near_usable_) continue;
      const double u = x[3 * i] + (length > 0 ? ((image[i] & IMGMASK) - IMGMAX) * length : 0.0);
      const double lo = bounds_[i][0], hi = bounds_[i][1];
      if (u - lo < reach_ || hi - u <= reach_) near_.push_back({i, lo, hi});
    }
  } else {
    for (Near &n : near_) {
      const double u = x[3 * n.i] + (length > 0 ? ((image[n.i] & IMGMASK) - IMGMAX) * length : 0.0);
      if (u >= n.lo && u < n.hi) continue;
      count_one(n.i, length);
      n.lo = bounds_[n.i][0];
      n.hi = bounds_[n.i][1];
    }
  }
  window_time_ += update->dt;
  const size_t nplanes = planes_.size();
  if (update->ntimestep % window_ != 0) {
    if (output->restart_requested(update->ntimestep)) consolidate();
    return;
  }
  std::vector<double> total(nplanes);
  MPI_Allreduce(mass_.data(), total.data(), static_cast<int>(nplanes), MPI_DOUBLE, MPI_SUM, world);
  for (size_t k = 0; k < nplanes; ++k) rate_[k] = total[k] / window_time_ * tsg::flow::kSecondsPerHour;
  if (fp_) {
    std::string line = std::to_string(update->ntimestep) + " " + number(now());
    char buffer[32];
    for (double r : rate_) {
      snprintf(buffer, sizeof buffer, " %.10g", r);
      line += buffer;
    }
    line += "\n";
    fputs(line.c_str(), fp_);
    fflush(fp_);
  }
  std::fill(mass_.begin(), mass_.end(), 0.0);
  window_time_ = 0;
}

void FixMassflowPlanes::count_one(int i, double length)
{
  double u = atom->x[i][0];
  if (length > 0) u += ((atom->image[i] & IMGMASK) - IMGMAX) * length;
  const double *b = bounds_[i];
  if (u >= b[0] && u < b[1]) return;  // the common case: no plane anywhere near
  double *side = side_[i];
  if (side[0] == 0) {  // inserted during this step: counts from the next step on
    place(i, u);
    return;
  }
  u = unwrapped_x(i, std::isfinite(b[0]) ? b[0] : b[1]);
  for (size_t k = 0; k < planes_.size(); ++k) {
    const double now_side = length > 0 ? std::floor((u - planes_[k]) / length) : (u >= planes_[k] ? 1.0 : 0.0);
    const double crossings = now_side - side[1 + k];
    if (crossings != 0) mass_[k] += crossings * atom->rmass[i];
  }
  place(i, u);
}

double FixMassflowPlanes::compute_vector(int k) { return rate_[k]; }

void FixMassflowPlanes::grow_arrays(int nmax)
{
  memory->grow(bounds_, nmax, 2, "massflow/planes:bounds");
  memory->grow(side_, nmax, nside_, "massflow/planes:side");
}

void FixMassflowPlanes::copy_arrays(int i, int j, int)
{
  bounds_[j][0] = bounds_[i][0];
  bounds_[j][1] = bounds_[i][1];
  std::copy(side_[i], side_[i] + nside_, side_[j]);
}

void FixMassflowPlanes::set_arrays(int i)
{
  bounds_[i][0] = bounds_[i][1] = 0.0;  // empty interval: the next step looks at it
  std::fill(side_[i], side_[i] + nside_, 0.0);  // not seen yet
}

int FixMassflowPlanes::pack_exchange(int i, double *buf)
{
  buf[0] = bounds_[i][0];
  buf[1] = bounds_[i][1];
  std::copy(side_[i], side_[i] + nside_, buf + 2);
  return 2 + nside_;
}

int FixMassflowPlanes::unpack_exchange(int nlocal, double *buf)
{
  bounds_[nlocal][0] = buf[0];
  bounds_[nlocal][1] = buf[1];
  std::copy(buf + 2, buf + 2 + nside_, side_[nlocal]);
  return 2 + nside_;
}

int FixMassflowPlanes::pack_restart(int i, double *buf)
{
  buf[0] = 3 + nside_;
  buf[1] = bounds_[i][0];
  buf[2] = bounds_[i][1];
  std::copy(side_[i], side_[i] + nside_, buf + 3);
  return 3 + nside_;
}

void FixMassflowPlanes::unpack_restart(int nlocal, int nth)
{
  double **extra = atom->extra;
  int m = 0;
  for (int i = 0; i < nth; ++i) m += static_cast<int>(extra[nlocal][m]);
  if (static_cast<int>(extra[nlocal][m]) != 3 + nside_)
    error->one(FLERR, (std::string("fix ") + id + " massflow/planes: the restart file holds " +
                       std::to_string(static_cast<int>(extra[nlocal][m]) - 3) + " sides per particle, this fix needs " +
                       std::to_string(nside_) + " (a different number of planes?)").c_str());
  bounds_[nlocal][0] = extra[nlocal][m + 1];
  bounds_[nlocal][1] = extra[nlocal][m + 2];
  std::copy(&extra[nlocal][m + 3], &extra[nlocal][m + 3] + nside_, side_[nlocal]);
}

int FixMassflowPlanes::size_restart(int) { return 3 + nside_; }

int FixMassflowPlanes::maxsize_restart() { return 3 + nside_; }

// global state: the open window (duration, net mass) and the last rates. Only rank 0 writes, so the
// open window's mass is first summed onto rank 0 (consolidate(): at restart steps and after runs).
void FixMassflowPlanes::write_restart(FILE *fp)
{
  const size_t n = planes_.size();
  std::vector<double> list;
  list.push_back(static_cast<double>(n));
  list.push_back(window_time_);
  list.insert(list.end(), rate_.begin(), rate_.end());
  list.insert(list.end(), mass_.begin(), mass_.end());
  list.push_back(now());
  list.push_back(static_cast<double>(update->ntimestep));
  if (comm->me == 0) {
    int size = static_cast<int>(list.size() * sizeof(double));
    fwrite(&size, sizeof(int), 1, fp);
    fwrite(list.data(), sizeof(double), list.size(), fp);
  }
}

// Sums the open window's mass over the ranks onto rank 0 (collective); the total is unchanged.
void FixMassflowPlanes::consolidate()
{
  std::vector<double> total(planes_.size());
  MPI_Allreduce(mass_.data(), total.data(), static_cast<int>(planes_.size()), MPI_DOUBLE, MPI_SUM, world);
  for (size_t k = 0; k < planes_.size(); ++k) mass_[k] = comm->me == 0 ? total[k] : 0.0;
}

void FixMassflowPlanes::post_run() { consolidate(); }

void FixMassflowPlanes::restart(char *buf)
{
  const double *list = reinterpret_cast<const double *>(buf);
  const size_t n = static_cast<size_t>(list[0]);
  if (n != planes_.size())
    error->all(FLERR, (std::string("fix ") + id + " massflow/planes: the restart file has " + std::to_string(n) +
                       " sensors, this fix " + std::to_string(planes_.size())).c_str());
  window_time_ = list[1];
  for (size_t k = 0; k < n; ++k) rate_[k] = list[2 + k];
  // the open window's mass (consolidated on rank 0 when written) restarts on rank 0
  for (size_t k = 0; k < n; ++k) mass_[k] = comm->me == 0 ? list[2 + n + k] : 0.0;
  restart_time_ = list[2 + 2 * n];
  restart_step_ = list[3 + 2 * n];
  clock_from_restart_ = true;
}

double FixMassflowPlanes::memory_usage() { return static_cast<double>(atom->nmax) * (2 + nside_) * sizeof(double); }
