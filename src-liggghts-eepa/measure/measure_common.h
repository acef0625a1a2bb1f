// What the measurement styles (fix residence/time, fix massflow/planes, compute element/stats) share:
// the error idiom, number parsing and printing, the unwrapped axial position, box checks, the lists
// of particles near a plane, output files, and the registration of the files they read and write (run_files.h).
#ifndef TSG_MEASURE_COMMON_H
#define TSG_MEASURE_COMMON_H

#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "lammps.h"
#include "neighbor.h"
#include "update.h"

#include "record_rollback.h"
#include "restart_clock.h"
#include "run_files.h"

namespace tsg::measure {

// Every error of a measurement style: "<who>: <message>" on all ranks (who = "fix ID style").
inline void fail(LAMMPS_NS::LAMMPS *lmp, const std::string &who, const std::string &message)
{
  lmp->error->all(FLERR, (who + ": " + message).c_str());
}

// The same, raised by one rank only (a file that only rank 0 opens, a particle that one rank owns).
inline void fail_one(LAMMPS_NS::LAMMPS *lmp, const std::string &who, const std::string &message)
{
  lmp->error->one(FLERR, (who + ": " + message).c_str());
}

// Numbers in messages and file headers: 10 significant digits, no trailing zeros.
inline std::string number(double value)
{
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.10g", value);
  return buffer;
}

// Whole-token finite real: "1e-3" yes; "", "5cm", "nan", "inf", "1e999" no.
inline bool parse_real(const char *text, double &value)
{
  if (!text || !*text) return false;
  char *end = nullptr;
  errno = 0;
  value = std::strtod(text, &end);
  return *end == '\0' && errno != ERANGE && std::isfinite(value);
}

// Whole-token integer in [lo, hi].
inline bool parse_integer(const char *text, long lo, long hi, long &value)
{
  if (!text || !*text) return false;
  char *end = nullptr;
  errno = 0;
  value = std::strtol(text, &end, 10);
  return *end == '\0' && errno != ERANGE && value >= lo && value <= hi;
}

// Every rank's values, concatenated in rank order on rank 0 (empty elsewhere): the records a
// measurement fix buffers per rank, for rank 0 to write.
inline std::vector<double> gather_to_root(MPI_Comm world, const std::vector<double> &mine, int me, int nprocs)
{
  int count = static_cast<int>(mine.size());
  std::vector<int> counts(nprocs), displs(nprocs, 0);
  MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, world);
  int total = 0;
  if (me == 0)
    for (int p = 0; p < nprocs; ++p) {
      displs[p] = total;
      total += counts[p];
    }
  std::vector<double> all(me == 0 ? static_cast<size_t>(total) : 0);
  MPI_Gatherv(mine.data(), count, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE, 0, world);
  return all;
}

// "yes" or "no", else an error naming the keyword and the value.
inline bool parse_yes_no(LAMMPS_NS::LAMMPS *lmp, const std::string &who, const std::string &keyword, const char *value)
{
  if (std::string(value) == "yes") return true;
  if (std::string(value) == "no") return false;
  fail(lmp, who, keyword + " = '" + value + "' must be 'yes' or 'no'");
  return false;
}

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

