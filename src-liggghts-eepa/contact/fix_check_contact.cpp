// fix check/contact: see fix_check_contact.h.
#include "fix_check_contact.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "atom.h"
#include "comm.h"
#include "error.h"
#include "fix_mesh_surface.h"
#include "fix_neighlist_mesh.h"
#include "fix_property_global.h"
#include "fix_wall_gran.h"
#include "force.h"
#include "memory.h"
#include "modify.h"
#include "tri_mesh.h"
#include "update.h"

#include "contact_timestep.h"
#include "errors.h"
#include "numbers.h"
#include "pair_contacts.h"
#include "wall_contact_source.h"

using namespace LAMMPS_NS;

namespace {

constexpr int kFixedOutputs = 5;      // pair δ/R run and now, estimate, dt/estimate, speed
constexpr int kFastEventsNamed = 10;  // fast_speed events named in the log; the rest are counted

// numbers in the guards' messages: 4 significant digits (numbers.h)
std::string number(double v) { return tsg::number(v, tsg::NumberKind::guard); }

struct ValueRank {  // layout of MPI_DOUBLE_INT
  double value;
  int rank;
};

}  // namespace

FixCheckContact::FixCheckContact(LAMMPS *lmp, int narg, char **arg)
    : Fix(lmp, narg, arg), check_every_(1000), step_fraction_(0.2), error_on_violation_(true), warned_(false),
      max_speed_(0), fast_speed_(0), above_fast_(nullptr), fast_events_(0), fast_events_local_(0),
      fast_events_named_(0), fast_event_to_name_(-1), max_pair_overlap_(0), max_wall_overlap_(0), walls_(nullptr),
      contact_source_(nullptr), max_overlap_ratio_run_(0), max_overlap_ratio_now_(0), max_speed_squared_window_(0),
      max_speed_now_(0), estimate_(0), youngs_modulus_(nullptr), poisson_ratio_(nullptr), plasticity_ratio_(nullptr)
{
  // every keyword is validated here, each with one message naming it, its value and what is allowed
  auto fail = [&](const std::string &message) {
    error->fix_error(FLERR, this, message.c_str());
  };
  auto positive_number = [&](const std::string &key, const char *value, const char *allowed) {
    double number = 0;
    if (!tsg::scan_real(value, number)) fail(key + " = " + value + " is not a number");
    if (!(number > 0 && std::isfinite(number))) fail(key + " = " + value + " is outside the allowed range " + allowed);
    return number;
  };
  auto positive_integer = [&](const std::string &key, const char *value) {
    long every = 0;
    if (!tsg::parse_integer(value, 1, 1000000000, every)) fail(key + " = " + value + " must be a positive integer");
    return static_cast<int>(every);
  };
  for (int iarg = 3; iarg < narg; iarg += 2) {
    if (iarg + 1 >= narg) fail(std::string("keyword '") + arg[iarg] + "' needs a value");
    const std::string key = arg[iarg];
    const char *value = arg[iarg + 1];
    if (key == "every") {
      check_every_ = positive_integer(key, value);
    } else if (key == "pair_every") {
      pair_every_ = positive_integer(key, value);
    } else if (key == "step_fraction") {
      step_fraction_ = positive_number(key, value, "(0, 1]");
      if (step_fraction_ > 1) fail(std::string("step_fraction = ") + value + " is outside the allowed range (0, 1]");
    } else if (key == "action") {
      if (strcmp(value, "warn") == 0)
        error_on_violation_ = false;
      else if (strcmp(value, "error") == 0)
        error_on_violation_ = true;
      else
        fail(std::string("action = ") + value + " must be 'error' or 'warn'");
    } else if (key == "max_speed") {
      max_speed_ = positive_number(key, value, "(0, inf) m/s");
    } else if (key == "fast_speed") {
      fast_speed_ = positive_number(key, value, "(0, inf) m/s");
    } else if (key == "max_pair_overlap") {
      max_pair_overlap_ = positive_number(key, value, "(0, inf) (overlap / radius)");
    } else if (key == "max_wall_overlap") {
      max_wall_overlap_ = positive_number(key, value, "(0, inf) (overlap / radius)");
    } else if (key == "walls") {
      wall_fix_id_ = value;
    } else {
      fail("unknown keyword '" + key +
           "' (allowed: every, pair_every, step_fraction, action, max_speed, fast_speed, max_pair_overlap, walls, "
           "max_wall_overlap)");
    }
  }
  if (fast_speed_ > 0 && max_speed_ > 0 && !(fast_speed_ < max_speed_))
    fail("fast_speed = " + number(fast_speed_) + " m/s must be below max_speed = " + number(max_speed_) +
         " m/s (the events it counts are the speeds between them)");
  if (pair_every_ == 0) pair_every_ = check_every_;
  if (max_wall_overlap_ > 0 && wall_fix_id_.empty())
    fail("max_wall_overlap needs 'walls <ID of a fix wall/gran with meshes>'");
  if (!wall_fix_id_.empty()) {
    const int index = modify->find_fix(wall_fix_id_.c_str());
    FixWallGran *walls = index < 0 ? nullptr : dynamic_cast<FixWallGran *>(modify->fix[index]);
    if (!walls || !walls->is_mesh_wall())
      fail("walls = " + wall_fix_id_ + " is not the ID of a fix wall/gran or wall/gran/corotating with meshes");
    for (int k = 0; k < walls->n_meshes(); ++k) mesh_ids_.push_back(walls->mesh_list()[k]->id);
    wall_overlap_now_.assign(mesh_ids_.size(), 0.0);
  }
  nevery = 1;  // the motion guard runs every step; the rest every check_every_ steps
  vector_flag = 1;
  size_vector = kFixedOutputs + static_cast<int>(mesh_ids_.size()) + 1;
  global_freq = 1;  // outputs hold the last check's values at any step (thermo at the end of a run)
  extvector = 0;
  restart_global = 1;    // the event count
  restart_peratom = 1;   // above_fast_: an excursion across a restart is one event
  create_attribute = 1;  // set_arrays for inserted particles
  grow_arrays(atom->nmax);
  for (int i = 0; i < atom->nmax; ++i) set_arrays(i);
  atom->add_callback(0);  // above_fast_ migrates with its particle
  atom->add_callback(1);  // and goes into restart files
}

