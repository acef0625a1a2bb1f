// Residence-time bookkeeping of one particle along the granulator axis, dependency-free.
//
// The state of a particle is a flat array of doubles (so that LIGGGHTS can keep it in a per-atom
// array, migrate it between ranks and write it to restart files); Slot names the entries.
// Times are accumulated lazily: only when the particle crosses a cell edge (axial_partition.h) is
// the time since it entered its cell added to that cell's zone. Between crossings the state does not
// change at all, so a copy taken at the last crossing is enough to close a record later (particle
// deleted or lost), and the per-step work is two comparisons.
//
// Open axis (non-periodic):
//   entry  = first sight (insertion, or presence when the tracking starts) at x >= inlet, or a
//            crossing of the inlet plane towards +x; without an inlet plane every particle is tagged
//            on first sight;
//   exit   = crossing of the outlet plane towards +x (reason "outlet"); afterwards the particle is
//            "done" and never tagged again.
// Periodic axis:
//   a pass runs from one crossing of the reference plane (any periodic image of it) towards +x to
//   the next one reached further downstream: the pass "level" counts net crossings (backflow across
//   the plane counts -1), a pass ends the first time the level reaches +1; the record has reason
//   "pass" and the next pass starts at the same instant.
// Analysis domain [analysis_lo, analysis_hi): time outside it (buffer zones) counts neither to any
// zone nor to the residence time, which is therefore exit - entry minus time spent in the buffers.
#ifndef TSG_RESIDENCE_H
#define TSG_RESIDENCE_H

#include <cstdio>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "axial_partition.h"
#include "zones.h"

namespace tsg::residence {

enum Status : int { kUnseen = 0, kWaiting = 1, kInside = 2, kDone = 3 };

enum class Reason { outlet = 0, pass = 1, deleted = 2, lost = 3, inside = 4 };

// The records file's exit_reason names, indexed by Reason.
constexpr const char *kReasonNames[] = {"outlet", "pass", "deleted", "lost", "inside"};
static_assert(sizeof kReasonNames / sizeof kReasonNames[0] == static_cast<int>(Reason::inside) + 1,
              "a name per Reason");

inline const char *reason_name(Reason reason) { return kReasonNames[static_cast<int>(reason)]; }

// Entries of the per-particle state; zone times follow from zone0 on. lo/hi: the particle's cell in
// unwrapped coordinates, so that the per-step check is two comparisons (an empty interval for a
// particle not seen yet, the whole line for one that is done). The position at the previous step
// is not stored: the caller passes it (LIGGGHTS: x - v dt, exact for constant velocity).
struct Slot {
  enum : int {
    status = 0,      // Status
    lo = 1,          // lower edge of the current cell (unwrapped), m
    hi = 2,          // upper edge of the current cell (unwrapped), m
    cell = 3,        // cell of the partition
    period = 4,      // periodic image of that cell
    id = 5,          // particle id when first seen (to detect renumbering)
    level = 6,       // periodic: net reference-plane crossings in the current pass
    entry_time = 7,  // s
    cell_time = 8,   // time the particle entered its current cell, s
    t_analysis = 9,  // time spent inside the analysis domain so far, s
    zone0 = 10       // time spent in zone 1, 2, ... (inside the analysis domain), s
  };
};

struct Record {
  double id = 0, entry_time = 0, exit_time = 0, residence_time = 0;
  Reason reason = Reason::outlet;
  double type_time[zones::kZoneTypes] = {0, 0, 0};
  std::vector<double> zone_time;
};

struct Settings {
  bool periodic = false;
  bool has_inlet = false;
  double inlet = 0;
  bool has_outlet = false;
  double outlet = 0;
  bool tag_existing = true;  // particles present when tracking starts: tagged at once, or waiting
};

class Tracker {
public:
  Tracker() = default;
  Tracker(axial::Partition partition, std::vector<zones::ZoneType> types, Settings settings)
      : partition_(std::move(partition)), types_(std::move(types)), settings_(settings)
  {}

  int zones() const { return static_cast<int>(types_.size()); }
  int state_size() const { return Slot::zone0 + zones(); }
  const axial::Partition &partition() const { return partition_; }
  const Settings &settings() const { return settings_; }

  // First sight of a particle at unwrapped coordinate u, time t. `existing`: it was there when the
  // tracking started (rather than inserted later). Returns the new status.
  int first_sight(double *s, double id, double u, double t, bool existing) const
  {
    int cell = 0;
    long per = 0;
    axial::locate(partition_, u, cell, per);
    for (int k = 0; k < state_size(); ++k) s[k] = 0;
    s[Slot::id] = id;
    s[Slot::cell] = cell;
    s[Slot::period] = static_cast<double>(per);
    int status = kWaiting;
    if (settings_.periodic) {
      if (existing && settings_.tag_existing) status = kInside;
    } else if (settings_.has_outlet && u >= settings_.outlet) {
      status = kDone;  // already downstream of the outlet: never entered
    } else if (existing && !settings_.tag_existing) {
      status = kWaiting;
    } else if (!settings_.has_inlet || u >= settings_.inlet) {
      status = kInside;
    }
    s[Slot::status] = status;
    if (status == kInside) start(s, t);
    set_bounds(s, cell, per);
    return status;
  }

