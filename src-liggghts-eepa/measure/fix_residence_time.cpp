// fix residence/time: see fix_residence_time.h and docs/measurement.md.
//
// Per particle the state of physics/residence.h lives in a per-atom array that migrates with the
// particle (pack/unpack_exchange) and goes into restart files (pack/unpack_restart).
//
// Nothing may vanish without a record: the ledger (physics/ledger.h) keeps a copy of the state of
// each inside particle this rank owns, refreshed whenever that state changes (a zone-edge crossing:
// rare). On every reneighbouring step (the only steps on which particles are deleted, lost or
// migrated) and at every run set-up it is reconciled with the particles actually owned: those gone
// without a pack were deleted (delete_atoms, fix massflow/mesh ... delete_atoms yes, ...): record
// "deleted"; those packed but arrived on no rank were lost (left a non-periodic box with
// thermo_modify lost ignore): record "lost", written by the lowest rank holding it in transit.
// Records are buffered per rank and gathered to rank 0 every `flush` steps, at restart steps and
// at the end of every run; rank 0 sorts them by (exit time, id) and appends them to the file.
#include "fix_residence_time.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <tuple>
#include <unordered_set>
#include <vector>

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "group.h"
#include "neighbor.h"
#include "output.h"
#include "update.h"

#include "arguments.h"
#include "axial_partition.h"
#include "box_checks.h"
#include "errors.h"
#include "gather.h"
#include "numbers.h"
#include "output_files.h"
#include "zones_file.h"

using namespace LAMMPS_NS;
namespace res = tsg::residence;
using res::Slot;

using tsg::fail;
using tsg::number;

namespace {
constexpr int kRecordHead = 8;  // id entry exit residence reason type_time[3]
}  // namespace