FixCheckContact::~FixCheckContact()
{
  atom->delete_callback(id, 0);
  atom->delete_callback(id, 1);
  memory->destroy(above_fast_);
}

void FixCheckContact::grow_arrays(int nmax) { memory->grow(above_fast_, nmax, "check/contact:above_fast"); }

void FixCheckContact::copy_arrays(int i, int j, int) { above_fast_[j] = above_fast_[i]; }

void FixCheckContact::set_arrays(int i) { above_fast_[i] = 0; }

int FixCheckContact::pack_exchange(int i, double *buf)
{
  buf[0] = above_fast_[i];
  return 1;
}

int FixCheckContact::unpack_exchange(int nlocal, double *buf)
{
  above_fast_[nlocal] = buf[0];
  return 1;
}

// per particle in a restart file: the block size, then the flag
int FixCheckContact::pack_restart(int i, double *buf)
{
  buf[0] = 2;
  buf[1] = above_fast_[i];
  return 2;
}

void FixCheckContact::unpack_restart(int nlocal, int nth)
{
  double **extra = atom->extra;
  int m = 0;
  for (int i = 0; i < nth; ++i) m += static_cast<int>(extra[nlocal][m]);
  above_fast_[nlocal] = extra[nlocal][m + 1];
}

void FixCheckContact::write_restart(FILE *fp)
{
  if (comm->me != 0) return;
  const double data[1] = {fast_events_};
  const int size = sizeof(data);
  fwrite(&size, sizeof(int), 1, fp);
  fwrite(data, sizeof(double), 1, fp);
}

void FixCheckContact::restart(char *buf) { fast_events_ = reinterpret_cast<const double *>(buf)[0]; }

int FixCheckContact::setmask() { return FixConst::END_OF_STEP; }

void FixCheckContact::init()
{
  if (!force->pair_match("gran", 0)) error->fix_error(FLERR, this, "needs a granular pair style (pair_style gran ...)");
  const int ntypes = atom->ntypes;
  youngs_modulus_ = static_cast<FixPropertyGlobal *>(
      modify->find_fix_property("youngsModulus", "property/global", "peratomtype", ntypes, 0, style));
  poisson_ratio_ = static_cast<FixPropertyGlobal *>(
      modify->find_fix_property("poissonsRatio", "property/global", "peratomtype", ntypes, 0, style));
  plasticity_ratio_ = static_cast<FixPropertyGlobal *>(
      modify->find_fix_property("plasticityRatio", "property/global", "peratomtypepair", ntypes, ntypes, style, false));
  walls_ = nullptr;
  contact_source_ = nullptr;
  if (!wall_fix_id_.empty()) {
    const int index = modify->find_fix(wall_fix_id_.c_str());
    walls_ = index < 0 ? nullptr : dynamic_cast<FixWallGran *>(modify->fix[index]);
    if (!walls_ || walls_->n_meshes() != static_cast<int>(mesh_ids_.size()))
      error->fix_error(FLERR, this, ("walls = " + wall_fix_id_ + ": the wall fix was deleted or replaced").c_str());
    contact_source_ = dynamic_cast<tsg::WallContactSource *>(walls_);
  }
}