  // True when u is still in the particle's cell (nothing to do but remember u).
  static bool stays(const double *s, double u) { return u >= s[Slot::lo] && u < s[Slot::hi]; }

  // One step: the particle moved from u0 (time t0) to u (time t1), in a straight line as far as the
  // crossing times are concerned. Records (outlet, pass) go to sink(const Record&); `starts` is
  // incremented for every entry (tagging or new pass). Returns true when the state changed.
  template <class Sink>
  bool advance(double *s, double u0, double u, double t0, double t1, Sink &&sink, long &starts) const
  {
    if (stays(s, u) || s[Slot::status] == kDone) return false;
    int cell = static_cast<int>(s[Slot::cell]);
    long per = static_cast<long>(s[Slot::period]);
    axial::walk(partition_, cell, per, u0, u, t0, t1, [&](int edge, int direction, double t, int from, int) {
      if (s[Slot::status] == kInside) {
        add_time(s, from, t - s[Slot::cell_time]);
        s[Slot::cell_time] = t;
      }
      const unsigned flags = partition_.flags[edge];
      if (!flags) return;
      if (!settings_.periodic) {
        if ((flags & axial::kInlet) && direction > 0 && s[Slot::status] == kWaiting) {
          start(s, t);
          ++starts;
        }
        if ((flags & axial::kOutlet) && direction > 0 && s[Slot::status] == kInside) {
          sink(close(s, t, Reason::outlet));
          s[Slot::status] = kDone;
        }
      } else if (flags & axial::kReference) {
        if (s[Slot::status] == kWaiting) {
          if (direction > 0) {
            start(s, t);
            ++starts;
          }
        } else if (s[Slot::status] == kInside) {
          s[Slot::level] += direction;
          if (s[Slot::level] >= 1) {
            sink(close(s, t, Reason::pass));
            start(s, t);
            ++starts;
          }
        }
      }
    });
    s[Slot::cell] = cell;
    s[Slot::period] = static_cast<double>(per);
    set_bounds(s, cell, per);
    return true;
  }

  // The record of an inside particle leaving (or observed) at time t; the state is not changed.
  Record close(const double *s, double t, Reason reason) const
  {
    Record r;
    r.id = s[Slot::id];
    r.entry_time = s[Slot::entry_time];
    r.exit_time = t;
    r.reason = reason;
    r.zone_time.assign(s + Slot::zone0, s + Slot::zone0 + zones());
    double in_analysis = s[Slot::t_analysis];
    const int cell = static_cast<int>(s[Slot::cell]);
    if (partition_.analysis[cell]) {
      const double dt = t - s[Slot::cell_time];
      in_analysis += dt;
      if (partition_.zone[cell] >= 0) r.zone_time[partition_.zone[cell]] += dt;
    }
    r.residence_time = in_analysis;
    for (int z = 0; z < zones(); ++z) r.type_time[static_cast<int>(types_[z])] += r.zone_time[z];
    return r;
  }

private:
  void set_bounds(double *s, int cell, long per) const
  {
    if (s[Slot::status] == kDone) {  // never looked at again
      s[Slot::lo] = -std::numeric_limits<double>::infinity();
      s[Slot::hi] = std::numeric_limits<double>::infinity();
    } else {
      s[Slot::lo] = partition_.lower(cell, per);
      s[Slot::hi] = partition_.upper(cell, per);
    }
  }

  void start(double *s, double t) const
  {
    s[Slot::status] = kInside;
    s[Slot::entry_time] = t;
    s[Slot::cell_time] = t;
    s[Slot::t_analysis] = 0;
    s[Slot::level] = 0;
    for (int z = 0; z < zones(); ++z) s[Slot::zone0 + z] = 0;
  }

  void add_time(double *s, int cell, double dt) const
  {
    if (!partition_.analysis[cell]) return;
    s[Slot::t_analysis] += dt;
    if (partition_.zone[cell] >= 0) s[Slot::zone0 + partition_.zone[cell]] += dt;
  }

  axial::Partition partition_;
  std::vector<zones::ZoneType> types_;
  Settings settings_;
};

// One line of the records file (no newline):
//   id entry_time exit_time residence_time exit_reason time_conveying time_kneading time_chopping
//   time_zone_1 ... time_zone_N
inline std::string format_record(const Record &r)
{
  char buffer[64];
  std::string line;
  std::snprintf(buffer, sizeof buffer, "%.0f", r.id);
  line += buffer;
  for (double v : {r.entry_time, r.exit_time, r.residence_time}) {
    std::snprintf(buffer, sizeof buffer, " %.15g", v);
    line += buffer;
  }
  line += ' ';
  line += reason_name(r.reason);
  for (double v : r.type_time) {
    std::snprintf(buffer, sizeof buffer, " %.15g", v);
    line += buffer;
  }
  for (double v : r.zone_time) {
    std::snprintf(buffer, sizeof buffer, " %.15g", v);
    line += buffer;
  }
  return line;
}

// Column names of the records file, for its "# columns:" header line.
inline std::string record_columns(int nzones)
{
  std::string line = "id entry_time exit_time residence_time exit_reason";
  for (const char *type : zones::kZoneTypeNames) line += std::string(" time_") + type;
  for (int z = 1; z <= nzones; ++z) line += " time_zone_" + std::to_string(z);
  return line;
}

}  // namespace tsg::residence

#endif