FixResidenceTime::FixResidenceTime(LAMMPS *lmp, int narg, char **arg)
    : FixMeasureBase(lmp, narg, arg), plane_reference_(0), analysis_lo_(-INFINITY), analysis_hi_(INFINITY),
      has_analysis_(false), existing_given_(false), write_inside_(false), flush_every_(1000), flush_given_(false),
      first_setup_done_(false), cache_valid_(false), inside_now_(0)
{
  const char *zones_file = nullptr;
  const char *records_file = nullptr;
  bool has_periodic = false;
  for (int iarg = 3; iarg < narg;) {
    const std::string key = arg[iarg];
    auto need = [&](int n) {
      if (iarg + n >= narg) fail(lmp, who_, "keyword '" + key + "' needs " + std::to_string(n) + " value(s)");
    };
    auto real = [&](int k) {
      double value = 0;
      if (!tsg::parse_real(arg[iarg + k], value))
        fail(lmp, who_, key + " value '" + arg[iarg + k] + "' is not a finite number (m)");
      return value;
    };
    if (key == "zones") {
      need(1);
      zones_file = arg[iarg + 1];
      iarg += 2;
    } else if (key == "records") {
      need(1);
      records_file = arg[iarg + 1];
      iarg += 2;
    } else if (key == "inlet") {
      need(1);
      settings_.has_inlet = true;
      settings_.inlet = real(1);
      iarg += 2;
    } else if (key == "outlet") {
      need(1);
      settings_.has_outlet = true;
      settings_.outlet = real(1);
      iarg += 2;
    } else if (key == "periodic") {
      need(1);
      plane_reference_ = real(1);
      has_periodic = true;
      iarg += 2;
    } else if (key == "analysis") {
      need(2);
      analysis_lo_ = real(1);
      analysis_hi_ = real(2);
      has_analysis_ = true;
      if (!(analysis_hi_ > analysis_lo_))
        fail(lmp, who_, std::string("analysis XLO XHI = ") + arg[iarg + 1] + " " + arg[iarg + 2] + " needs XLO < XHI");
      iarg += 3;
    } else if (key == "existing") {
      need(1);
      if (strcmp(arg[iarg + 1], "tag") == 0)
        settings_.tag_existing = true;
      else if (strcmp(arg[iarg + 1], "wait") == 0)
        settings_.tag_existing = false;
      else
        fail(lmp, who_, std::string("existing = '") + arg[iarg + 1] + "' must be 'tag' or 'wait'");
      existing_given_ = true;
      iarg += 2;
    } else if (key == "inside") {
      need(1);
      write_inside_ = tsg::parse_yes_no(lmp, who_, "inside", arg[iarg + 1]);
      iarg += 2;
    } else if (key == "append") {
      need(1);
      append_ = tsg::parse_append(lmp, who_, arg[iarg + 1]);
      iarg += 2;
    } else if (key == "flush") {
      need(1);
      long n = 0;
      if (!tsg::parse_integer(arg[iarg + 1], 1, 2000000000L, n))
        fail(lmp, who_, std::string("flush = '") + arg[iarg + 1] + "' must be a positive integer (steps)");
      flush_every_ = static_cast<int>(n);
      flush_given_ = true;
      iarg += 2;
    } else {
      fail(lmp, who_,
           "unknown keyword '" + key +
               "' (allowed: zones, records, inlet, outlet, periodic, analysis, existing, inside, flush, append)");
    }
  }
  if (!zones_file) fail(lmp, who_, "missing 'zones FILE' (the zones file of the mesh generator)");
  if (!records_file) fail(lmp, who_, "missing 'records FILE' (where the records are written)");
  settings_.periodic = has_periodic;
  if (has_periodic && (settings_.has_inlet || settings_.has_outlet))
    fail(lmp, who_,
         "'periodic' cannot be combined with 'inlet' or 'outlet' (a pass runs from one "
         "crossing of the reference plane to the next)");
  if (settings_.has_inlet && settings_.has_outlet && !(settings_.outlet > settings_.inlet))
    fail(lmp, who_,
         "outlet " + number(settings_.outlet) + " must lie downstream (+x) of inlet " + number(settings_.inlet));
  if (!existing_given_) settings_.tag_existing = !has_periodic;

  zones_path_ = zones_file;
  records_path_ = records_file;
  zones_ = tsg::measure::read_zones(lmp, zones_path_, who_);
  tsg::claim_output(lmp, who_, "records file", records_path_);
  size_vector = 9;
  for (double &c : local_) c = 0;
  for (double &c : total_) c = 0;
  allocate_per_atom(Slot::zone0 + static_cast<int>(zones_.size()), kHotSlots);
  // the records file is opened when the first run starts: by then a restart file has told the fix
  // whether it continues an earlier measurement (restart() is called after the constructor)
}

void FixResidenceTime::open_records_file()
{
  std::string header = "# tsg-dem residence records v1\n";
  header += std::string("# fix ") + id + " residence/time, group " + group->names[igroup] + "\n";
  header += "# zones file: " + zones_path_ + " (" + std::to_string(zones_.size()) + " zones)\n";
  header += "# zones content hash: " + tsg::zones::hash_text(tsg::zones::content_hash(zones_)) + "\n";
  for (const auto &z : zones_)
    header += "# zone " + std::to_string(z.index) + " " + tsg::zones::type_name(z.type) + " " + number(z.x_start) +
              " " + number(z.x_end) + "\n";
  if (settings_.periodic)
    header += "# axis: periodic, passes between crossings of x = " + number(plane_reference_) + " (+x)\n";
  else
    header += std::string("# axis: open, inlet ") +
              (settings_.has_inlet ? number(settings_.inlet) : "none (tagged on insertion)") + ", outlet " +
              (settings_.has_outlet ? number(settings_.outlet) : "none") + "\n";
  header +=
      "# analysis domain: " +
      (has_analysis_ ? "[" + number(analysis_lo_) + ", " + number(analysis_hi_) + ")" : std::string("whole axis")) +
      "\n";
  header += "# times in s; residence_time = time inside the analysis domain between entry and exit; "
            "exit_reason: outlet pass deleted lost inside\n";
  header += "# columns: " + res::record_columns(static_cast<int>(zones_.size())) + "\n";
  // the fix id, group and the zones file's name may change between the parts of a measurement
  open_file("records file", records_path_, header, {"# fix ", "# zones file: "}, 3);  // by exit_time
}