void FixCheckContact::setup(int)
{
  check_motion();
  check();
}

void FixCheckContact::end_of_step()
{
  check_motion();
  if (update->ntimestep % check_every_ == 0)
    check();
  else if (update->ntimestep % pair_every_ == 0)
    check_pair_overlap();
}

void FixCheckContact::check()
{
  check_time_step();
  check_pair_overlap();
  check_wall_overlap();
  double window = 0;
  MPI_Allreduce(&max_speed_squared_window_, &window, 1, MPI_DOUBLE, MPI_MAX, world);
  max_speed_now_ = std::sqrt(window);
  max_speed_squared_window_ = 0;
  double new_events = 0;
  MPI_Allreduce(&fast_events_local_, &new_events, 1, MPI_DOUBLE, MPI_SUM, world);
  fast_events_ += new_events;
  fast_events_local_ = 0;
}

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

void FixCheckContact::check_time_step()
{
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
             "above the allowed step_fraction %.3g; use timestep <= %.4g%s",
             update->dt, ratio, estimate_, step_fraction_, step_fraction_ * estimate_,
             error_on_violation_ ? " (or 'action warn' to run on at your own risk)" : "");
    if (error_on_violation_) error->all(FLERR, message);
    if (!warned_ && comm->me == 0) error->warning(FLERR, message);
    warned_ = true;
  }
}

// Every step: a non-finite position, velocity or force, or a particle faster than max_speed; and
// the fast_speed events. The common case costs one pass without branches on the values: NaN and
// infinity propagate through a sum, so one finite sum clears every particle; only a non-finite sum
// (or a speed above the bound) sends a second pass looking for the particle.
void FixCheckContact::check_motion()
{
  double **x = atom->x, **v = atom->v, **f = atom->f;
  const int *mask = atom->mask;
  const int nlocal = atom->nlocal;
  const double fast_squared = fast_speed_ > 0 ? fast_speed_ * fast_speed_ : INFINITY;
  double sum = 0;
  double largest = max_speed_squared_window_;
  fast_event_to_name_ = -1;
  for (int i = 0; i < nlocal; ++i) {
    if (!(mask[i] & groupbit)) continue;
    const double speed_squared = v[i][0] * v[i][0] + v[i][1] * v[i][1] + v[i][2] * v[i][2];
    sum += x[i][0] + x[i][1] + x[i][2] + f[i][0] + f[i][1] + f[i][2] + speed_squared;
    largest = std::max(largest, speed_squared);
    const double above = speed_squared > fast_squared ? 1.0 : 0.0;
    if (above > above_fast_[i]) {  // a new excursion above fast_speed
      fast_events_local_ += 1;
      if (fast_event_to_name_ < 0) fast_event_to_name_ = i;
    }
    above_fast_[i] = above;
  }
  int bad = -1;
  if (!std::isfinite(sum))  // a non-finite value, or finite values too large to add: look
    for (int i = 0; i < nlocal && bad < 0; ++i)
      if ((mask[i] & groupbit) && !(std::isfinite(x[i][0]) && std::isfinite(x[i][1]) && std::isfinite(x[i][2]) &&
                                    std::isfinite(v[i][0]) && std::isfinite(v[i][1]) && std::isfinite(v[i][2]) &&
                                    std::isfinite(f[i][0]) && std::isfinite(f[i][1]) && std::isfinite(f[i][2])))
        bad = i;
  if (std::isfinite(largest)) max_speed_squared_window_ = largest;
  const bool too_fast = bad < 0 && max_speed_ > 0 && largest > max_speed_ * max_speed_;
  if (too_fast)
    for (int i = 0; i < nlocal && bad < 0; ++i)
      if ((mask[i] & groupbit) && v[i][0] * v[i][0] + v[i][1] * v[i][1] + v[i][2] * v[i][2] > max_speed_ * max_speed_)
        bad = i;
  // what this rank has to say, most serious first: 3 non-finite, 2 too fast, 1 a fast_speed event to name
  const bool name_event = fast_event_to_name_ >= 0 && fast_events_named_ < kFastEventsNamed;
  int mine[2] = {bad >= 0 ? (too_fast ? 2 : 3) : (name_event ? 1 : 0), comm->me}, worst[2] = {0, 0};
  MPI_Allreduce(mine, worst, 1, MPI_2INT, MPI_MAXLOC, world);
  if (worst[0] == 0) return;
  auto speed_of = [&](int i) {
    return std::sqrt(v[i][0] * v[i][0] + v[i][1] * v[i][1] + v[i][2] * v[i][2]);
  };
  std::string message;
  if (comm->me == worst[1]) {
    const int who_index = worst[0] == 1 ? fast_event_to_name_ : bad;
    const std::string who = "step " + std::to_string(static_cast<long long>(update->ntimestep)) + ": particle " +
                            std::to_string(static_cast<long long>(atom->tag[who_index]));
    auto triple = [](const double *a) {
      return "(" + number(a[0]) + ", " + number(a[1]) + ", " + number(a[2]) + ")";
    };
    if (worst[0] == 3)
      message = "check/contact: " + who + " has a non-finite position, velocity or force: x " + triple(x[bad]) +
                " m, v " + triple(v[bad]) + " m/s, f " + triple(f[bad]) + " N; " + contacts_of(bad);
    else if (worst[0] == 2)
      message = "check/contact: " + who + " moves at " + number(speed_of(bad)) +
                " m/s, above max_speed = " + number(max_speed_) +
                " m/s (kinetic energy blow-up: time step too large for the contact stiffness, or a particle "
                "crushed between walls); " +
                contacts_of(bad);
    else
      message = "check/contact: fast_speed event " + std::to_string(fast_events_named_ + 1) + " (of the first " +
                std::to_string(kFastEventsNamed) + " named): " + who + " moves at " +
                number(speed_of(fast_event_to_name_)) + " m/s, above fast_speed = " + number(fast_speed_) + " m/s; " +
                contacts_of(fast_event_to_name_) +
                " (counted, not stopped: a release from a squeeze, docs/stability.md)";
  }
  if (worst[0] > 1) tsg::fail_from(lmp, worst[1], message);
  const std::string text = tsg::broadcast_text(world, message, worst[1]);
  ++fast_events_named_;
  if (comm->me == 0) {
    if (screen) fprintf(screen, "%s\n", text.c_str());
    if (logfile) fprintf(logfile, "%s\n", text.c_str());
  }
}

