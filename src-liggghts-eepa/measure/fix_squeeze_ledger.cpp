// fix squeeze/ledger: see fix_squeeze_ledger.h and docs/stability.md.
//
// Per particle the squeeze track of physics/squeeze.h, whether its centre is behind a wall, whether
// the fix has seen it and its kinetic energy at the last step live in a per-atom array that migrates
// with the particle and goes into restart files. The wall contacts come from the wall fix
// (tsg::WallContactSource); each particle's deepest pair contact from the granular pair style's own
// force pass (tsg::PairDepthSink, patches/pair-gran-base-h.patch; newton off: a pair with a ghost
// partner is also held by the partner's owner, so only local particles are updated).
#include "fix_squeeze_ledger.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <tuple>

#include "atom.h"
#include "comm.h"
#include "error.h"
#include "fix_gravity.h"
#include "force.h"
#include "group.h"
#include "modify.h"
#include "output.h"
#include "update.h"

#include "errors.h"
#include "gather.h"
#include "numbers.h"
#include "output_files.h"

using namespace LAMMPS_NS;
namespace sq = tsg::squeeze;
using tsg::fail;
using tsg::number;

namespace {
constexpr int kTrackSize = static_cast<int>(sizeof(sq::Track) / sizeof(double));
static_assert(sizeof(sq::Track) == kTrackSize * sizeof(double), "Track holds doubles only");
enum Slot { kCrossed = kTrackSize, kSeen, kKineticPrevious, kSlots };
// a record: t_start t_end id x y z radius peak_wall peak_pair walls kind with_particles start_speed
// release_speed number
constexpr int kRecordWidth = 15;
constexpr int kCrossingWidth = 6;  // id wall x y z time
constexpr int kCrossingsNamed = 10;

sq::Track load_track(const double *s)
{
  sq::Track t;
  std::memcpy(static_cast<void *>(&t), s, sizeof t);  // Track: doubles only (static_assert above)
  return t;
}
}  // namespace

FixSqueezeLedger::FixSqueezeLedger(LAMMPS *lmp, int narg, char **arg) : FixMeasureBase(lmp, narg, arg)
{
  bool end_given = false;
  for (int iarg = 3; iarg < narg;) {
    const std::string key = arg[iarg];
    if (iarg + 1 >= narg) fail(lmp, who_, "keyword '" + key + "' needs a value");
    const char *value = arg[iarg + 1];
    auto real = [&](const char *allowed, bool ok(double)) {
      double v = 0;
      if (!tsg::parse_real(value, v) || !ok(v)) fail(lmp, who_, key + " = '" + value + "' is not allowed: " + allowed);
      return v;
    };
    auto integer = [&](long lo, const char *allowed) {
      long n = 0;
      if (!tsg::parse_integer(value, lo, 2000000000L, n))
        fail(lmp, who_, key + " = '" + value + "' is not allowed: " + allowed);
      return n;
    };
    if (key == "walls") {
      wall_fix_id_ = value;
    } else if (key == "records") {
      records_path_ = value;
    } else if (key == "start") {
      thresholds_.start = real("a number in (0, 10) (overlap / radius)", [](double v) { return v > 0 && v < 10; });
    } else if (key == "end") {
      thresholds_.end = real("a number in (0, start] (overlap / radius)", [](double v) { return v > 0 && v < 10; });
      end_given = true;
    } else if (key == "release_steps") {
      thresholds_.release_steps = static_cast<int>(integer(0, "an integer >= 0 (steps)"));
    } else if (key == "max_energy_excess") {
      max_energy_excess_ = real("a number > 0 (a fraction of the energy turnover; leave the keyword out for no limit)",
                                [](double v) { return v > 0; });
    } else if (key == "max_crossed") {
      max_crossed_ = integer(0, "an integer >= 0 (particle centres behind a wall)");
    } else if (key == "flush") {
      flush_every_ = static_cast<int>(integer(1, "a positive integer (steps)"));
    } else if (key == "append") {
      append_ = tsg::parse_append(lmp, who_, value);
    } else {
      fail(lmp, who_,
           "unknown keyword '" + key +
               "' (allowed: walls, records, start, end, release_steps, max_energy_excess, max_crossed, flush, append)");
    }
    iarg += 2;
  }
  if (!end_given) thresholds_.end = 0.5 * thresholds_.start;
  if (!(thresholds_.end <= thresholds_.start))
    fail(lmp, who_, "end = " + number(thresholds_.end) + " must not exceed start = " + number(thresholds_.start));
  if (wall_fix_id_.empty()) fail(lmp, who_, "missing 'walls WALL-FIX' (the ID of the wall fix, e.g. walls)");
  if (records_path_.empty()) fail(lmp, who_, "missing 'records FILE' (where the squeeze events are written)");
  tsg::claim_output(lmp, who_, "records file", records_path_);
  size_vector = 13;
  allocate_per_atom(kSlots, 1);
}