void FixResidenceTime::init()
{
  if (!atom->tag_enable) fail(lmp, who_, "needs atom IDs (atom_modify id yes)");
  const double lo = domain->boxlo[0], hi = domain->boxhi[0];
  const bool x_periodic = domain->xperiodic;
  if (settings_.periodic && !x_periodic) fail(lmp, who_, "'periodic' needs a box periodic in x (boundary p ...)");
  if (!settings_.periodic && x_periodic)
    fail(lmp, who_, "the box is periodic in x; give 'periodic X' (the reference plane of a pass)");
  if (tsg::fixed_box_x(domain)) {
    try {
      tsg::zones::check_inside(zones_, lo, hi, "zones file '" + zones_path_ + "'");
    } catch (const std::invalid_argument &e) {
      fail(lmp, who_, e.what());
    }
    using tsg::check_plane_in_box;
    if (settings_.has_inlet) check_plane_in_box(lmp, who_, "inlet plane", settings_.inlet, false);
    if (settings_.has_outlet) check_plane_in_box(lmp, who_, "outlet plane", settings_.outlet, false);
    if (settings_.periodic) check_plane_in_box(lmp, who_, "periodic reference plane", plane_reference_, true);
    if (has_analysis_) {
      check_plane_in_box(lmp, who_, "analysis XLO plane", analysis_lo_, false);
      check_plane_in_box(lmp, who_, "analysis XHI plane", analysis_hi_, false);
    }
  }
  std::vector<tsg::axial::Plane> planes;
  if (settings_.has_inlet) planes.push_back({settings_.inlet, tsg::axial::kInlet});
  if (settings_.has_outlet) planes.push_back({settings_.outlet, tsg::axial::kOutlet});
  if (settings_.periodic) planes.push_back({plane_reference_, tsg::axial::kReference});
  tsg::axial::Partition partition;
  try {
    partition = tsg::axial::build_partition(zones_, settings_.periodic, lo, hi, analysis_lo_, analysis_hi_, planes);
  } catch (const std::invalid_argument &e) {
    fail(lmp, who_, e.what());
  }
  if (!partition_edges_.empty() && partition_edges_ != partition.edge)
    fail(lmp, who_,
         "the box along x changed since the fix was defined; the tracked zone cells would "
         "no longer match (unfix and define the fix again)");
  partition_edges_ = partition.edge;
  std::vector<tsg::zones::ZoneType> types;
  for (const auto &z : zones_) types.push_back(z.type);
  tracker_ = res::Tracker(partition, types, settings_);
  if (!flush_given_) flush_every_ = output->thermo_every > 0 ? output->thermo_every : 1000;
  comm->maxexchange_fix = std::max(comm->maxexchange_fix, nstate_ + 1);
  near_.configure(neighbor, atom);
  if (!file_opened_) open_records_file();
}

void FixResidenceTime::remember(int i)
{
  ledger_.remember(static_cast<long long>(state_[i][Slot::id]), state_[i], nstate_);
}

void FixResidenceTime::add_record(const res::Record &record)
{
  pending_.push_back(record);
  switch (record.reason) {
    case res::Reason::outlet:
      local_[kOutlet] += 1;
      local_[kSumResidence] += record.residence_time;
      break;
    case res::Reason::pass:
      local_[kPass] += 1;
      local_[kSumResidence] += record.residence_time;
      break;
    case res::Reason::deleted:
      local_[kDeleted] += 1;
      break;
    case res::Reason::lost:
      local_[kLost] += 1;
      break;
    case res::Reason::inside:
      local_[kRecordsInside] += 1;
      break;
  }
}

// Every particle of the group at set-up, on steps with a neighbour-list build and whenever the
// neighbour settings do not bound the moves between builds; otherwise only those near a cell edge.
void FixResidenceTime::track(double t0, double t1, bool at_setup)
{
  long starts = 0;
  near_.visit(at_setup || neighbor->ago == 0, atom, groupbit, period(), hot_,
              [&](int i) { track_one(i, t0, t1, at_setup, starts); });
  local_[kEntered] += starts;
}