// Deepest particle-particle contact over the pair style's neighbour list (only_atom >= 0: the
// contacts of that local particle only).
FixCheckContact::Deepest FixCheckContact::deepest_pair_contact(int only_atom) const
{
  Deepest deepest;
  const int *mask = atom->mask;
  const tagint *tag = atom->tag;
  tsg::for_each_pair_contact(lmp, [&](int i, int j, double ratio) {
    if (!(mask[i] & groupbit) || (only_atom >= 0 && i != only_atom && j != only_atom)) return;
    if (ratio > deepest.overlap_ratio) {
      const bool i_first = only_atom < 0 || i == only_atom;
      deepest = {ratio, tag[i_first ? i : j], tag[i_first ? j : i]};
    }
  });
  return deepest;
}

// Deepest contact of a particle with a mesh handled by stock fix wall/gran, from that fix's mesh
// neighbour lists (the triangles within reach of each particle).
FixCheckContact::Deepest FixCheckContact::deepest_stock_wall_contact(int mesh, int only_atom) const
{
  Deepest deepest;
  FixMeshSurface *surface = walls_->mesh_list()[mesh];
  TriMesh *triangles = surface->triMesh();
  FixNeighlistMesh *lists = surface->meshNeighlist();
  if (!lists) return deepest;
  double **x = atom->x;
  const double *radius = atom->radius;
  const int nlocal = atom->nlocal;
  const int ntriangles = triangles->sizeLocal() + triangles->sizeGhost();
  double delta[3];
  for (int t = 0; t < ntriangles; ++t)
    for (const int i : lists->get_contact_list(t)) {
      if (i >= nlocal || !(atom->mask[i] & groupbit) || (only_atom >= 0 && i != only_atom)) continue;
      int barysign = 0;
      const double gap = triangles->resolveTriSphereContact(i, t, radius[i], x[i], delta, barysign);
      if (-gap > deepest.overlap_ratio * radius[i]) deepest = {-gap / radius[i], atom->tag[i], 0};
    }
  return deepest;
}

