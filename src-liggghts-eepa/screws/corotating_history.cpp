// fix wall/gran/corotating: the per-particle contact history with the screws' triangles, as it migrates
// with its particle and goes into restart files (fix_wall_gran_corotating.h).
#include "fix_wall_gran_corotating.h"

#include <algorithm>

#include "atom.h"
#include "error.h"
#include "memory.h"

using namespace LAMMPS_NS;

// ---- per-particle contact history ------------------------------------------------------------------

void FixWallGranCorotating::grow_arrays(int nmax)
{
  memory->grow(contact_count_, nmax, "wall/gran/corotating:count");
  memory->grow(contact_key_, nmax, max_contacts_, "wall/gran/corotating:key");
  memory->grow(contact_history_, nmax, std::max(1, max_contacts_ * history_size_), "wall/gran/corotating:history");
  memory->grow(contact_kept_, nmax, max_contacts_, "wall/gran/corotating:kept");
}

void FixWallGranCorotating::copy_arrays(int i, int j, int)
{
  contact_count_[j] = contact_count_[i];
  std::copy(contact_key_[i], contact_key_[i] + max_contacts_, contact_key_[j]);
  std::copy(contact_kept_[i], contact_kept_[i] + max_contacts_, contact_kept_[j]);
  std::copy(contact_history_[i], contact_history_[i] + max_contacts_ * history_size_, contact_history_[j]);
}

void FixWallGranCorotating::set_arrays(int i)
{
  contact_count_[i] = 0;
  std::fill(contact_key_[i], contact_key_[i] + max_contacts_, -1);
  std::fill(contact_kept_[i], contact_kept_[i] + max_contacts_, 0);
  std::fill(contact_history_[i], contact_history_[i] + max_contacts_ * history_size_, 0.0);
}

// packed: count, then (key, history values) per contact
int FixWallGranCorotating::pack_exchange(int i, double *buf)
{
  int m = 0;
  buf[m++] = contact_count_[i];
  for (int k = 0; k < max_contacts_; ++k)
    if (contact_key_[i][k] >= 0) {
      buf[m++] = contact_key_[i][k];
      for (int h = 0; h < history_size_; ++h) buf[m++] = contact_history_[i][k * history_size_ + h];
    }
  return m;
}

int FixWallGranCorotating::unpack_exchange(int nlocal, double *buf)
{
  set_arrays(nlocal);
  int m = 0;
  const int count = static_cast<int>(buf[m++]);
  for (int k = 0; k < count; ++k) {
    contact_key_[nlocal][k] = static_cast<int>(buf[m++]);
    for (int h = 0; h < history_size_; ++h) contact_history_[nlocal][k * history_size_ + h] = buf[m++];
  }
  contact_count_[nlocal] = count;
  return m;
}

int FixWallGranCorotating::pack_restart(int i, double *buf)
{
  const int m = pack_exchange(i, buf + 1);
  buf[0] = m + 1;
  return m + 1;
}

void FixWallGranCorotating::unpack_restart(int nlocal, int nth)
{
  double **extra = atom->extra;
  int m = 0;
  for (int i = 0; i < nth; ++i) m += static_cast<int>(extra[nlocal][m]);
  const int count = static_cast<int>(extra[nlocal][m + 1]);
  if (reset_restart_contacts_) {  // restart_contacts reset: the particle starts without wall contacts
    set_arrays(nlocal);
    contact_count_[nlocal] = 0;
    return;
  }
  if (count > max_contacts_)
    error->one(FLERR,
               (std::string("fix ") + id + " wall/gran/corotating: the restart file holds " + std::to_string(count) +
                " screw contacts for a particle, more than max_contacts = " + std::to_string(max_contacts_))
                   .c_str());
  unpack_exchange(nlocal, &extra[nlocal][m + 1]);
}

int FixWallGranCorotating::size_restart(int nlocal) { return 2 + contact_count_[nlocal] * (1 + history_size_); }

int FixWallGranCorotating::maxsize_restart() { return 2 + max_contacts_ * (1 + history_size_); }