void FixResidenceTime::track_one(int i, double t0, double t1, bool at_setup, long &starts)
{
  double u = tsg::measure::unwrapped_x_fast(atom->x[0], atom->image, i, period());
  const double *b = hot_[i];
  if (u >= b[0] && u < b[1]) return;  // the common case: still in the same cell, nothing changes
  double *s = state_[i];
  const int status = static_cast<int>(s[Slot::status]);
  if (status == res::kUnseen) {
    const bool existing = at_setup && !first_setup_done_;
    if (tracker_.first_sight(s, atom->tag[i], unwrapped_x(i, NAN), t1, existing) == res::kInside) {
      ++starts;
      remember(i);
    }
    refresh(i);
    return;
  }
  const bool was_inside = status == res::kInside;
  // the cell edge is never more than a few steps away: it anchors the image-flag wrap-around
  u = unwrapped_x(i, std::isfinite(s[Slot::lo]) ? s[Slot::lo] : s[Slot::hi]);
  const double u0 = u - atom->v[i][0] * (t1 - t0);  // where it was at t0 (exact for constant velocity)
  auto sink = [this](const res::Record &record) {
    add_record(record);
  };
  if (tracker_.advance(s, u0, u, t0, t1, sink, starts)) {
    if (s[Slot::status] == res::kInside)
      remember(i);
    else if (was_inside)
      ledger_.forget(static_cast<long long>(s[Slot::id]));
    refresh(i);
  }
}

// Particle ids can only change between runs (delete_atoms ... compress yes, reset_atom_ids).
void FixResidenceTime::check_ids()
{
  const int *tag = atom->tag;
  for (int i = 0; i < atom->nlocal; ++i) {
    if (!(atom->mask[i] & groupbit)) continue;
    const double *s = state_[i];
    if (s[Slot::status] != res::kUnseen && s[Slot::id] != tag[i])
      tsg::fail_one(lmp, who_,
                    "particle id changed from " + number(s[Slot::id]) + " to " + std::to_string(tag[i]) +
                        " (ids renumbered, e.g. by delete_atoms ... compress yes); residence tracking "
                        "needs stable ids: use compress no");
  }
}

void FixResidenceTime::reconcile(double t)
{
  const int nlocal = atom->nlocal;
  const int *mask = atom->mask;
  // 1. particles gone from this rank without leaving through pack_exchange: deleted
  long owned_inside = 0;
  for (int i = 0; i < nlocal; ++i) owned_inside += hot_[i][kHotInside] != 0;  // only group members are ever inside
  if (owned_inside != ledger_.resident()) {
    std::unordered_set<long long> owned;
    owned.reserve(static_cast<size_t>(owned_inside) * 2 + 1);
    for (int i = 0; i < nlocal; ++i)
      if ((mask[i] & groupbit) && state_[i][Slot::status] == res::kInside)
        owned.insert(static_cast<long long>(state_[i][Slot::id]));
    for (const auto &gone : ledger_.take_deleted(owned))
      add_record(tracker_.close(gone.second.data(), t, res::Reason::deleted));
    // owned inside particles the ledger does not hold as resident: after read_restart (the ledger is
    // not part of the restart file) — take them from the particles
    for (int i = 0; i < nlocal; ++i)
      if ((mask[i] & groupbit) && state_[i][Slot::status] == res::kInside &&
          !ledger_.holds(static_cast<long long>(state_[i][Slot::id])))
        remember(i);
  }

  // 2. packed for another rank but arrived nowhere: lost
  long gap_local = ledger_.packs_minus_arrivals(), gap = 0;
  MPI_Allreduce(&gap_local, &gap, 1, MPI_LONG, MPI_SUM, world);
  if (gap != 0) {
    std::vector<long long> mine = ledger_.transit_ids();
    int count = static_cast<int>(mine.size());
    std::vector<int> counts(comm->nprocs), displs(comm->nprocs, 0);
    MPI_Allgather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, world);
    int total = 0;
    for (int p = 0; p < comm->nprocs; ++p) {
      displs[p] = total;
      total += counts[p];
    }
    std::vector<long long> all(static_cast<size_t>(total));
    MPI_Allgatherv(mine.data(), count, MPI_LONG_LONG, all.data(), counts.data(), displs.data(), MPI_LONG_LONG, world);
    std::sort(all.begin(), all.end());
    all.erase(std::unique(all.begin(), all.end()), all.end());
    std::vector<int> claim(all.size()), result(all.size());
    for (size_t k = 0; k < all.size(); ++k) claim[k] = ledger_.claim(all[k], comm->me, comm->nprocs);
    if (!all.empty()) MPI_Allreduce(claim.data(), result.data(), static_cast<int>(all.size()), MPI_INT, MPI_MIN, world);
    for (size_t k = 0; k < all.size(); ++k)
      if (result[k] == comm->me) add_record(tracker_.close(ledger_.state(all[k])->data(), t, res::Reason::lost));
  }
  ledger_.end_exchange();
}