// "deepest contact: particle 12 at δ/R 0.31; walls: screw1 0.12, barrel 0.05" for local particle i
std::string FixCheckContact::contacts_of(int i) const
{
  const Deepest pair = deepest_pair_contact(i);
  std::string text = pair.partner_id ? "deepest particle contact: particle " +
                                           std::to_string(static_cast<long long>(pair.partner_id)) +
                                           " at overlap/radius " + number(pair.overlap_ratio)
                                     : std::string("no particle contact");
  if (!walls_) return text;
  const unsigned touched = contact_source_ ? contact_source_->walls_in_contact(i) : 0u;
  std::string walls;
  for (size_t k = 0; k < mesh_ids_.size(); ++k) {
    if (reported(static_cast<int>(k))) {
      if (touched & (1u << k)) walls += (walls.empty() ? "" : ", ") + mesh_ids_[k];
      continue;
    }
    const Deepest wall = deepest_stock_wall_contact(static_cast<int>(k), i);
    if (wall.overlap_ratio > 0)
      walls += (walls.empty() ? "" : ", ") + mesh_ids_[k] + " at overlap/radius " + number(wall.overlap_ratio);
  }
  return text + "; wall contacts: " + (walls.empty() ? "none" : walls);
}

void FixCheckContact::check_pair_overlap()
{
  const Deepest mine = deepest_pair_contact(-1);
  ValueRank local{mine.overlap_ratio, comm->me}, global{0, 0};
  MPI_Allreduce(&local, &global, 1, MPI_DOUBLE_INT, MPI_MAXLOC, world);
  max_overlap_ratio_now_ = global.value;
  max_overlap_ratio_run_ = std::max(max_overlap_ratio_run_, max_overlap_ratio_now_);
  if (!(max_pair_overlap_ > 0 && global.value > max_pair_overlap_)) return;
  std::string message;
  if (comm->me == global.rank)
    message = "check/contact: step " + std::to_string(static_cast<long long>(update->ntimestep)) + ": particles " +
              std::to_string(static_cast<long long>(mine.atom_id)) + " and " +
              std::to_string(static_cast<long long>(mine.partner_id)) + " overlap by " + number(mine.overlap_ratio) +
              " of the smaller radius, above max_pair_overlap = " + number(max_pair_overlap_) +
              " (not physics: particles crushed, or a time step too large)";
  tsg::fail_from(lmp, global.rank, message);
}

void FixCheckContact::check_wall_overlap()
{
  if (!walls_) return;
  const size_t nmeshes = mesh_ids_.size();
  std::vector<Deepest> mine(nmeshes);
  std::vector<ValueRank> local(nmeshes), global(nmeshes);
  for (size_t k = 0; k < nmeshes; ++k) {
    if (reported(static_cast<int>(k))) {
      const tsg::WallContactSource::DeepestContact deepest = contact_source_->take_deepest(static_cast<int>(k));
      mine[k] = {deepest.overlap_ratio, static_cast<tagint>(deepest.atom_id), 0};
    } else {
      mine[k] = deepest_stock_wall_contact(static_cast<int>(k), -1);
    }
    local[k] = {mine[k].overlap_ratio, comm->me};
  }
  MPI_Allreduce(local.data(), global.data(), static_cast<int>(nmeshes), MPI_DOUBLE_INT, MPI_MAXLOC, world);
  for (size_t k = 0; k < nmeshes; ++k) wall_overlap_now_[k] = global[k].value;
  if (!(max_wall_overlap_ > 0)) return;
  for (size_t k = 0; k < nmeshes; ++k) {
    if (!(global[k].value > max_wall_overlap_)) continue;
    std::string message;
    if (comm->me == global[k].rank)
      message = "check/contact: step " + std::to_string(static_cast<long long>(update->ntimestep)) + ": particle " +
                std::to_string(static_cast<long long>(mine[k].atom_id)) + " overlaps mesh " + mesh_ids_[k] + " by " +
                number(mine[k].overlap_ratio) +
                " of its radius, above max_wall_overlap = " + number(max_wall_overlap_) +
                " (a particle pushed into the wall: crushed in a clearance, or too fast)";
    tsg::fail_from(lmp, global[k].rank, message);
  }
}

double FixCheckContact::compute_vector(int n)
{
  switch (n) {
    case 0:
      return max_overlap_ratio_run_;
    case 1:
      return max_overlap_ratio_now_;
    case 2:
      return estimate_;
    case 3:
      return estimate_ > 0 ? update->dt / estimate_ : 0;
    case 4:
      return max_speed_now_;
    default:
      if (n == kFixedOutputs + static_cast<int>(wall_overlap_now_.size())) return fast_events_;
      return wall_overlap_now_[n - kFixedOutputs];
  }
}