std::string FixSqueezeLedger::state_size_hint() const
{
  return "a squeeze track of " + std::to_string(kTrackSize) + " values and 3 more";
}

void FixSqueezeLedger::init()
{
  if (!atom->tag_enable) fail(lmp, who_, "needs atom IDs (atom_modify id yes)");
  if (!atom->radius_flag || !atom->rmass_flag)
    fail(lmp, who_, "needs per-particle radius and mass (atom_style sphere)");
  if (force->newton_pair) fail(lmp, who_, "needs newton off (each rank sees every contact of its particles)");
  const int ifix = modify->find_fix(wall_fix_id_.c_str());
  if (ifix < 0) fail(lmp, who_, "walls = '" + wall_fix_id_ + "': no fix with this ID");
  walls_ = dynamic_cast<tsg::WallContactSource *>(modify->fix[ifix]);
  if (!walls_)
    fail(lmp, who_,
         "walls = '" + wall_fix_id_ + "' (style " + modify->fix[ifix]->style +
             ") does not report its contacts per particle (allowed: fix wall/gran/corotating)");
  if (ifix > modify->find_fix(id)) fail(lmp, who_, "must be defined after its wall fix '" + wall_fix_id_ + "'");
  if (walls_->wall_count() > 32) fail(lmp, who_, "at most 32 walls (one bit each per particle)");
  wall_names_.clear();
  for (int k = 0; k < walls_->wall_count(); ++k) wall_names_.push_back(walls_->wall_name(k));
  gravity_[0] = gravity_[1] = gravity_[2] = 0;
  for (int k = 0; k < modify->nfix; ++k)
    if (std::strcmp(modify->fix[k]->style, "gravity") == 0) {
      double g[3];
      static_cast<FixGravity *>(modify->fix[k])->get_gravity(g);
      for (int d = 0; d < 3; ++d) gravity_[d] += g[d];
    }
  if (flush_every_ == 0) flush_every_ = output->thermo_every > 0 ? output->thermo_every : 1000;
  comm->maxexchange_fix = std::max(comm->maxexchange_fix, nstate_ + 1);
  if (!file_opened_) {
    std::string header = "# tsg-dem squeeze records v1\n";
    header += std::string("# fix ") + id + " squeeze/ledger, group " + group->names[igroup] + ", walls fix " +
              wall_fix_id_ + "\n";
    header += "# a squeeze opens at overlap/radius > " + number(thresholds_.start) +
              " (wall or pair) and closes below " + number(thresholds_.end) + "; release speed: the largest in " +
              std::to_string(thresholds_.release_steps) + " steps after\n";
    header += "# walls (bit k of the mask):";
    for (size_t k = 0; k < wall_names_.size(); ++k) header += " " + std::to_string(k) + "=" + wall_names_[k];
    header += "\n# kind: 0 two_walls, 1 wall_and_particles, 2 wall_alone, 3 particles; times s, speeds m/s, m\n";
    header += "# columns: start_time end_time id x y z radius peak_wall_ratio peak_pair_ratio walls kind "
              "with_particles start_speed release_speed event_number\n";
    open_file("records file", records_path_, header, {"# fix "}, 2);
  }
}

int FixSqueezeLedger::setmask() { return FixMeasureBase::setmask() | FixConst::PRE_FORCE; }

