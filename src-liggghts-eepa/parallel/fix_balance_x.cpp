// fix balance/x: see fix_balance_x.h and docs/performance.md, "fix balance/x".
#include "fix_balance_x.h"

#include <mpi.h>

#include <stdexcept>

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "neighbor.h"
#include "update.h"

#include "balance_cuts.h"
#include "errors.h"
#include "numbers.h"

using namespace LAMMPS_NS;
namespace bal = ::tsg::balance;
using tsg::fail;
using tsg::number;

namespace {
// histogram bins per rank: a cut lands inside the bin of its equal-count place (balance_cuts.h), so
// a rank's count is off its share by at most the particles of the two bins at its ends (for an
// even fill, 2 % of the share)
constexpr int kBinsPerRank = 100;
}  // namespace

FixBalanceX::FixBalanceX(LAMMPS *lmp, int narg, char **arg)
    : Fix(lmp, narg, arg), who_(std::string("fix ") + id + " balance/x"), every_(0), parts_(comm->procgrid[0])
{
  long every = 0;
  if (narg != 4 || !tsg::parse_integer(arg[3], 1, 1000000000, every))
    fail(lmp, who_,
         std::string("needs one argument, the balancing interval N in steps (an integer >= 1), got '") +
             (narg > 3 ? arg[3] : "") + (narg > 4 ? " ..." : "") + "'");
  if (igroup != 0)
    fail(lmp, who_, std::string("group '") + arg[1] + "' is not allowed: the work is all particles, use group all");
  every_ = static_cast<int>(every);
  if (comm->procgrid[1] != 1 || comm->procgrid[2] != 1)
    fail(lmp, who_,
         "the processor grid is " + std::to_string(comm->procgrid[0]) + " x " + std::to_string(comm->procgrid[1]) +
             " x " + std::to_string(comm->procgrid[2]) +
             "; balance along x needs slabs along x only: 'processors * 1 1' (or N 1 1) before the box is made");
  // one rank: nothing to move, and nothing to make LIGGGHTS redo on every re-neighbouring
  if (parts_ > 1) {
    box_change_domain = 1;
    force_reneighbor = 1;
    next_reneighbor = (update->ntimestep / every_ + 1) * every_;
  }
  scalar_flag = 1;
  extscalar = 0;
  vector_flag = 1;
  size_vector = parts_ + 1;
  extvector = 0;
  global_freq = 1;
}

int FixBalanceX::setmask() { return FixConst::PRE_EXCHANGE; }

void FixBalanceX::init()
{
  if (domain->triclinic) fail(lmp, who_, "needs an orthogonal box (triclinic boxes are not supported)");
}

void FixBalanceX::setup_pre_exchange()
{
  if (parts_ == 1) return;
  next_reneighbor = (update->ntimestep / every_ + 1) * every_;
  move_cuts();
}

void FixBalanceX::pre_exchange()
{
  if (parts_ == 1 || update->ntimestep < next_reneighbor) return;
  next_reneighbor = (update->ntimestep / every_ + 1) * every_;
  move_cuts();
}

// Equal-count cuts from a global histogram of the particles' x, approached as far as the one-rank
// limit allows, written to Comm's non-uniform split; the caller (Verlet) then sets up Comm and
// exchanges particles, and fix mesh/surface the triangles, for the new sub-domains.
void FixBalanceX::move_cuts()
{
  const double lo = domain->boxlo[0], hi = domain->boxhi[0], length = domain->prd[0];
  // (checked here, not in init(): the neighbour cutoff is set after the fixes' init)
  if (static_cast<double>(parts_) * neighbor->cutneighmax > length)
    fail(lmp, who_,
         std::to_string(parts_) + " slabs of at least the neighbour cutoff " + number(neighbor->cutneighmax) +
             " m do not fit in the box length " + number(length) + " m along x: use fewer ranks");
  const auto nbins = static_cast<std::size_t>(kBinsPerRank) * static_cast<std::size_t>(parts_);
  std::vector<double> mine(nbins, 0.0), all(nbins, 0.0);
  double **x = atom->x;
  for (int i = 0; i < atom->nlocal; ++i) mine[bal::bin_of(x[i][0], lo, hi, nbins)] += 1.0;
  MPI_Allreduce(mine.data(), all.data(), static_cast<int>(nbins), MPI_DOUBLE, MPI_SUM, world);

  std::vector<double> old_cut(static_cast<std::size_t>(parts_) + 1);
  for (int k = 0; k <= parts_; ++k) old_cut[static_cast<std::size_t>(k)] = lo + length * comm->xsplit[k];
  std::vector<double> cut;
  try {
    const auto target = bal::equal_weight_cuts(all, lo, hi, parts_, neighbor->cutneighmax);
    cut = bal::blend(old_cut, target, bal::step_fraction(old_cut, target, neighbor->skin));
  } catch (const std::invalid_argument &e) {
    fail(lmp, who_,
         std::string(e.what()) + " (box " + number(lo) + " .. " + number(hi) + " m, neighbour cutoff " +
             number(neighbor->cutneighmax) + " m, skin " + number(neighbor->skin) + " m)");
  }
  for (int k = 1; k < parts_; ++k) comm->xsplit[k] = (cut[static_cast<std::size_t>(k)] - lo) / length;
  comm->xsplit[0] = 0.0;
  comm->xsplit[parts_] = 1.0;
  comm->uniform = 0;
  domain->set_local_box();
}

double FixBalanceX::compute_scalar()
{
  const double mine = atom->nlocal;
  double largest = 0.0, total = 0.0;
  MPI_Allreduce(&mine, &largest, 1, MPI_DOUBLE, MPI_MAX, world);
  MPI_Allreduce(&mine, &total, 1, MPI_DOUBLE, MPI_SUM, world);
  return total > 0 ? largest * comm->nprocs / total : 1.0;
}

double FixBalanceX::compute_vector(int k) { return domain->boxlo[0] + domain->prd[0] * comm->xsplit[k]; }
