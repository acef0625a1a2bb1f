// What fix residence/time and fix massflow/planes share as LIGGGHTS fixes: per-particle state that
// migrates with its particle and goes into restart files, a compact per-particle copy read every
// step, the clock across a restart, the list of particles near a plane, and one output file.
#ifndef TSG_FIX_MEASURE_BASE_H
#define TSG_FIX_MEASURE_BASE_H

#include <cstdio>
#include <string>
#include <vector>

#include "fix.h"

#include "axial_position.h"
#include "output_files.h"
#include "restart_clock.h"

namespace LAMMPS_NS {

class FixMeasureBase : public Fix {
public:
  ~FixMeasureBase() override;
  int setmask() override;

  void grow_arrays(int nmax) override;
  void copy_arrays(int i, int j, int delflag) override;
  void set_arrays(int i) override;
  int pack_exchange(int i, double *buf) override;
  int unpack_exchange(int nlocal, double *buf) override;
  int pack_restart(int i, double *buf) override;
  void unpack_restart(int nlocal, int nth) override;
  int size_restart(int nlocal) override;
  int maxsize_restart() override;
  double memory_usage() override;

protected:
  // Sets the flags every measurement fix has (a global vector every step, restart data, a state for
  // particles created later); the derived constructor then calls allocate_per_atom().
  FixMeasureBase(class LAMMPS *, int, char **);
  // Per particle, `nstate` values that migrate and are restarted, and `nhot` values refreshed from
  // them (hot_[i][0..1]: the interval where nothing changes, for NearList); registers the callbacks.
  void allocate_per_atom(int nstate, int nhot);
  // hot_[i] from state_[i] (after a change of state_[i], an arrival, a restart, a new particle)
  virtual void refresh(int i) = 0;
  // particle i is about to leave for another rank / has arrived from one
  virtual void leaving(int) {}
  virtual void arrived(int) {}
  // why a restart file may hold another number of values per particle, for the error message
  virtual std::string state_size_hint() const = 0;

  double now() const { return clock_.now(update); }
  double unwrapped_x(int i, double near) const { return tsg::measure::unwrapped_x(atom, domain, i, near); }
  double period() const { return domain->xperiodic ? domain->xprd : 0.0; }
  // Opens the output file on rank 0 (output_files.h open_output) with append_ and continuing_;
  // `time_column` (1-based) holds the time of each record, for the records after a restart.
  void open_file(const std::string &role, const std::string &path, const std::string &header,
                 const std::vector<std::string> &free_prefixes, int time_column);
  // Writes the global part of a restart file (rank 0).
  void write_global(FILE *fp, const std::vector<double> &list) const;

  const std::string who_;  // "fix ID style", the start of every error message
  int nstate_ = 0, nhot_ = 0;
  double **state_ = nullptr;
  double **hot_ = nullptr;
  tsg::measure::NearList near_;
  tsg::RestartClock clock_;
  tsg::Append append_ = tsg::Append::automatic;
  bool continuing_ = false;  // restored from a restart file: the output file continues
  bool file_opened_ = false;
  FILE *fp_ = nullptr;  // rank 0
};

}  // namespace LAMMPS_NS

#endif
