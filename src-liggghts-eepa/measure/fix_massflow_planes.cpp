// fix massflow/planes: see fix_massflow_planes.h and docs/measurement.md.
#include "fix_massflow_planes.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string>

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "group.h"
#include "neighbor.h"
#include "output.h"
#include "update.h"

#include "box_checks.h"
#include "errors.h"
#include "numbers.h"
#include "output_files.h"
#include "plane_crossing.h"

using namespace LAMMPS_NS;

using tsg::fail;
using tsg::number;

FixMassflowPlanes::FixMassflowPlanes(LAMMPS *lmp, int narg, char **arg) : FixMeasureBase(lmp, narg, arg)
{
  bool have_planes = false;
  for (int iarg = 3; iarg < narg;) {
    const std::string key = arg[iarg];
    if (key == "planes") {
      long k = 0;
      if (iarg + 1 >= narg || !tsg::parse_integer(arg[iarg + 1], 1, 1000, k))
        fail(lmp, who_,
             std::string("'planes K X1 ... XK' needs a sensor count K between 1 and 1000, got '") +
                 (iarg + 1 < narg ? arg[iarg + 1] : "") + "'");
      if (iarg + 1 + k >= narg)
        fail(lmp, who_, std::string("'planes ") + arg[iarg + 1] + "' needs " + std::to_string(k) + " positions");
      for (long j = 0; j < k; ++j) {
        const char *text = arg[iarg + 2 + j];
        double x = 0;
        if (!tsg::parse_real(text, x))
          fail(lmp, who_,
               "plane " + std::to_string(j + 1) + " position '" + text + "' is not a finite number (m); 'planes " +
                   std::to_string(k) + "' needs " + std::to_string(k) + " positions");
        planes_.push_back(x);
      }
      have_planes = true;
      iarg += 2 + static_cast<int>(k);
    } else if (key == "window") {
      long n = 0;
      if (iarg + 1 >= narg || !tsg::parse_integer(arg[iarg + 1], 1, 2000000000L, n))
        fail(lmp, who_,
             std::string("window = '") + (iarg + 1 < narg ? arg[iarg + 1] : "") +
                 "' must be a positive number of steps");
      window_ = static_cast<int>(n);
      iarg += 2;
    } else if (key == "file") {
      if (iarg + 1 >= narg) fail(lmp, who_, "'file' needs a file name");
      path_ = arg[iarg + 1];
      iarg += 2;
    } else if (key == "append") {
      if (iarg + 1 >= narg) fail(lmp, who_, "append needs 'yes' or 'no'");
      append_ = tsg::parse_append(lmp, who_, arg[iarg + 1]);
      iarg += 2;
    } else {
      fail(lmp, who_, "unknown keyword '" + key + "' (allowed: planes, window, file, append)");
    }
  }
  if (!have_planes) fail(lmp, who_, "missing 'planes K X1 ... XK'");
  if (window_ == 0) fail(lmp, who_, "missing 'window N' (averaging window, steps)");
  if (!path_.empty()) tsg::claim_output(lmp, who_, "mass-flow file", path_);

  size_vector = static_cast<int>(planes_.size());
  mass_.assign(planes_.size(), 0.0);
  rate_.assign(planes_.size(), 0.0);
  allocate_per_atom(kSides + static_cast<int>(planes_.size()), 2);

  // the file is opened when the first run starts: by then a restart file has told the fix whether it
  // continues an earlier measurement (restart() is called after the constructor)
}

// Rank 0 opens the file (append or new, see output_files.h open_output) with its header.
void FixMassflowPlanes::open_mass_flow_file()
{
  file_opened_ = true;
  if (path_.empty()) return;
  std::string header = "# tsg-dem mass flow v1\n";
  header += std::string("# fix ") + id + " massflow/planes, group " + group->names[igroup] + "\n";
  header += "# window " + std::to_string(window_) + " steps; signed mass flow rate (+ towards +x), kg/h\n";
  for (size_t k = 0; k < planes_.size(); ++k)
    header += "# sensor_" + std::to_string(k + 1) + " at x = " + number(planes_[k]) + " m\n";
  header += "# columns: step time";
  for (size_t k = 0; k < planes_.size(); ++k) header += " sensor_" + std::to_string(k + 1);
  header += "\n";
  open_file("mass-flow file", path_, header, {"# fix "}, 2);  // step time rate...
}

void FixMassflowPlanes::init()
{
  if (!atom->rmass_flag) fail(lmp, who_, "needs per-particle mass (atom_style granular or sphere)");
  if (tsg::fixed_box_x(domain))
    for (size_t k = 0; k < planes_.size(); ++k)
      tsg::check_plane_in_box(lmp, who_, "plane " + std::to_string(k + 1) + " at", planes_[k], domain->xperiodic);
  near_.configure(neighbor, atom);
  if (!file_opened_) open_mass_flow_file();
}

void FixMassflowPlanes::refresh(int i)
{
  hot_[i][0] = state_[i][kLo];
  hot_[i][1] = state_[i][kHi];
}