// Before the forces of every step: no pair depth recorded yet.
void FixSqueezeLedger::pre_force(int)
{
  pair_ratio_.assign(atom->nlocal, -1.0);
  pair_depths_recorded_ = false;
}

void FixSqueezeLedger::setup_pre_force(int vflag) { pre_force(vflag); }

double *FixSqueezeLedger::pair_depths_recorded_by_pair_style()
{
  if (pair_ratio_.size() != static_cast<size_t>(atom->nlocal)) pre_force(0);
  pair_depths_recorded_ = true;
  return pair_ratio_.data();
}

// Energy the particles hold at set-up, taken as given (a run's start, or what commands between runs
// changed); every particle present is seen.
void FixSqueezeLedger::setup(int)
{
  // a ledger that starts on a restart file written without it: LIGGGHTS restarts its time at 0, so
  // the clock starts at step x dt (the cases' time step is constant)
  if (!first_setup_done_ && !continuing_)
    clock_.load(static_cast<double>(update->ntimestep) * update->dt, static_cast<double>(update->ntimestep));
  // the pair style's pass of set-up has recorded the pair depths, or there are no particle contacts
  if (force->pair && !pair_depths_recorded_)
    fail(lmp, who_,
         std::string("pair style '") + force->pair_style +
             "' does not record each particle's deepest particle-particle overlap (allowed: pair_style gran, "
             "with its force computation on)");
  clock_.resume(update);
  double kinetic = 0, lift = 0;
  const double g = std::sqrt(gravity_[0] * gravity_[0] + gravity_[1] * gravity_[1] + gravity_[2] * gravity_[2]);
  for (int i = 0; i < atom->nlocal; ++i) {
    if (!(atom->mask[i] & groupbit)) continue;
    const double *v = atom->v[i];
    const double ke = 0.5 * atom->rmass[i] * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    state_[i][kSeen] = 1;
    state_[i][kKineticPrevious] = ke;
    kinetic += ke;
    lift += atom->rmass[i] * g * atom->radius[i];
  }
  double local[2] = {kinetic, lift}, sum[2];
  MPI_Allreduce(local, sum, 2, MPI_DOUBLE, MPI_SUM, world);
  budget_ += sum[0] - kinetic_;
  scale_ += std::fabs(sum[0] - kinetic_);
  kinetic_ = sum[0];
  lift_ = sum[1];
  first_setup_done_ = true;
}