void FixResidenceTime::setup(int)
{
  clock_.resume(update);
  const double t = now();
  cache_valid_ = false;
  check_ids();
  reconcile(t);       // deletions between runs, losses during set-up, ledger after a restart
  track(t, t, true);  // first sight of existing particles; moves between runs are instantaneous
  first_setup_done_ = true;
}

void FixResidenceTime::end_of_step()
{
  const double t1 = now();
  const double t0 = t1 - update->dt;
  cache_valid_ = false;
  if (neighbor->ago == 0) reconcile(t1);
  track(t0, t1, false);
  const bigint step = update->ntimestep;
  if (step % flush_every_ == 0 || output->restart_requested(step) || step == update->laststep) flush();
}

void FixResidenceTime::post_run()
{
  cache_valid_ = false;
  if (write_inside_) {
    const double t = now();
    for (int i = 0; i < atom->nlocal; ++i)
      if ((atom->mask[i] & groupbit) && state_[i][Slot::status] == res::kInside)
        add_record(tracker_.close(state_[i], t, res::Reason::inside));
  }
  flush();
}

void FixResidenceTime::flush()
{
  const int nzones = static_cast<int>(zones_.size());
  const int width = kRecordHead + nzones;
  std::vector<double> mine;
  mine.reserve(pending_.size() * width);
  for (const auto &r : pending_) {
    mine.insert(mine.end(), {r.id, r.entry_time, r.exit_time, r.residence_time, static_cast<double>(r.reason),
                             r.type_time[0], r.type_time[1], r.type_time[2]});
    mine.insert(mine.end(), r.zone_time.begin(), r.zone_time.end());
  }
  pending_.clear();
  const std::vector<double> all = tsg::gather_to_root(world, mine, comm->me, comm->nprocs);
  if (comm->me == 0 && !all.empty()) {
    const size_t n = all.size() / static_cast<size_t>(width);
    std::vector<res::Record> records(n);
    for (size_t k = 0; k < n; ++k) {
      const double *row = &all[k * width];
      res::Record &r = records[k];
      r.id = row[0];
      r.entry_time = row[1];
      r.exit_time = row[2];
      r.residence_time = row[3];
      r.reason = static_cast<res::Reason>(static_cast<int>(row[4]));
      for (int c = 0; c < 3; ++c) r.type_time[c] = row[5 + c];
      r.zone_time.assign(row + kRecordHead, row + width);
    }
    std::sort(records.begin(), records.end(), [](const res::Record &a, const res::Record &b) {
      return std::make_tuple(a.exit_time, a.id, static_cast<int>(a.reason)) <
             std::make_tuple(b.exit_time, b.id, static_cast<int>(b.reason));
    });
    std::string text;
    for (const auto &r : records) text += res::format_record(r) + "\n";
    fwrite(text.data(), 1, text.size(), fp_);
  }
  if (comm->me == 0 && fp_) fflush(fp_);
  sync_counters();
}

void FixResidenceTime::sync_counters()
{
  double sum[kCounters];
  MPI_Allreduce(local_, sum, kCounters, MPI_DOUBLE, MPI_SUM, world);
  for (int c = 0; c < kCounters; ++c) {
    total_[c] += sum[c];
    local_[c] = 0;
  }
}

