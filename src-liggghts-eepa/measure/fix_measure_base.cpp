// The shared part of the measurement fixes: see fix_measure_base.h.
#include "fix_measure_base.h"

#include <algorithm>

#include "atom.h"
#include "comm.h"
#include "memory.h"
#include "update.h"

using namespace LAMMPS_NS;

FixMeasureBase::FixMeasureBase(LAMMPS *lmp, int narg, char **arg)
    : Fix(lmp, narg, arg), who_(std::string("fix ") + id + " " + style)
{
  nevery = 1;
  vector_flag = 1;
  global_freq = 1;
  extvector = 0;
  restart_global = 1;
  restart_peratom = 1;
  create_attribute = 1;
}

FixMeasureBase::~FixMeasureBase()
{
  if (state_) {
    atom->delete_callback(id, 0);
    atom->delete_callback(id, 1);
  }
  memory->destroy(state_);
  memory->destroy(hot_);
  if (fp_) fclose(fp_);
  tsg::run_files::release(who_);
}

int FixMeasureBase::setmask() { return FixConst::END_OF_STEP; }

void FixMeasureBase::allocate_per_atom(int nstate, int nhot)
{
  nstate_ = nstate;
  nhot_ = nhot;
  grow_arrays(atom->nmax);
  for (int i = 0; i < atom->nmax; ++i) set_arrays(i);
  atom->add_callback(0);
  atom->add_callback(1);
}

void FixMeasureBase::open_file(const std::string &role, const std::string &path, const std::string &header,
                               const std::vector<std::string> &free_prefixes, int time_column)
{
  // a record of the restart step itself stays: half a step of margin above the printed time
  const tsg::Rollback rollback{time_column, clock_.restart_time() + 0.5 * update->dt};
  fp_ = tsg::open_output(lmp, who_, role, path, header, append_, continuing_, free_prefixes, rollback);
  file_opened_ = true;
}

void FixMeasureBase::write_global(FILE *fp, const std::vector<double> &list) const
{
  if (comm->me != 0) return;
  const int size = static_cast<int>(list.size() * sizeof(double));
  fwrite(&size, sizeof(int), 1, fp);
  fwrite(list.data(), sizeof(double), list.size(), fp);
}

void FixMeasureBase::grow_arrays(int nmax)
{
  memory->grow(state_, nmax, nstate_, "measure:state");
  memory->grow(hot_, nmax, nhot_, "measure:hot");
}

void FixMeasureBase::copy_arrays(int i, int j, int)
{
  std::copy(state_[i], state_[i] + nstate_, state_[j]);
  std::copy(hot_[i], hot_[i] + nhot_, hot_[j]);
}

void FixMeasureBase::set_arrays(int i)
{
  std::fill(state_[i], state_[i] + nstate_, 0.0);  // all zeros: not seen yet
  refresh(i);
}

int FixMeasureBase::pack_exchange(int i, double *buf)
{
  leaving(i);
  std::copy(state_[i], state_[i] + nstate_, buf);
  return nstate_;
}

int FixMeasureBase::unpack_exchange(int nlocal, double *buf)
{
  std::copy(buf, buf + nstate_, state_[nlocal]);
  refresh(nlocal);
  arrived(nlocal);
  return nstate_;
}

// per particle in a restart file: the block size, then the state
int FixMeasureBase::pack_restart(int i, double *buf)
{
  buf[0] = nstate_ + 1;
  std::copy(state_[i], state_[i] + nstate_, buf + 1);
  return nstate_ + 1;
}

void FixMeasureBase::unpack_restart(int nlocal, int nth)
{
  double **extra = atom->extra;
  int m = 0;
  for (int i = 0; i < nth; ++i) m += static_cast<int>(extra[nlocal][m]);
  const int size = static_cast<int>(extra[nlocal][m]) - 1;
  if (size != nstate_)
    tsg::fail_one(lmp, who_,
                  "the restart file holds " + std::to_string(size) + " values per particle, this fix needs " +
                      std::to_string(nstate_) + " (" + state_size_hint() + ")");
  std::copy(&extra[nlocal][m + 1], &extra[nlocal][m + 1] + nstate_, state_[nlocal]);
  refresh(nlocal);
}

int FixMeasureBase::size_restart(int) { return nstate_ + 1; }

int FixMeasureBase::maxsize_restart() { return nstate_ + 1; }

double FixMeasureBase::memory_usage() { return static_cast<double>(atom->nmax) * (nstate_ + nhot_) * sizeof(double); }