void FixSqueezeLedger::end_of_step()
{
  const double t = now();
  const double dt = update->dt;
  const int nlocal = atom->nlocal;
  const int *mask = atom->mask;
  double **v = atom->v, **f = atom->f, **x = atom->x;
  const double *rmass = atom->rmass, *radius = atom->radius;
  const double *wall_ratio = walls_->step_overlap_ratio();
  const unsigned *touched = walls_->step_walls_touched();
  const unsigned *crossed = walls_->step_walls_crossed();
  const double g = std::sqrt(gravity_[0] * gravity_[0] + gravity_[1] * gravity_[1] + gravity_[2] * gravity_[2]);

  enum {
    kKinetic,
    kKineticSeen,
    kKineticNew,
    kGravityWork,
    kClosed,
    kPressed,
    kDistinct,
    kCrossings,
    kReleased,
    kLift,
    kSums
  };
  double sums[kSums] = {0};
  enum { kPeakWall, kPeakPair, kRelease, kMaxima };
  double maxima[kMaxima] = {0};
  std::vector<double> new_crossings;
  for (int i = 0; i < nlocal; ++i) {
    if (!(mask[i] & groupbit)) continue;
    double *s = state_[i];
    const double speed2 = v[i][0] * v[i][0] + v[i][1] * v[i][1] + v[i][2] * v[i][2];
    const double ke = 0.5 * rmass[i] * speed2;
    sums[kKinetic] += ke;
    sums[s[kSeen] != 0 ? kKineticSeen : kKineticNew] += s[kSeen] != 0 ? s[kKineticPrevious] : ke;
    s[kSeen] = 1;
    s[kKineticPrevious] = ke;
    // gravity over the step: m g · (x1 − x0), x1 − x0 = dt v(t + dt/2) in velocity Verlet
    double work = 0;
    for (int d = 0; d < 3; ++d) work += gravity_[d] * (rmass[i] * v[i][d] - 0.5 * dt * f[i][d]);
    sums[kGravityWork] += dt * work;
    sums[kLift] += rmass[i] * g * radius[i];

    if (s[0] == sq::kFree && !(std::max(wall_ratio[i], pair_ratio_[i]) > thresholds_.start) && crossed[i] == 0 &&
        s[kCrossed] == 0)
      continue;  // the common case: no squeeze open, none opening, no crossing
    sq::Sample sample;
    sample.wall_ratio = wall_ratio[i];
    sample.walls = touched[i];
    sample.pair_ratio = std::max(pair_ratio_[i], 0.0);
    sample.with_particles = pair_ratio_[i] >= 0;
    sample.speed = std::sqrt(speed2);
    std::copy(x[i], x[i] + 3, sample.position);
    sq::Track track = load_track(s);
    const double events_before = track.events;
    sq::Event event;
    if (sq::advance(track, sample, thresholds_, t, event)) {
      sums[kClosed] += 1;
      sums[kReleased] += 0.5 * rmass[i] * event.release_speed * event.release_speed;
      maxima[kPeakWall] = std::max(maxima[kPeakWall], event.peak_wall);
      maxima[kPeakPair] = std::max(maxima[kPeakPair], event.peak_pair);
      maxima[kRelease] = std::max(maxima[kRelease], event.release_speed);
      pending_.insert(pending_.end(), {event.start_time, event.end_time, static_cast<double>(atom->tag[i]),
                                       event.position[0], event.position[1], event.position[2], radius[i],
                                       event.peak_wall, event.peak_pair, static_cast<double>(event.walls),
                                       static_cast<double>(sq::kind(event)), event.with_particles ? 1.0 : 0.0,
                                       event.start_speed, event.release_speed, static_cast<double>(event.number)});
    }
    if (events_before == 0 && track.events > 0) sums[kDistinct] += 1;
    sums[kPressed] += track.phase == sq::kPressed;
    std::memcpy(s, &track, sizeof track);

    if (crossed[i] != 0 && s[kCrossed] == 0) {
      sums[kCrossings] += 1;
      int wall = 0;
      while (!(crossed[i] & (1u << wall))) ++wall;
      new_crossings.insert(new_crossings.end(), {static_cast<double>(atom->tag[i]), static_cast<double>(wall), x[i][0],
                                                 x[i][1], x[i][2], t});
    }
    s[kCrossed] = crossed[i] != 0;
  }
  const double power_local = walls_->step_power();

  double reduced[kSums + 1], local[kSums + 1];
  std::copy(sums, sums + kSums, local);
  local[kSums] = power_local;
  MPI_Allreduce(local, reduced, kSums + 1, MPI_DOUBLE, MPI_SUM, world);
  // the peaks change only where a squeeze closed (maxima stay 0 on every rank otherwise): one
  // reduction a step, a second on the steps where one closed
  double peaks[kMaxima] = {0};
  if (reduced[kClosed] > 0) MPI_Allreduce(maxima, peaks, kMaxima, MPI_DOUBLE, MPI_MAX, world);

  // the energy budget: the walls' work (trapezoid over the step), gravity's, particles brought and taken
  const double power = reduced[kSums];
  const double wall_work = 0.5 * dt * (power + power_previous_);
  power_previous_ = power;
  const double removed = kinetic_ - reduced[kKineticSeen];
  work_walls_ += wall_work;
  work_gravity_ += reduced[kGravityWork];
  budget_ += wall_work + reduced[kGravityWork] + reduced[kKineticNew] - removed;
  scale_ += std::fabs(wall_work) + std::fabs(reduced[kGravityWork]) + reduced[kKineticNew] + std::fabs(removed);
  kinetic_ = reduced[kKinetic];
  lift_ = reduced[kLift];
  events_ += reduced[kClosed];
  pressed_now_ = reduced[kPressed];
  distinct_ += reduced[kDistinct];
  released_ += reduced[kReleased];
  peak_wall_ = std::max(peak_wall_, peaks[kPeakWall]);
  peak_pair_ = std::max(peak_pair_, peaks[kPeakPair]);
  max_release_ = std::max(max_release_, peaks[kRelease]);

  if (reduced[kCrossings] > 0) report_crossings(new_crossings, reduced[kCrossings]);
  if (max_energy_excess_ > 0 && excess() > max_energy_excess_) stop_for_energy();

  const bigint step = update->ntimestep;
  if (step % flush_every_ == 0 || output->restart_requested(step) || step == update->laststep) flush();
}

