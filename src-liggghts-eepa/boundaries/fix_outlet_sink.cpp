// fix outlet/sink: see fix_outlet_sink.h.
#include "fix_outlet_sink.h"

#include <mpi.h>

#include "atom.h"
#include "atom_vec.h"
#include "comm.h"
#include "domain.h"
#include "update.h"

#include "box_checks.h"
#include "errors.h"
#include "numbers.h"

using namespace LAMMPS_NS;
using tsg::fail;
using tsg::number;

FixOutletSink::FixOutletSink(LAMMPS *lmp, int narg, char **arg)
    : Fix(lmp, narg, arg), who_(std::string("fix ") + id + " outlet/sink"), outlet_x_(0)
{
  if (narg != 5 || std::string(arg[3]) != "x" || !tsg::parse_real(arg[4], outlet_x_))
    fail(lmp, who_,
         std::string("needs 'x X', the outlet plane's position along the axis in m, got '") + (narg > 3 ? arg[3] : "") +
             (narg > 4 ? std::string(" ") + arg[4] : "") + (narg > 5 ? " ..." : "") + "'");
  if (domain->periodicity[0])
    fail(lmp, who_, "the x axis is periodic: particles never leave it, there is no outlet to remove them at");
  if (!tsg::fixed_box_x(domain))
    fail(lmp, who_, "the box along x is shrink-wrapped: give it fixed ends (boundary f ...) to place the outlet in");
  if (!(outlet_x_ > domain->boxlo[0] && outlet_x_ < domain->boxhi[0]))
    fail(lmp, who_,
         "x " + number(outlet_x_) + " is not allowed: the outlet plane must lie inside the box along x (" +
             number(domain->boxlo[0]) + ", " + number(domain->boxhi[0]) + ")");
  if (!atom->tag_enable) fail(lmp, who_, "needs particle ids (atom_modify id yes)");
  force_reneighbor = 1;  // so that LIGGGHTS asks next_reneighbor every step
  next_reneighbor = -1;
  vector_flag = 1;
  size_vector = 2;
  extvector = 1;
  global_freq = 1;
  restart_global = 1;
}

int FixOutletSink::setmask() { return FixConst::END_OF_STEP | FixConst::PRE_EXCHANGE; }

void FixOutletSink::init()
{
  if (domain->triclinic) fail(lmp, who_, "needs an orthogonal box (triclinic boxes are not supported)");
}

// particles past the outlet at the start of a run (inserted there, or from a restart file) go at
// its first re-neighbouring, the set-up's
void FixOutletSink::setup(int) { end_of_step(); }

bool FixOutletSink::any_past() const
{
  const double *const *x = atom->x;
  const int *mask = atom->mask;
  int here = 0;
  for (int i = 0; i < atom->nlocal && !here; ++i)
    if ((mask[i] & groupbit) && x[i][0] > outlet_x_) here = 1;
  int anywhere = 0;
  MPI_Allreduce(&here, &anywhere, 1, MPI_INT, MPI_MAX, world);
  return anywhere != 0;
}

void FixOutletSink::end_of_step()
{
  if (any_past()) next_reneighbor = update->ntimestep + 1;
}

// Every re-neighbouring step, whoever asked for it: delete this rank's particles past the plane
// (the last local particle moves into each freed slot, per-particle arrays of fixes with it), then
// the global count and the id map follow, as in LIGGGHTS' delete_atoms; Thermo's lost-atom check
// is told how many went on purpose.
void FixOutletSink::pre_exchange() { remove_past(); }

void FixOutletSink::remove_past()
{
  double count = 0, mass = 0;
  const int *mask = atom->mask;
  int i = 0;
  while (i < atom->nlocal) {
    if ((mask[i] & groupbit) && atom->x[i][0] > outlet_x_) {
      count += 1;
      mass += atom->rmass ? atom->rmass[i] : atom->mass[atom->type[i]];
      atom->avec->copy(atom->nlocal - 1, i, 1);
      atom->nlocal--;
    } else {
      ++i;
    }
  }
  double mine[2] = {count, mass}, all[2] = {0, 0};
  MPI_Allreduce(mine, all, 2, MPI_DOUBLE, MPI_SUM, world);
  if (all[0] == 0) return;
  removed_ += all[0];
  removed_mass_ += all[1];
  atom->nremoved_on_purpose += static_cast<bigint>(all[0]);  // not lost (patches/atom-h.patch)
  bigint nlocal = atom->nlocal;
  MPI_Allreduce(&nlocal, &atom->natoms, 1, MPI_LMP_BIGINT, MPI_SUM, world);
  if (atom->map_style) {
    atom->nghost = 0;
    atom->map_init();
    atom->map_set();
  }
}

double FixOutletSink::compute_vector(int n) { return n == 0 ? removed_ : removed_mass_; }

void FixOutletSink::write_restart(FILE *fp)
{
  if (comm->me != 0) return;
  const double data[2] = {removed_, removed_mass_};
  const int size = sizeof(data);
  fwrite(&size, sizeof(int), 1, fp);
  fwrite(data, sizeof(double), 2, fp);
}

void FixOutletSink::restart(char *buf)
{
  const double *data = reinterpret_cast<const double *>(buf);
  removed_ = data[0];
  removed_mass_ = data[1];
}