int FixResidenceTime::modify_param(int narg, char **arg)
{
  if (strcmp(arg[0], "inside") == 0) {
    if (narg < 2) fail(lmp, std::string("fix_modify ") + id, "inside needs yes or no");
    write_inside_ = tsg::parse_yes_no(lmp, std::string("fix_modify ") + id, "inside", arg[1]);
    return 2;
  }
  return 0;
}

double FixResidenceTime::compute_vector(int n)
{
  if (!cache_valid_) {  // collective: thermo and variables evaluate fix values on every rank
    sync_counters();
    double inside = 0;
    for (int i = 0; i < atom->nlocal; ++i) inside += hot_[i][kHotInside];
    MPI_Allreduce(&inside, &inside_now_, 1, MPI_DOUBLE, MPI_SUM, world);
    cache_valid_ = true;
  }
  const double complete = total_[kOutlet] + total_[kPass];
  switch (n) {
    case 0:
      return complete + total_[kDeleted] + total_[kLost];
    case 1:
      return complete;
    case 2:
      return complete > 0 ? total_[kSumResidence] / complete : 0.0;
    case 3:
      return total_[kEntered];
    case 4:
      return inside_now_;
    case 5:
      return total_[kOutlet];
    case 6:
      return total_[kPass];
    case 7:
      return total_[kDeleted];
    default:
      return total_[kLost];
  }
}

// ---- the ledger follows inside particles from rank to rank ----------------------------------------

void FixResidenceTime::leaving(int i)
{
  if (state_[i][Slot::status] == res::kInside) ledger_.packed(static_cast<long long>(state_[i][Slot::id]));
}

void FixResidenceTime::arrived(int i)
{
  if (state_[i][Slot::status] != res::kInside) return;
  ledger_.arrived();
  remember(i);
}

// global state: a format mark, the counters (synced at every restart step, see end_of_step), whether
// the particles present at the start have been seen, the clock, and the identity of the zones
// (zones.h), so that a restart with other zones is refused instead of mixing two sets of cells.
namespace {
constexpr double kRestartMark = -20261201.0;  // not a counter value: marks this layout
constexpr int kRestartCounters = 7;           // FixResidenceTime::kCounters (checked below)
enum RestartEntry {
  kMark,
  kCountersStart,
  kFirstSetupDone = kCountersStart + kRestartCounters,
  kClockTime,
  kClockStep,
  kZonesIdentity
};
}  // namespace

void FixResidenceTime::write_restart(FILE *fp)
{
  static_assert(kCounters == kRestartCounters, "restart layout: counter count");
  std::vector<double> list(kZonesIdentity);
  list[kMark] = kRestartMark;
  for (int c = 0; c < kCounters; ++c) list[kCountersStart + c] = total_[c];
  list[kFirstSetupDone] = first_setup_done_ ? 1.0 : 0.0;
  clock_.save(update, &list[kClockTime], &list[kClockStep]);
  const std::vector<double> identity = tsg::zones::identity(zones_);
  list.insert(list.end(), identity.begin(), identity.end());
  write_global(fp, list);
}

void FixResidenceTime::restart(char *buf)
{
  const double *list = reinterpret_cast<const double *>(buf);
  if (list[kMark] != kRestartMark)
    fail(lmp, who_,
         "the restart file was written by an earlier version of this fix, which did not keep the "
         "identity of its zones; continue from a restart file written by this version");
  const std::string difference = tsg::zones::identity_difference(list + kZonesIdentity, zones_);
  if (!difference.empty())
    fail(lmp, who_,
         "the zones file '" + zones_path_ +
             "' does not describe the zones the restart file was "
             "written with: " +
             difference +
             "; a residence measurement cannot mix two sets of zone cells: "
             "continue with the zones file of the earlier run, or start a new measurement (a new fix ID "
             "and records file)");
  for (int c = 0; c < kCounters; ++c) total_[c] = list[kCountersStart + c];
  first_setup_done_ = list[kFirstSetupDone] != 0;
  clock_.load(list[kClockTime], list[kClockStep]);
  continuing_ = true;
}

double FixResidenceTime::memory_usage()
{
  return FixMeasureBase::memory_usage() + static_cast<double>(ledger_.size()) * (nstate_ * sizeof(double) + 64);
}