double FixSqueezeLedger::excess() const
{
  const double scale = scale_ + lift_ + kinetic_;
  return scale > 0 ? (kinetic_ - budget_) / scale : 0.0;
}

// The new crossings of this step, gathered on rank 0: the first ones are named in the log; above
// max_crossed the run stops with the last of them.
void FixSqueezeLedger::report_crossings(const std::vector<double> &mine, double count)
{
  const double before = crossings_;
  crossings_ += count;
  const bool name = crossings_named_ < kCrossingsNamed;
  const bool stop = max_crossed_ >= 0 && crossings_ > static_cast<double>(max_crossed_);
  if (!name && !stop) return;
  const std::vector<double> all = tsg::gather_to_all(world, mine, comm->nprocs);
  const int total = static_cast<int>(all.size());
  auto describe = [&](const double *c) {
    const int wall = static_cast<int>(c[1]);
    return "particle " + number(c[0]) + " has its centre behind the surface of wall " +
           (wall < static_cast<int>(wall_names_.size()) ? wall_names_[wall] : std::to_string(wall)) + " at (" +
           number(c[2]) + ", " + number(c[3]) + ", " + number(c[4]) + ") m, t = " + number(c[5]) + " s";
  };
  const int n = total / kCrossingWidth;
  for (int k = 0; k < n && crossings_named_ < kCrossingsNamed; ++k, ++crossings_named_)
    if (comm->me == 0)
      error->warning(FLERR, (who_ + ": crossing " + number(before + k + 1) + ": " + describe(&all[k * kCrossingWidth]) +
                             (crossings_named_ + 1 == kCrossingsNamed ? " (further crossings are counted only)" : ""))
                                .c_str());
  if (stop && n > 0)
    fail(lmp, who_,
         describe(&all[(n - 1) * kCrossingWidth]) + "; " + number(crossings_) +
             " crossings exceed max_crossed = " + std::to_string(max_crossed_) +
             " (a centre behind a wall is pushed on through it: raise max_crossed to count them only)");
}

void FixSqueezeLedger::stop_for_energy()
{
  struct {
    double speed;
    int rank;
  } mine{0, comm->me}, fastest{0, 0};
  int fastest_local = -1;
  for (int i = 0; i < atom->nlocal; ++i) {
    if (!(atom->mask[i] & groupbit)) continue;
    const double *v = atom->v[i];
    const double speed = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (speed >= mine.speed) mine.speed = speed, fastest_local = i;
  }
  MPI_Allreduce(&mine, &fastest, 1, MPI_DOUBLE_INT, MPI_MAXLOC, world);
  double where[4] = {0, 0, 0, 0};
  if (comm->me == fastest.rank && fastest_local >= 0) {
    where[0] = atom->tag[fastest_local];
    std::copy(atom->x[fastest_local], atom->x[fastest_local] + 3, where + 1);
  }
  MPI_Bcast(where, 4, MPI_DOUBLE, fastest.rank, world);
  fail(lmp, who_,
       "kinetic energy runaway: KE = " + number(kinetic_) +
           " J exceeds the energy the walls, gravity and new particles " + "brought (" + number(budget_) + " J) by " +
           number(excess()) + " of the energy turnover, above max_energy_excess = " + number(max_energy_excess_) +
           "; fastest particle " + number(where[0]) + " at (" + number(where[1]) + ", " + number(where[2]) + ", " +
           number(where[3]) + ") m, " + number(fastest.speed) +
           " m/s (the integration creates energy: reduce the time step)");
}

void FixSqueezeLedger::post_run() { flush(); }