// Records particle i's side of every plane at u, and the interval around u where none changes
// (shrunk on a periodic axis by a margin far above rounding, so that the floor formula of
// plane_crossing.h cannot change inside it).
void FixMassflowPlanes::place(int i, double u)
{
  const double length = period();
  double lo = -INFINITY, hi = INFINITY;
  double *state = state_[i];
  double *side = state + kSides;
  state[kSeen] = 1.0;
  for (size_t k = 0; k < planes_.size(); ++k) {
    const double plane = planes_[k];
    if (length > 0) {
      const double n = std::floor((u - plane) / length);
      side[k] = n;
      lo = std::max(lo, plane + n * length);
      hi = std::min(hi, plane + (n + 1) * length);
    } else if (u >= plane) {
      side[k] = 1.0;
      lo = std::max(lo, plane);
    } else {
      side[k] = 0.0;
      hi = std::min(hi, plane);
    }
  }
  if (length > 0) {
    const double margin = 1e-12 * (std::fabs(u) + length);
    lo += margin;
    hi -= margin;
  }
  state[kLo] = lo;
  state[kHi] = hi;
  refresh(i);
}

void FixMassflowPlanes::setup(int)
{
  clock_.resume(update);
  // first sight of particles present now; positions changed between runs (set, displace_atoms) are
  // taken as they are, without counting
  near_.visit(true, atom, groupbit, period(), hot_, [&](int i) {
    const double near = state_[i][kSeen] != 0 ? state_[i][kLo] : NAN;
    place(i, unwrapped_x(i, std::isfinite(near) ? near : NAN));
  });
}

void FixMassflowPlanes::end_of_step()
{
  const double length = period();
  near_.visit(neighbor->ago == 0, atom, groupbit, length, hot_, [&](int i) { count_one(i, length); });
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
    for (double r : rate_) line += " " + number(r);
    line += "\n";
    fputs(line.c_str(), fp_);
    fflush(fp_);
  }
  std::fill(mass_.begin(), mass_.end(), 0.0);
  window_time_ = 0;
}

void FixMassflowPlanes::count_one(int i, double length)
{
  double u = tsg::measure::unwrapped_x_fast(atom->x[0], atom->image, i, length);
  const double *b = hot_[i];
  if (u >= b[0] && u < b[1]) return;  // the common case: no plane anywhere near
  const double *side = state_[i] + kSides;
  if (state_[i][kSeen] == 0) {  // inserted during this step: counts from the next step on
    place(i, u);
    return;
  }
  u = unwrapped_x(i, std::isfinite(b[0]) ? b[0] : b[1]);
  for (size_t k = 0; k < planes_.size(); ++k) {
    const double now_side = length > 0 ? std::floor((u - planes_[k]) / length) : (u >= planes_[k] ? 1.0 : 0.0);
    const double crossings = now_side - side[k];
    if (crossings != 0) mass_[k] += crossings * atom->rmass[i];
  }
  place(i, u);
}

double FixMassflowPlanes::compute_vector(int k) { return rate_[k]; }

// global state: a format mark, the sensor positions (a restart must continue with the same sensors),
// the open window (duration, net mass), the last rates and the clock. Only rank 0 writes,
// so the open window's mass is first summed onto rank 0 (consolidate(): at restart steps and after
// runs).
namespace {
constexpr double kRestartMark = -20261202.0;  // not a sensor count: marks this layout
}

void FixMassflowPlanes::write_restart(FILE *fp)
{
  std::vector<double> list{kRestartMark, static_cast<double>(planes_.size()), window_time_};
  list.insert(list.end(), planes_.begin(), planes_.end());
  list.insert(list.end(), rate_.begin(), rate_.end());
  list.insert(list.end(), mass_.begin(), mass_.end());
  list.resize(list.size() + 2);
  clock_.save(update, &list[list.size() - 2], &list[list.size() - 1]);
  write_global(fp, list);
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
  if (list[0] != kRestartMark)
    fail(lmp, who_,
         "the restart file was written by an earlier version of this fix, which did not keep its "
         "sensor positions; continue from a restart file written by this version");
  const size_t n = static_cast<size_t>(list[1]);
  const double *positions = list + 3;
  std::string stored;
  for (size_t k = 0; k < n; ++k) stored += (k ? " " : "") + number(positions[k]);
  std::string now_planes;
  for (size_t k = 0; k < planes_.size(); ++k) now_planes += (k ? " " : "") + number(planes_[k]);
  // the same sensors: positions equal within 1 nm (a domain length written with 11 or 13 digits moves
  // a plane by 1e-13 m; no particle crosses that sliver unnoticed in a step of 1e-7 m)
  constexpr double kSamePlane = 1e-9;
  double shift = 0.0;
  for (size_t k = 0; k < std::min(n, planes_.size()); ++k)
    shift = std::max(shift, std::fabs(planes_[k] - positions[k]));
  if (n != planes_.size() || shift > kSamePlane)
    fail(lmp, who_,
         "the restart file was written with planes " + std::to_string(n) + " " + stored + ", this fix has planes " +
             std::to_string(planes_.size()) + " " + now_planes +
             (n == planes_.size() ? " (moved by up to " + number(shift) + " m; allowed: " + number(kSamePlane) + " m)"
                                  : std::string()) +
             "; a mass-flow record cannot mix two sets of sensors: use the planes of the earlier run, or "
             "start a new record (a new fix ID and file)");
  window_time_ = list[2];
  const double *rest = positions + n;
  for (size_t k = 0; k < n; ++k) rate_[k] = rest[k];
  // the open window's mass (consolidated on rank 0 when written) restarts on rank 0
  for (size_t k = 0; k < n; ++k) mass_[k] = comm->me == 0 ? rest[n + k] : 0.0;
  clock_.load(rest[2 * n], rest[2 * n + 1]);
  continuing_ = true;
}