// Whether the box along x is fixed (periodic or fixed walls) rather than shrink-wrapped (the box
// follows the particles, so positions in the input cannot be checked against it).
inline bool fixed_box_x(const LAMMPS_NS::Domain *domain)
{
  return domain->boundary[0][0] <= 1 && domain->boundary[0][1] <= 1;
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

// Registers a file the style writes / reads (run_files.h); an error when it is already in use.
inline void claim_output(LAMMPS_NS::LAMMPS *lmp, const std::string &who, const std::string &role,
                         const std::string &path)
{
  const std::string problem = tsg::run_files::claim_output(path, who, role);
  if (!problem.empty()) fail(lmp, who, problem);
}

inline void note_input(LAMMPS_NS::LAMMPS *lmp, const std::string &who, const std::string &role, const std::string &path)
{
  const std::string problem = tsg::run_files::note_input(path, who, role);
  if (!problem.empty()) fail(lmp, who, problem);
}

// How an output file is opened when the first run starts.
enum class Append {
  automatic,  // not given: append when the fix continues from a restart file, else start a new file
  yes,        // always append (the header of a non-empty file must match)
  no          // start a new file; refused when continuing from a restart and the file holds data
};

inline Append parse_append(LAMMPS_NS::LAMMPS *lmp, const std::string &who, const char *value)
{
  return parse_yes_no(lmp, who, "append", value) ? Append::yes : Append::no;
}

namespace detail {

inline std::vector<std::string> header_lines(const std::string &text, const std::vector<std::string> &free_prefixes)
{
  std::vector<std::string> lines;
  std::string::size_type start = 0;
  while (start < text.size() && text[start] == '#') {
    std::string::size_type end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    const std::string line = text.substr(start, end - start);
    bool free = false;
    for (const std::string &prefix : free_prefixes) free = free || line.compare(0, prefix.size(), prefix) == 0;
    if (!free) lines.push_back(line);
    start = end + 1;
  }
  return lines;
}

// What rank 0 found wrong ("" if nothing), for every rank.
inline std::string broadcast(LAMMPS_NS::LAMMPS *lmp, std::string text)
{
  int size = static_cast<int>(text.size());
  MPI_Bcast(&size, 1, MPI_INT, 0, lmp->world);
  text.resize(static_cast<std::string::size_type>(size));
  if (size > 0) MPI_Bcast(&text[0], size, MPI_CHAR, 0, lmp->world);
  return text;
}

}  // namespace detail

// Where a continued run's records start: a fix continuing from a restart file drops the records of
// its file whose time (column `time_column`, 1-based) lies after `restart_time`, which the run that
// wrote the restart file went on to write before it ended (a job killed at its time limit); the
// continued run writes them again.
struct Rollback {
  int time_column;
  double restart_time;
};

// Opens an output file on rank 0 (nullptr on the other ranks) and writes `header` into a new or
// empty file. Appending to a file that holds data requires its header to equal `header`, except lines
// starting with one of `free_prefixes` (names that may change without changing what the columns
// mean): records of two set-ups never mix in one file. When continuing, the records after the
// restart are dropped first (Rollback) and their number is reported. Errors on every rank.
inline FILE *open_output(LAMMPS_NS::LAMMPS *lmp, const std::string &who, const std::string &role,
                         const std::string &path, const std::string &header, Append mode, bool continuing,
                         const std::vector<std::string> &free_prefixes, const Rollback &rollback)
{
  const bool append = mode == Append::yes || (mode == Append::automatic && continuing);
  std::string problem;
  FILE *fp = nullptr;
  if (lmp->comm->me == 0) {
    // the header lines (leading '#' lines) of the file as it is, and its size; not the whole file
    std::string old;
    long size = 0;
    std::ifstream in(path, std::ios::binary);
    if (in) {
      for (std::string line; std::getline(in, line) && !line.empty() && line[0] == '#';) old += line + "\n";
      in.clear();
      in.seekg(0, std::ios::end);
      size = static_cast<long>(in.tellg());
    }
    if (size > 0 && mode == Append::no && continuing) {
      problem = "'append no' would overwrite the " + role + " '" + path + "' (" + std::to_string(size) +
                " bytes) that the run which wrote the restart file may have filled; continue it with 'append yes' "
                "(the default after read_restart) or give another file name";
    } else if (size > 0 && append) {
      const auto had = detail::header_lines(old, free_prefixes), want = detail::header_lines(header, free_prefixes);
      if (had != want) {
        std::size_t k = 0;
        while (k < had.size() && k < want.size() && had[k] == want[k]) ++k;
        problem = "cannot append to the " + role + " '" + path +
                  "': it was written for another set-up (its header has '" +
                  (k < had.size() ? had[k] : std::string("(no line)")) + "' where this fix writes '" +
                  (k < want.size() ? want[k] : std::string("(no line)")) +
                  "'); append only to a file of the same set-up, or give another file name";
      }
    }
    if (problem.empty() && size > 0 && append && continuing) {
      std::ifstream text(path, std::ios::binary);
      std::ostringstream rest;
      const std::size_t dropped = keep_records_until(text, rest, rollback.time_column, rollback.restart_time);
      text.close();
      if (dropped > 0) {
        std::ofstream rewritten(path + ".rollback", std::ios::binary | std::ios::trunc);
        rewritten << rest.str();
        rewritten.close();
        if (!rewritten || std::rename((path + ".rollback").c_str(), path.c_str()) != 0) {
          problem =
              "cannot drop the records after the restart from the " + role + " '" + path + "': " + std::strerror(errno);
        } else {
          const std::string note = who + ": dropped " + std::to_string(dropped) +
                                   " records after t = " + number(rollback.restart_time) + " s from the " + role +
                                   " '" + path +
                                   "' (written after the restart file by the run that wrote it; this run "
                                   "writes them again)";
          lmp->error->message(FLERR, note.c_str());
        }
      }
    }
    if (problem.empty()) {
      fp = std::fopen(path.c_str(), append ? "a" : "w");
      if (!fp) {
        problem = "cannot open the " + role + " '" + path + "' for writing: " + std::strerror(errno);
      } else if (!append || size == 0) {
        std::fputs(header.c_str(), fp);
        std::fflush(fp);
      }
    }
  }
  problem = detail::broadcast(lmp, problem);
  if (!problem.empty()) {
    if (fp) std::fclose(fp);
    fail(lmp, who, problem);
  }
  return fp;
}

}  // namespace tsg::measure

#endif