void FixSqueezeLedger::flush()
{
  const std::vector<double> all = tsg::gather_to_root(world, pending_, comm->me, comm->nprocs);
  pending_.clear();
  if (comm->me != 0 || !fp_) return;
  const size_t n = all.size() / kRecordWidth;
  std::vector<const double *> rows(n);
  for (size_t k = 0; k < n; ++k) rows[k] = &all[k * kRecordWidth];
  std::sort(rows.begin(), rows.end(),
            [](const double *a, const double *b) { return std::tie(a[1], a[2], a[0]) < std::tie(b[1], b[2], b[0]); });
  std::string text;
  char line[512];
  for (const double *r : rows) {
    std::snprintf(line, sizeof line,
                  "%.10g %.10g %.0f %.10g %.10g %.10g %.10g %.10g %.10g %.0f %.0f %.0f %.10g %.10g %.0f\n", r[0], r[1],
                  r[2], r[3], r[4], r[5], r[6], r[7], r[8], r[9], r[10], r[11], r[12], r[13], r[14]);
    text += line;
  }
  fwrite(text.data(), 1, text.size(), fp_);
  fflush(fp_);
}

double FixSqueezeLedger::compute_vector(int n)
{
  const double values[] = {events_,    pressed_now_, distinct_,     peak_wall_, peak_pair_,         max_release_,
                           crossings_, work_walls_,  work_gravity_, kinetic_,   budget_ - kinetic_, excess(),
                           released_};
  return values[std::min(n, static_cast<int>(sizeof values / sizeof values[0]) - 1)];
}

// global state: a format mark, the counters, the energy budget and the clock
namespace {
constexpr double kRestartMark = -20261203.0;
enum RestartEntry {
  kMark,
  kEvents,
  kDistinct,
  kCrossingsTotal,
  kPeakWallRun,
  kPeakPairRun,
  kMaxRelease,
  kWorkWalls,
  kWorkGravity,
  kBudget,
  kScale,
  kKineticTotal,
  kReleasedTotal,
  kPowerPrevious,
  kCrossingsNamedTotal,
  kFirstSetup,
  kClockTime,
  kClockStep,
  kEntries
};
}  // namespace

void FixSqueezeLedger::write_restart(FILE *fp)
{
  std::vector<double> list(kEntries);
  list[kMark] = kRestartMark;
  list[kEvents] = events_, list[kDistinct] = distinct_, list[kCrossingsTotal] = crossings_;
  list[kPeakWallRun] = peak_wall_, list[kPeakPairRun] = peak_pair_, list[kMaxRelease] = max_release_;
  list[kWorkWalls] = work_walls_, list[kWorkGravity] = work_gravity_, list[kBudget] = budget_;
  list[kScale] = scale_, list[kKineticTotal] = kinetic_, list[kReleasedTotal] = released_;
  list[kPowerPrevious] = power_previous_, list[kCrossingsNamedTotal] = crossings_named_;
  list[kFirstSetup] = first_setup_done_ ? 1 : 0;
  clock_.save(update, &list[kClockTime], &list[kClockStep]);
  write_global(fp, list);
}

void FixSqueezeLedger::restart(char *buf)
{
  const double *list = reinterpret_cast<const double *>(buf);
  if (list[kMark] != kRestartMark) fail(lmp, who_, "the restart file was not written by this version of the fix");
  events_ = list[kEvents], distinct_ = list[kDistinct], crossings_ = list[kCrossingsTotal];
  peak_wall_ = list[kPeakWallRun], peak_pair_ = list[kPeakPairRun], max_release_ = list[kMaxRelease];
  work_walls_ = list[kWorkWalls], work_gravity_ = list[kWorkGravity], budget_ = list[kBudget];
  scale_ = list[kScale], kinetic_ = list[kKineticTotal], released_ = list[kReleasedTotal];
  power_previous_ = list[kPowerPrevious];
  crossings_named_ = static_cast<int>(list[kCrossingsNamedTotal]);
  first_setup_done_ = list[kFirstSetup] != 0;
  clock_.load(list[kClockTime], list[kClockStep]);
  continuing_ = true;
}
